#pragma once
// Image resampling (the notes' reconstruction + sampling): reconstruct a continuous image from the
// pixels with a separable filter, then sample it on the new pixel grid. When minifying, the filter
// is widened by the reduction factor so that it also removes what the new grid cannot hold.
#include <cstdint>
#include <string>
#include <vector>

#include "mipraster/core/image.hpp"
#include "mipraster/core/reconstruction_filter.hpp"

namespace mipraster {

/// Largest resampled width or height, and the most bytes an output (or the intermediate image of
/// the two separable passes) may take as float: checked before anything is allocated.
inline constexpr int kMaxResampleDimension = 1 << 16;
inline constexpr std::uint64_t kMaxResampleBytes = std::uint64_t{8} << 30;
static_assert(kMaxResampleBytes >= std::uint64_t{16384} * 16384 * 16, "a 16384² RGBA float image must fit");

/// The weights of one axis. Target pixel i (centre i + ½) maps to source position
/// c = (i + ½)·source/target; it reads the source pixels first[i] … first[i] + taps − 1 with the
/// weights weights[offset[i] …], f((k + ½ − c)/scale) normalized to sum 1, where
/// scale = max(1, source/target) widens the kernel when minifying. Taps that fall outside the
/// source are dropped (the rest renormalized), so an edge pixel is a mean of pixels that exist.
struct ResampleWeights {
    int source_size = 0, target_size = 0;
    ReconstructionFilter filter = ReconstructionFilter::box;
    double scale = 1.0;
    std::vector<int> first;       ///< per target pixel
    std::vector<int> offset;      ///< per target pixel, plus one past the end (= weights.size())
    std::vector<float> weights;   ///< normalized, contiguous per target pixel

    int taps(int i) const { return offset[static_cast<std::size_t>(i) + 1] - offset[static_cast<std::size_t>(i)]; }
    std::string to_string() const;
};

/// The weights of resampling `source_size` pixels to `target_size` (each ≥ 1, else
/// std::invalid_argument naming it).
ResampleWeights resample_weights(int source_size, int target_size, ReconstructionFilter filter);

/// Resizes a linear float image (any channel count; colour images premultiplied) to
/// width × height with `filter`, in two separable passes (rows, then columns) on `threads`
/// threads (0 = all cores; the result does not depend on it). The same size returns a copy of the
/// input (no filtering). Values are not clamped: filters with negative lobes (mitchell,
/// catmull-rom, lanczos3) may overshoot near edges. Throws std::invalid_argument naming the bad
/// input: an empty or malformed image, a non-finite pixel, a size outside 1…kMaxResampleDimension
/// or beyond kMaxResampleBytes.
Image resample(const Image& image, int width, int height, ReconstructionFilter filter, int threads = 0);

}  // namespace mipraster
