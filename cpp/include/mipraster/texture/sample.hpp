#pragma once
// Texture lookups: a uv point and its screen-space derivatives in, a filtered colour out
// (DESIGN.md §1 LOD and anisotropy, §2.6 sampling contract).
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture.hpp"

namespace mipraster {

/// EWA works on the finest level at which the footprint ellipse's minor semi-axis spans at least
/// this many texels (fewer texels per lookup, at the cost of the coarser level's prefilter).
inline constexpr double kEwaMinAxisTexels = 1.0;
/// EWA's Gaussian is exp(−α·r²), r the distance in pixels from the sample: α = 6 gives the
/// variance of the one-pixel box (1/12), so it approximates the box-filtered footprint; the
/// ellipse is cut at r = 1 (weight e⁻⁶ ≈ 0.25%).
inline constexpr double kEwaAlpha = 6.0;

/// λ of a lookup: isotropic and EWA/SAT footprints use ρ = max(‖∂uv/∂x‖, ‖∂uv/∂y‖) in texels,
/// anisotropic uses Pmax/N (EXT_texture_filter_anisotropic); then + bias, clamped to
/// [min_lod, max_lod] and [0, levels − 1]. Infinite or NaN derivatives give the coarsest level
/// allowed (levels − 1, or max_lod when smaller). λ within 1e-6 of an integer is snapped to it:
/// float derivatives of an exact 2^k footprint come out a few ulps short, and should read one
/// level, not two.
/// λ ≤ 0 means magnification (the mag filter on level 0).
double texture_lod(const TextureView& texture, const Sampler& sampler, glm::vec2 duv_dx, glm::vec2 duv_dy);

/// How many probes an anisotropic lookup takes for the squared lengths px2, py2 of its derivative
/// vectors in level-0 texels (finite): min(⌈Pmax/Pmin⌉, max anisotropy), 1 when they are equal.
int anisotropic_probe_count(double px2, double py2, float max_anisotropy);

/// The filtered, premultiplied linear RGBA colour at uv (0,0 = top-left of the first row) for
/// a pixel whose uv changes by duv_dx, duv_dy per pixel step. A non-finite uv returns the border
/// colour. Positions, fractions and λ are computed in double; texels are blended in float, four
/// channels at once (SSE2 on every x86-64, so the result does not depend on the CPU). Means are
/// kept relative to one of their terms, so a constant texture returns its value exactly for
/// every footprint.
glm::vec4 sample_texture(const TextureView& texture, const Sampler& sampler, glm::vec2 uv, glm::vec2 duv_dx,
                         glm::vec2 duv_dy);

}  // namespace mipraster
