#pragma once
// One level of a texture and the level-generation filter (DESIGN.md §1: mip levels).
#include <cstddef>
#include <vector>

#include <glm/vec4.hpp>

#include "mipraster/core/huge_pages.hpp"

namespace mipraster {

/// Linear, premultiplied RGBA texels, row-major, row 0 at v = 0.
struct TextureLevel {
    int width = 0, height = 0;
    std::vector<glm::vec4> texels;

    TextureLevel() = default;
    // On huge pages where large: a bilinear quad's rows lie a whole texel row apart, and a line of
    // anisotropic probes crosses many, each a 4 KiB page of its own without them (TLB misses).
    TextureLevel(int w, int h) : width(w), height(h) {
        const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
        reserve_on_huge_pages(texels, n);
        texels.resize(n);
    }
    const glm::vec4& at(int x, int y) const { return texels[static_cast<std::size_t>(y) * width + x]; }
    glm::vec4& at(int x, int y) { return texels[static_cast<std::size_t>(y) * width + x]; }
    std::size_t bytes() const { return texels.size() * sizeof(glm::vec4); }
};

/// Number of levels of a w×h texture: level k is max(1, ⌊w/2^k⌋)×max(1, ⌊h/2^k⌋), down to 1×1.
int mip_level_count(int width, int height);

/// The next level: max(1, ⌊w/2⌋)×max(1, ⌊h/2⌋). Each output texel is the area-weighted mean of
/// the source texels under its cell (cell width w/⌊w/2⌋): a 2×2 box for even sizes; for odd sizes
/// every source texel contributes, the middle one split between neighbours. Sums in double, so a
/// constant level reduces to the same constant exactly, and the mean of the level is kept.
TextureLevel downsample(const TextureLevel& source);

}  // namespace mipraster
