#pragma once
// The pieces of sample_texture's anisotropic filter that BatchSampler reuses for footprints
// needing several probes (private to the texture module; defined in sample.cpp, the AVX2 line in
// anisotropic_line_avx2.cpp), so that both decide magnification and step along the line with the
// same arithmetic.
#include "mipraster/texture/sample_batch.hpp"
#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture_level.hpp"
#include "texel.hpp"

namespace mipraster {

/// True when an anisotropic lookup whose longer derivative has squared length pmax2 (finite, in
/// level-0 texels) magnifies: λ of log2 Pmax ≤ 0 after bias, snapping and clamping. When it does
/// not and log2_pmax is given, *log2_pmax is log2 Pmax (null: the log2 is skipped where it can be).
bool anisotropic_magnifies(double pmax2, const Sampler& sampler, int levels, double* log2_pmax = nullptr);

/// anisotropic_magnifies' first test: with no bias, no positive min_lod, a max_lod above 0 and
/// more than one level (lod_is_plain), a squared length pmax2 > kSurelyMinifying2 has
/// log2 Pmax > 7·10⁻⁶, past λ's snap to integers: λ > 0, it minifies.
bool lod_is_plain(const Sampler& sampler, int levels);
inline constexpr double kSurelyMinifying2 = 1.00001;

/// The most probes a line of a sampler with this max_anisotropy takes (anisotropic_probe_count's cap).
int most_probes(float max_anisotropy);

/// How far from the origin a line's probes may reach (texels) for their indices to be worked out
/// in int: ⌊x⌋ + 1 fits, with room for wrapping.
inline constexpr double kProbeReach = 0x1p30;

/// Where the bilinear quads of anisotropic_line's probes lie on a level, in texels: probe k's at
/// x0 + k·step·sx, y0 + k·step·sy (its top-left texel the floor), step = 1/count.
struct ProbeLine {
    double x0, y0, sx, sy, step;
    bool inside;  // every probe's quad lies inside the level: none wraps
    bool near;    // every probe within ±kProbeReach (false for NaN)
};
ProbeLine probe_line(const TextureLevel& level, const Sampler& sampler, double u, double v, double du, double dv,
                     int count);

/// The mean of `count` bilinear probes on one level at uv + ((i + ½)/count − ½)·(du, dv), i < count
/// (EXT_texture_filter_anisotropic's line along the longer derivative).
texel::Texel anisotropic_line(const TextureLevel& level, const Sampler& sampler, double u, double v, double du,
                              double dv, int count);

/// The lanes of a lookup batch that take lines of probes: lane i's lookup (u, v), its longer
/// derivative (du, dv), its probe count, the level(s) it reads (coarser null: one level) and the
/// coarser one's weight, and the batch lane whose result it is.
struct LineLanes {
    int n = 0;
    double u[kLookupBatch], v[kLookupBatch], du[kLookupBatch], dv[kLookupBatch];
    int count[kLookupBatch];
    const TextureLevel* finer[kLookupBatch];
    const TextureLevel* coarser[kLookupBatch];
    float weight[kLookupBatch];
    int out[kLookupBatch];
};

/// Lane i of `lanes`: anisotropic_line on *finer[i] and, where coarser[i] is not null, blended
/// towards the line on *coarser[i] by weight[i].
glm::vec4 anisotropic_lines_lookup(const LineLanes& lanes, int i, const Sampler& sampler);

/// out[lanes.out[i]] = anisotropic_lines_lookup(lanes, i, sampler) for every i < lanes.n, one lane
/// at a time (the four-lane batch path's).
void anisotropic_lines(const LineLanes& lanes, const Sampler& sampler, glm::vec4* out);

/// anisotropic_lines' bits with AVX2 (anisotropic_line_avx2.cpp), for repeat and clamp: the lines
/// placed four lanes per vector, probe k of four lines in one vector, a lookup's two lines summed
/// in the two halves of one register (lines of more than 16 probes, from a max_anisotropy above
/// 16, one lane at a time). Only on a CPU with AVX2.
void anisotropic_lines_avx2(const LineLanes& lanes, const Sampler& sampler, glm::vec4* out);

}  // namespace mipraster
