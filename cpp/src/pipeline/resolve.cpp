#include "mipraster/pipeline/resolve.hpp"

#include <stdexcept>

#include "mipraster/core/thread_pool.hpp"

namespace mipraster {

std::string to_string(ResolveFilter) { return "box"; }

ResolveFilter parse_resolve_filter(const std::string& name) {
    if (name == "box") return ResolveFilter::box;
    throw std::invalid_argument("resolve filter: unknown name '" + name + "'; expected box");
}

Image resolve_color(const Framebuffer& fb, ResolveFilter, ThreadPool& pool) {
    Image out(fb.width, fb.height, 4);
    const int S = fb.samples;
    pool.parallel_for(static_cast<std::size_t>(fb.height), [&](std::size_t y) {
        for (int x = 0; x < fb.width; ++x) {
            const float* src = &fb.color[4 * fb.sample_index(x, static_cast<int>(y), 0)];
            float sum[4] = {0, 0, 0, 0};
            for (int s = 0; s < S; ++s)
                for (int c = 0; c < 4; ++c) sum[c] += src[4 * s + c];
            for (int c = 0; c < 4; ++c) out.at(x, static_cast<int>(y), c) = sum[c] / static_cast<float>(S);
        }
    });
    return out;
}

Image resolve_color(Framebuffer&& fb, ResolveFilter filter, ThreadPool& pool) {
    if (fb.samples != 1) return resolve_color(static_cast<const Framebuffer&>(fb), filter, pool);
    Image out;
    out.width = fb.width;
    out.height = fb.height;
    out.channels = 4;
    out.pixels = std::move(fb.color);
    return out;
}

}  // namespace mipraster
