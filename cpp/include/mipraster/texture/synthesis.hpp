#pragma once
// Texture synthesis by non-parametric sampling (Efros & Leung, ICCV 1999), as in the notes: grow
// the output pixel by pixel from a seed patch, in onion-skin order; for each pixel compare its
// known neighbourhood with every neighbourhood of the sample (Gaussian-weighted sum of squared
// differences over the known pixels only) and copy the centre of one of the best matches, chosen
// at random among those within (1 + ε) of the best.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "mipraster/core/image.hpp"

namespace mipraster {

/// Largest synthesized width or height.
inline constexpr int kMaxSynthesisDimension = 8192;
/// Side of the seed patch copied from the sample to start the growth (Efros & Leung: 3×3).
inline constexpr int kSynthesisSeedSize = 3;
/// The Gaussian that weighs a neighbourhood has σ = window / 6.4 (Efros & Leung's choice: the
/// window's edge gets about 1/200 of the centre's weight).
inline constexpr double kSynthesisSigmaDivisor = 6.4;
static_assert(kSynthesisSeedSize >= 1 && kSynthesisSigmaDivisor > 0.0, "a seed pixel and a positive sigma");

struct SynthesisSettings {
    int width = 0, height = 0;  ///< output size, 1…kMaxSynthesisDimension each
    int window = 11;            ///< neighbourhood side n: odd, 1 ≤ n ≤ the sample's width and height
    std::uint64_t seed = 0;     ///< the same seed gives the same output, for any thread count
    double epsilon = 0.1;       ///< candidates within (1 + ε)·best SSD are drawn from; ε ≥ 0
    /// The sample tiles (is periodic): its neighbourhoods wrap around its edges, so every pixel is
    /// a candidate centre. Otherwise only windows entirely inside the sample are candidates.
    bool periodic_sample = false;
    /// The output tiles: its neighbourhoods wrap around its edges (needs n ≤ the output's sides),
    /// so it can be used with the repeat wrap mode without seams.
    bool tileable = false;
    int threads = 0;  ///< 0 = all cores; the candidate search of each pixel is split across them

    std::string to_string() const;
};

struct SynthesisResult {
    Image image;                       ///< width × height with the sample's channels: copied sample pixels
    std::vector<std::int32_t> source;  ///< per output pixel, the sample pixel it copies: y·sample_width + x
    std::size_t candidates = 0;        ///< neighbourhoods compared for each pixel
    double milliseconds = 0;

    std::string to_string() const;
};

/// Synthesizes a texture like `sample` (linear float, 1–4 channels; distances are measured in
/// its values). Throws std::invalid_argument naming the bad input: an empty sample, more than 4
/// channels, a non-finite pixel, an even window or one outside 1…min(sample width, height) (or,
/// tileable, the output's), an output size outside 1…kMaxSynthesisDimension, a negative or
/// non-finite ε, a thread count outside 0…kMaxThreads.
SynthesisResult synthesize_texture(const Image& sample, const SynthesisSettings& settings);

}  // namespace mipraster
