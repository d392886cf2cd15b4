#pragma once
// A plain linear-float image: (height, width, channels), row 0 at the top.
#include <cstddef>
#include <string>
#include <vector>

#include "mipraster/core/huge_pages.hpp"

namespace mipraster {

/// Linear float pixels, row-major (H, W, C), row 0 is the top row. Colour images are
/// premultiplied RGBA (C = 4) as the framebuffer produces them.
struct Image {
    int width = 0;
    int height = 0;
    int channels = 0;
    std::vector<float> pixels;

    Image() = default;
    /// Zero-filled; a large one on huge pages (a render's image is written once, right away).
    Image(int w, int h, int c) : width(w), height(h), channels(c) {
        const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * static_cast<std::size_t>(c);
        reserve_on_huge_pages(pixels, n);
        pixels.resize(n, 0.0f);
    }

    float& at(int x, int y, int c) { return pixels[(static_cast<std::size_t>(y) * width + x) * channels + c]; }
    float at(int x, int y, int c) const { return pixels[(static_cast<std::size_t>(y) * width + x) * channels + c]; }

    std::string to_string() const;
};

}  // namespace mipraster
