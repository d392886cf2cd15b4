#pragma once
// The stress suite's texture oracle: wrap modes, nearest and bilinear lookups on level 0 in
// double, written from DESIGN.md §1 (texel centres at (i+½)/w, nearest i = ⌊u·w⌋, bilinear
// i = ⌊u·w − ½⌋) independently of the texture module's code.
#include <glm/vec4.hpp>

#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture_level.hpp"

namespace mipraster::stress {

/// Texel index along an n-texel axis after wrapping, or −1 for the border. i may be any value
/// an int64 holds.
long long reference_wrap(long long i, long long n, WrapMode mode);

/// Level-0 lookup with `filter` at uv (finite, |u·w| and |v·h| < 2^52), wrap and border colour
/// from the sampler.
glm::dvec4 reference_lookup(const TextureLevel& level, double u, double v, TexelFilter filter, const Sampler& sampler);

}  // namespace mipraster::stress
