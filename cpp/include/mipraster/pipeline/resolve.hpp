#pragma once
// Resolve stage: reconstruct pixels from the supersample framebuffer with a filter.
#include <string>

#include "mipraster/core/image.hpp"
#include "mipraster/pipeline/framebuffer.hpp"

namespace mipraster {

class ThreadPool;

/// Reconstruction filters. Only the box filter (mean of the pixel's own samples) exists so far;
/// wider filters slot in here.
enum class ResolveFilter { box };

std::string to_string(ResolveFilter filter);
ResolveFilter parse_resolve_filter(const std::string& name);

/// Resolves colour to a (H, W, 4) linear premultiplied image. With one sample per pixel the
/// samples already are the image and are moved out without a pass (pass the framebuffer as an
/// rvalue to allow that).
Image resolve_color(Framebuffer&& framebuffer, ResolveFilter filter, ThreadPool& pool);
Image resolve_color(const Framebuffer& framebuffer, ResolveFilter filter, ThreadPool& pool);

}  // namespace mipraster
