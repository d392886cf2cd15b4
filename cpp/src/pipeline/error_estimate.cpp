#include "mipraster/pipeline/error_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "mipraster/core/constants.hpp"

namespace mipraster {

std::vector<std::uint8_t> interleaved_halves(const SamplePattern& pattern) {
    const int n = pattern.count();
    if (n < 2)
        throw std::invalid_argument("error estimate: needs at least 2 samples per pixel, got " + std::to_string(n));
    int rows = 1;
    for (int r = 1; r * r <= n; ++r)
        if (n % r == 0) rows = r;
    const int cols = n / rows;
    std::vector<std::uint8_t> half(static_cast<std::size_t>(n));
    int count[2] = {0, 0};
    for (int s = 0; s < n; ++s) {
        const int col = std::min<int>(cols - 1, static_cast<int>(pattern.x[static_cast<std::size_t>(s)] * cols / kSubpixelOne));
        const int row = std::min<int>(rows - 1, static_cast<int>(pattern.y[static_cast<std::size_t>(s)] * rows / kSubpixelOne));
        half[static_cast<std::size_t>(s)] = static_cast<std::uint8_t>((col + row) & 1);
        ++count[(col + row) & 1];
    }
    if (count[0] == 0 || count[1] == 0)
        throw std::invalid_argument("error estimate: pattern " + pattern.to_string() +
                                    " does not split into two interleaved halves");
    return half;
}

void estimate_tile_error(const SampleWindow& samples, const std::vector<std::uint8_t>& halves, int x0, int y0,
                         int x1, int y1, Image& out) {
    const int S = samples.samples;
    double n_half[2] = {0, 0};
    for (int s = 0; s < S; ++s) n_half[halves[static_cast<std::size_t>(s)]] += 1;
    // A − B as one weighted sum, +1/nA over half A and −1/nB over half B: no branch per sample.
    // The sum of |weight·value| bounds the rounding of that sum; a difference within a few float
    // epsilons of it is no disagreement (a flat pixel estimates exactly 0).
    float weight[kMaxSamples];
    for (int s = 0; s < S; ++s)
        weight[s] = static_cast<float>(halves[static_cast<std::size_t>(s)] ? -1.0 / n_half[1] : 1.0 / n_half[0]);
    constexpr float kRoundingTolerance = 8.0f * std::numeric_limits<float>::epsilon();
    // E[(I − truth)²] = E[(A − B)²]·nA·nB/n² (see the header); the mean over R, G, B.
    const double scale = n_half[0] * n_half[1] / (double(S) * double(S)) / 3.0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const float* src = samples.at(x, y, 0);
            float d[3] = {0, 0, 0}, magnitude[3] = {0, 0, 0};
            for (int s = 0; s < S; ++s)
                for (int c = 0; c < 3; ++c) {
                    d[c] += weight[s] * src[4 * s + c];
                    magnitude[c] += std::abs(weight[s] * src[4 * s + c]);
                }
            double squared = 0;
            for (int c = 0; c < 3; ++c)
                if (std::abs(d[c]) > kRoundingTolerance * magnitude[c]) squared += double(d[c]) * d[c];
            out.at(x, y, 0) = static_cast<float>(std::sqrt(squared * scale));
        }
}

ErrorEstimate summarize_error_map(const Image& map) {
    ErrorEstimate e;
    double sum = 0;
    for (float v : map.pixels) {
        sum += double(v) * double(v);
        e.max_pixel = std::max(e.max_pixel, double(v));
    }
    if (!map.pixels.empty()) e.rmse = std::sqrt(sum / static_cast<double>(map.pixels.size()));
    return e;
}

std::string ErrorEstimate::to_string() const {
    char buf[96];
    std::snprintf(buf, sizeof buf, "ErrorEstimate(rmse=%.6g, max_pixel=%.6g)", rmse, max_pixel);
    return buf;
}

}  // namespace mipraster
