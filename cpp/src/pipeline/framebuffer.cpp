#include "mipraster/pipeline/framebuffer.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <xmmintrin.h>

#include "mipraster/core/constants.hpp"
#include "mipraster/core/memory_limit.hpp"

namespace mipraster {

std::uint64_t framebuffer_bytes(int width, int height, int samples, bool with_depth) {
    const std::uint64_t n = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) *
                            static_cast<std::uint64_t>(samples);
    return n * (4 * sizeof(float) + (with_depth ? sizeof(float) : 0));
}

void validate_framebuffer_size(int width, int height, int samples, bool with_depth) {
    auto dim = [&](const char* name, int v) {
        if (v >= 1 && v <= kMaxDimension) return;
        std::string message = std::string(name) + ": expected 1 to " + std::to_string(kMaxDimension) +
                              " pixels, got " + std::to_string(v);
        if (width > 0 && height > 0 && samples > 0)
            message += " (a " + std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(samples) +
                       " framebuffer would need " + std::to_string(framebuffer_bytes(width, height, samples, with_depth) >> 20) +
                       " MiB)";
        throw std::invalid_argument(message);
    };
    dim("width", width);
    dim("height", height);
    if (samples < 1 || samples > kMaxSamples)
        throw std::invalid_argument("samples per pixel: expected 1 to " + std::to_string(kMaxSamples) + ", got " +
                                    std::to_string(samples));
}

Framebuffer make_framebuffer(int width, int height, int samples, glm::vec4 clear_color, bool with_depth,
                             float clear_depth) {
    validate_framebuffer_size(width, height, samples, with_depth);
    check_memory(framebuffer_bytes(width, height, samples, with_depth),
                 "a " + std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(samples) +
                     " sample framebuffer");
    Framebuffer fb;
    fb.width = width;
    fb.height = height;
    fb.samples = samples;
    const std::size_t n = static_cast<std::size_t>(width) * height * samples;
    fb.color.resize(4 * n);
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 4; ++c) fb.color[4 * i + c] = clear_color[c];
    if (with_depth) fb.depth.assign(n, clear_depth);
    return fb;
}

void SampleWindow::fill(int x0, int y0, int x1, int y1, const glm::vec4& value) const {
    // A row of the rectangle is contiguous. Depth (1 channel) and colour (4) get loops of vector
    // stores: the per-channel loop stored one float at a time, and a 16-byte copy per sample
    // became two 8-byte stores (5 % of a 1080p textured frame went to clears).
    const float v[4] = {value[0], value[1], value[2], value[3]};
    const std::size_t n = static_cast<std::size_t>(x1 - x0) * static_cast<std::size_t>(samples);  // per row
    typedef float TwoSamples __attribute__((vector_size(32)));  // (aligned: one load, kept in a register)
    const TwoSamples two{v[0], v[1], v[2], v[3], v[0], v[1], v[2], v[3]};
    for (int y = y0; y < y1; ++y) {
        float* const p = at(x0, y, 0);
        if (channels == 1) {
            std::fill(p, p + n, v[0]);
        } else if (channels == 4) {
            std::size_t i = 0;
            for (; i + 2 <= n; i += 2) std::memcpy(p + 4 * i, &two, sizeof two);
            if (i < n) std::memcpy(p + 4 * i, v, sizeof v);
        } else {
            for (std::size_t i = 0; i < n; ++i)
                for (int c = 0; c < channels; ++c) p[i * static_cast<std::size_t>(channels) + c] = v[c];
        }
    }
}

void fill_undrawn(const SampleWindow& color, const SampleWindow& depth, int x0, int y0, int x1, int y1,
                  float clear_depth, const glm::vec4& value) {
    // Eight depths a compare: a tile drawn whole (most of them) takes two compares and a branch
    // per eight samples, where the clear stored 128 bytes.
    const __m128 clear = _mm_set1_ps(clear_depth);
    const std::size_t n = static_cast<std::size_t>(x1 - x0) * static_cast<std::size_t>(color.samples);  // per row
    const __m128 v = _mm_loadu_ps(&value.x);
    const auto fill = [&](float* c, int undrawn) {  // bit k: sample k of the eight at c
        if (undrawn == 0xFF) {  // (the background around a triangle: all eight)
            for (int k = 0; k < 8; ++k) _mm_storeu_ps(c + 4 * k, v);
            return;
        }
        for (; undrawn; undrawn &= undrawn - 1) _mm_storeu_ps(c + 4 * __builtin_ctz(undrawn), v);
    };
    for (int y = y0; y < y1; ++y) {
        const float* const z = depth.at(x0, y, 0);
        float* const c = color.at(x0, y, 0);
        std::size_t i = 0;
        for (; i + 8 <= n; i += 8) {
            const int undrawn = _mm_movemask_ps(_mm_cmpeq_ps(_mm_loadu_ps(z + i), clear)) |
                                _mm_movemask_ps(_mm_cmpeq_ps(_mm_loadu_ps(z + i + 4), clear)) << 4;
            if (undrawn) fill(c + 4 * i, undrawn);
        }
        for (; i < n; ++i)
            if (z[i] == clear_depth) _mm_storeu_ps(c + 4 * i, v);
    }
}

SampleWindow color_window(Framebuffer& fb) { return {fb.color.data(), 4, 0, 0, fb.width, fb.samples}; }

SampleWindow depth_window(Framebuffer& fb) {
    return {fb.has_depth() ? fb.depth.data() : nullptr, 1, 0, 0, fb.width, fb.samples};
}

std::string Framebuffer::to_string() const {
    return "Framebuffer(" + std::to_string(width) + "x" + std::to_string(height) + ", samples=" +
           std::to_string(samples) + (has_depth() ? ", depth" : ", no depth") + ")";
}

}  // namespace mipraster
