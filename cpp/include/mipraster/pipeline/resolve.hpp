#pragma once
// Resolve stage: reconstruct pixels from supersamples with a filter.
#include <string>

#include <glm/vec4.hpp>

#include "mipraster/core/image.hpp"
#include "mipraster/core/reconstruction_filter.hpp"
#include "mipraster/core/thread_pool.hpp"
#include "mipraster/pipeline/framebuffer.hpp"
#include "mipraster/pipeline/sample_pattern.hpp"

namespace mipraster {

/// Resolve filters are the reconstruction filters of image resampling. The box filter (the mean
/// of the pixel's own samples) is pixel-local, so the renderer resolves each tile while its
/// samples are in cache; wider filters read neighbouring pixels and resolve the whole kept
/// framebuffer once every tile is drawn (resolve_framebuffer).
using ResolveFilter = ReconstructionFilter;

/// parse_reconstruction_filter with a message naming the resolve filter.
ResolveFilter parse_resolve_filter(const std::string& name);

/// Box-resolves the pixels [x0, x1) × [y0, y1) of `samples` (RGBA windows) into `out` (H, W, 4).
/// Only the box filter is pixel-local: another filter throws std::invalid_argument.
void resolve_tile(const SampleWindow& samples, int x0, int y0, int x1, int y1, ResolveFilter filter, Image& out);

/// fill_undrawn (framebuffer.hpp) and then resolve_tile's box, in one pass: each sample whose
/// depth is still `clear_depth` counts as `clear` (the same bits), and `samples` is left as it is.
/// A pixel none of whose samples was drawn reads no colour. `depth` has the window's layout.
void resolve_undrawn(const SampleWindow& samples, const SampleWindow& depth, int x0, int y0, int x1, int y1,
                     float clear_depth, const glm::vec4& clear, Image& out);

/// Writes `value` to the pixels [x0, x1) × [y0, y1) of `out` (H, W, 4) the way resolve_tile writes
/// its pixels (past the cache where it can): a tile with nothing drawn on it.
void write_pixels(const glm::vec4& value, int x0, int y0, int x1, int y1, Image& out);

/// Resolves a whole framebuffer with any filter: pixel (x, y) is the weighted mean of the samples
/// of the pixels around it, sample s of pixel (x', y') at (x' + ox_s, y' + oy_s) weighing
/// f(x' + ox_s − x − ½)·f(y' + oy_s − y − ½), over the samples inside the frame (the kernel is
/// in pixels: a filter of radius r reaches r pixels from the centre whatever the sample count).
/// For a C×R grid pattern this equals resampling the (C·W)×(R·H) image of the samples to W×H
/// with the same filter (core/resample.hpp), which widens the kernel by the same factor.
/// Separable: rows, then columns, on the pool's threads (the result does not depend on them).
void resolve_framebuffer(const Framebuffer& samples, const SamplePattern& pattern, ResolveFilter filter,
                         ThreadPool& pool, Image& out);

}  // namespace mipraster
