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

/// A window onto sample storage (the whole framebuffer, a tile-local buffer, or an image at one
/// sample per pixel): sample s of pixel (x, y) is element ((y − origin_y)·pitch + x − origin_x)·S + s,
/// with `channels` floats per element.
struct SampleWindow {
    float* data = nullptr;
    int channels = 4;
    int origin_x = 0, origin_y = 0;
    int pitch = 0;  ///< pixels per row
    int samples = 1;

    std::size_t index(int x, int y, int s) const {
        return (static_cast<std::size_t>(y - origin_y) * static_cast<std::size_t>(pitch) +
                static_cast<std::size_t>(x - origin_x)) * static_cast<std::size_t>(samples) + static_cast<std::size_t>(s);
    }
    float* at(int x, int y, int s) const { return data + index(x, y, s) * static_cast<std::size_t>(channels); }

    /// Sets every sample of the pixels [x0, x1) × [y0, y1) to `value` (its first `channels` components).
    void fill(int x0, int y0, int x1, int y1, const glm::vec4& value) const;
};

/// The colour clear after drawing, for draws that write depth wherever they write colour: every
/// sample of the pixels [x0, x1) × [y0, y1) whose depth is still `clear_depth` (none drew it) gets
/// `value`. `color` and `depth` are windows with the same origin, pitch and samples.
void fill_undrawn(const SampleWindow& color, const SampleWindow& depth, int x0, int y0, int x1, int y1,
                  float clear_depth, const glm::vec4& value);

/// Windows onto a whole framebuffer's colour and depth (depth.data is null when it has none).
SampleWindow color_window(Framebuffer& framebuffer);
SampleWindow depth_window(Framebuffer& framebuffer);

/// Bytes a framebuffer of this size needs (colour, plus depth when asked for).
std::uint64_t framebuffer_bytes(int width, int height, int samples, bool with_depth);

/// Checks the size (1…kMaxDimension each, samples 1…kMaxSamples) before anything is allocated;
/// the error names the input and the memory it would need. (The bytes are checked against
/// memory_limit() by make_framebuffer and, for a whole render, by render.)
void validate_framebuffer_size(int width, int height, int samples, bool with_depth);

/// Allocates and clears a framebuffer; throws MemoryLimitError above memory_limit().
Framebuffer make_framebuffer(int width, int height, int samples, glm::vec4 clear_color, bool with_depth,
                             float clear_depth);

}  // namespace mipraster
