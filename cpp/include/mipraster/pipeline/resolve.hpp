#pragma once
// Resolve stage: reconstruct pixels from supersamples with a filter.
#include <string>

#include "mipraster/core/image.hpp"
#include "mipraster/pipeline/framebuffer.hpp"

namespace mipraster {

/// Reconstruction filters. Only the box filter (mean of the pixel's own samples) exists so far.
/// It is pixel-local, so the renderer resolves each tile while its samples are in cache; wider
/// filters, which read neighbouring pixels, will resolve a whole kept framebuffer instead.
enum class ResolveFilter { box };

std::string to_string(ResolveFilter filter);
ResolveFilter parse_resolve_filter(const std::string& name);

/// Resolves the pixels [x0, x1) × [y0, y1) of `samples` (RGBA windows) into `out` (H, W, 4).
void resolve_tile(const SampleWindow& samples, int x0, int y0, int x1, int y1, ResolveFilter filter, Image& out);

}  // namespace mipraster
