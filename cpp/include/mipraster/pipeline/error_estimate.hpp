#pragma once
// A render's error estimated from its own samples: the samples are split into two interleaved
// halves A and B; where their resolves disagree, the full resolve is uncertain.
//
// With nA + nB = n samples whose errors are independent with equal variance, the full resolve
// I = (nA·A + nB·B)/n has E[(I − truth)²] = E[(A − B)²]·nA·nB/n², so the per-pixel estimate is
// |A − B|·√(nA·nB)/n (= |A − B|/2 for equal halves). It sees sampling error (edges, texture
// detail between samples); it cannot see error that both halves share (a blurry texture filter,
// MSAA's one shade per pixel).
#include <cstdint>
#include <string>
#include <vector>

#include "mipraster/core/image.hpp"
#include "mipraster/pipeline/framebuffer.hpp"
#include "mipraster/pipeline/sample_pattern.hpp"

namespace mipraster {

/// Which half each sample belongs to (0 or 1): the parity of its stratum (column + row) on the
/// most square columns × rows grid of the count, a checkerboard over the pixel, so both halves
/// cover the whole pixel. Throws std::invalid_argument for fewer than 2 samples or when a half
/// would be empty.
std::vector<std::uint8_t> interleaved_halves(const SamplePattern& pattern);

/// Writes the per-pixel estimate (root mean square over R, G, B of the linear colour) of the
/// pixels [x0, x1) × [y0, y1) into `out` (H, W, 1).
void estimate_tile_error(const SampleWindow& samples, const std::vector<std::uint8_t>& halves, int x0, int y0,
                         int x1, int y1, Image& out);

/// The whole-image figures of a per-pixel estimate map.
struct ErrorEstimate {
    double rmse = 0;     ///< estimated RMSE of the image over R, G, B (linear)
    double max_pixel = 0;///< the largest per-pixel estimate
    std::string to_string() const;
};

/// Summarizes an (H, W, 1) map made by estimate_tile_error.
ErrorEstimate summarize_error_map(const Image& map);

}  // namespace mipraster
