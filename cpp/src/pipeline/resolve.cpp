#include "mipraster/pipeline/resolve.hpp"

#include <stdexcept>


namespace mipraster {

std::string to_string(ResolveFilter) { return "box"; }

ResolveFilter parse_resolve_filter(const std::string& name) {
    if (name == "box") return ResolveFilter::box;
    throw std::invalid_argument("resolve filter: unknown name '" + name + "'; expected box");
}

void resolve_tile(const SampleWindow& samples, int x0, int y0, int x1, int y1, ResolveFilter, Image& out) {
    const int S = samples.samples;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const float* src = samples.at(x, y, 0);
            // The sum in double: a float sum of samples near the float maximum would overflow
            // to infinity, though their mean is finite.
            double sum[4] = {0, 0, 0, 0};
            for (int s = 0; s < S; ++s)
                for (int c = 0; c < 4; ++c) sum[c] += src[4 * s + c];
            for (int c = 0; c < 4; ++c) out.at(x, y, c) = static_cast<float>(sum[c] / S);
        }
}

}  // namespace mipraster
