#pragma once
// The supersample framebuffer: W×H×S samples of linear premultiplied RGBA and float32 depth.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

namespace mipraster {

/// Sample s of pixel (x, y) is sample (y·W + x)·S + s: `color` holds 4 floats (RGBA) per sample,
/// `depth` one float32 window depth. `depth` is empty when no draw tests depth (nothing allocates
/// a buffer that nothing uses).
struct Framebuffer {
    int width = 0, height = 0, samples = 1;
    std::vector<float> color;
    std::vector<float> depth;

    std::size_t sample_index(int x, int y, int s) const {
        return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) *
                   static_cast<std::size_t>(samples) + static_cast<std::size_t>(s);
    }
    bool has_depth() const { return !depth.empty(); }

    std::string to_string() const;
};

/// Bytes a framebuffer of this size needs (colour, plus depth when asked for).
std::uint64_t framebuffer_bytes(int width, int height, int samples, bool with_depth);

/// Checks the size (1…kMaxDimension each, samples 1…kMaxSamples, within kMaxFramebufferBytes)
/// before anything is allocated; the error names the input and the memory it would need.
void validate_framebuffer_size(int width, int height, int samples, bool with_depth);

/// Allocates and clears a framebuffer.
Framebuffer make_framebuffer(int width, int height, int samples, glm::vec4 clear_color, bool with_depth,
                             float clear_depth);

}  // namespace mipraster
