#pragma once
// The two pieces of sample_texture's anisotropic filter that BatchSampler reuses for footprints
// needing several probes (private to the texture module; defined in sample.cpp), so that both
// decide magnification and step along the line with the same arithmetic.
#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture_level.hpp"
#include "texel.hpp"

namespace mipraster {

/// True when an anisotropic lookup whose longer derivative has squared length pmax2 (finite, in
/// level-0 texels) magnifies: λ of log2 Pmax ≤ 0 after bias, snapping and clamping. When it does
/// not and log2_pmax is given, *log2_pmax is log2 Pmax (null: the log2 is skipped where it can be).
bool anisotropic_magnifies(double pmax2, const Sampler& sampler, int levels, double* log2_pmax = nullptr);

/// The mean of `count` bilinear probes on one level at uv + ((i + ½)/count − ½)·(du, dv), i < count
/// (EXT_texture_filter_anisotropic's line along the longer derivative).
texel::Texel anisotropic_line(const TextureLevel& level, const Sampler& sampler, double u, double v, double du,
                              double dv, int count);

}  // namespace mipraster
