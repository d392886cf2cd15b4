#pragma once
// A plain linear-float image: (height, width, channels), row 0 at the top.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "mipraster/core/block_recycler.hpp"
#include "mipraster/core/huge_pages.hpp"

namespace mipraster {

/// RecyclingAllocator, except that resize(n) leaves new elements default-initialized (for float:
/// unwritten), so a buffer that is about to be overwritten whole costs no zeroing pass. Starting
/// on a cache line matters here: tiles of a render write their own rows of one image from
/// different threads, and a line shared across a tile's edge would pass between their cores.
template <typename T>
struct DefaultInitAllocator : RecyclingAllocator<T> {
    template <typename U>
    struct rebind {
        using other = DefaultInitAllocator<U>;
    };
    DefaultInitAllocator() = default;
    template <typename U>
    DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        if constexpr (sizeof...(Args) == 0) ::new (static_cast<void*>(p)) U;
        else ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

/// Linear float pixels, row-major (H, W, C), row 0 is the top row. Colour images are
/// premultiplied RGBA (C = 4) as the framebuffer produces them.
struct Image {
    int width = 0;
    int height = 0;
    int channels = 0;
    std::vector<float, DefaultInitAllocator<float>> pixels;

    Image() = default;
    /// Zero-filled; a large one on huge pages (a render's image is written once, right away).
    Image(int w, int h, int c) : Image(unfilled(w, h, c)) { std::fill(pixels.begin(), pixels.end(), 0.0f); }

    /// With its pixels unwritten, for a caller that writes every one (a render's colour image).
    static Image unfilled(int w, int h, int c) {
        Image image;
        image.width = w, image.height = h, image.channels = c;
        const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * static_cast<std::size_t>(c);
        reserve_on_huge_pages(image.pixels, n);
        image.pixels.resize(n);
        return image;
    }

    float& at(int x, int y, int c) { return pixels[(static_cast<std::size_t>(y) * width + x) * channels + c]; }
    float at(int x, int y, int c) const { return pixels[(static_cast<std::size_t>(y) * width + x) * channels + c]; }

    std::string to_string() const;
};

}  // namespace mipraster
