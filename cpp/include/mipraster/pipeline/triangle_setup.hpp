#pragma once
// Triangle setup: project and snap to 16.8 fixed point, cull, and build the exact integer edge
// equations (top-left rule folded in) and the depth and 1/w planes the rasterizer steps.
#include <array>
#include <cmath>
#include <cstdint>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/clip.hpp"
#include "mipraster/pipeline/draw.hpp"
#include "mipraster/scene/camera.hpp"

namespace mipraster {

/// A triangle ready for rasterization. Edge i is opposite vertex i; at a sample (X, Y) in
/// 1/256 px, E_i = a_i·X + b_i·Y + c_i is exact in int64, and the sample is inside iff all three
/// E_i ≥ 0 (c_i already includes the top-left bias; `bias_i` adds it back for barycentrics).
struct SetupTriangle {
    std::array<std::int32_t, 3> edge_a, edge_b;
    std::array<std::int64_t, 3> edge_c;
    std::array<std::int8_t, 3> bias;
    std::int32_t min_x, min_y, max_x, max_y;  ///< inclusive pixel bounds, inside the viewport
    double inv_area2;                         ///< 1 / (twice the area in 1/256² px²)
    double z0, dz1, dz2;                      ///< depth = z0 + λ1·dz1 + λ2·dz2 (window depth), rounded to float once
    std::array<float, 3> inv_w;               ///< 1/w at each vertex, times a power of two (see setup_triangle)
    std::int32_t clip_index;                  ///< −1, or which clipped-weights entry maps vertices to the original
    std::uint32_t triangle;                   ///< index of the original triangle within its draw
    std::uint32_t draw;                       ///< index of the draw
};

/// Weights of the original triangle's vertices at the three vertices of a clipped sub-triangle.
using ClipWeights = std::array<glm::vec3, 3>;

/// What setup rejected, by reason.
struct SetupCounters {
    std::uint64_t culled_backface = 0, culled_degenerate = 0, culled_outside = 0, dropped_nonfinite = 0;
    std::uint64_t culled_between_samples = 0;  ///< in the viewport, with no sample position in its box
};

struct Viewport {
    int width = 0, height = 0;
    DepthConvention depth_convention = DepthConvention::reverse_z;
    /// Where a pixel's samples lie, in 1/256 px from its top-left corner: the smallest and largest
    /// offsets of the sample pattern in x and y. A triangle's bounds are the pixels with a sample
    /// position inside its box, so that a small triangle visits fewer pixels and tiles, and one
    /// between the samples is not set up (culled_between_samples). (The defaults, the whole pixel,
    /// suit every pattern.)
    static constexpr std::int32_t kLastSubpixel = static_cast<std::int32_t>(kSubpixelOne - 1);
    std::int32_t sample_x0 = 0, sample_x1 = kLastSubpixel, sample_y0 = 0, sample_y1 = kLastSubpixel;
};

/// A clip-space vertex on the screen: its position snapped to 1/256 px (y down), how far the
/// snapping moved it (in 1/256 px, within ±½), its window depth at the unsnapped position and 1/w.
/// Not valid (inv_w = 0) when a projected coordinate is not finite or beyond kMaxFixedCoordinate,
/// or 1/w is not a positive normal double; the other fields are then meaningless. (32 bytes: setup
/// reads three per triangle. No default values: a frame's array of them is sized, then written
/// only where a vertex is inside the clip volume; ScreenVertex{} is all zeros.)
struct ScreenVertex {
    std::int32_t x, y;
    double inv_w;
    double depth;
    float snap_x, snap_y;  // snapped − unsnapped position
    bool valid() const { return inv_w > 0.0; }
};
static_assert(sizeof(ScreenVertex) == 32);

/// Projects and snaps one clip-space vertex. A vertex shared by several triangles is projected
/// once: the result is the same whichever triangle asks. (Inline: returned through memory, the
/// struct's reload waited on its stores.)
inline ScreenVertex project_vertex(const glm::dvec4& p, const Viewport& viewport) {
    // Snap to 1/256 px, round half to even (the default rounding mode of nearbyint). Clipping
    // bounded |x|, |y| by the guard band.
    const double half_w = 0.5 * viewport.width, half_h = 0.5 * viewport.height;
    const double limit = static_cast<double>(kMaxFixedCoordinate);
    const double inv_w = 1.0 / p.w;
    const double x = (p.x * inv_w + 1.0) * half_w * kSubpixelOne, y = (1.0 - p.y * inv_w) * half_h * kSubpixelOne;
    const double xs = std::nearbyint(x), ys = std::nearbyint(y);
    const double z = p.z * inv_w;
    ScreenVertex v{};
    v.depth = viewport.depth_convention == DepthConvention::opengl ? 0.5 * z + 0.5 : z;
    // Only finite, in-range values may be converted to integers. Clipping keeps w ≥ kMinClipW, so
    // 1/w is positive; a vertex that breaks this is not projected.
    if (!(std::fabs(xs) <= limit && std::fabs(ys) <= limit && std::isfinite(v.depth) && inv_w > 0.0 &&
          std::isnormal(inv_w)))
        return v;
    v.x = static_cast<std::int32_t>(xs);
    v.y = static_cast<std::int32_t>(ys);
    v.snap_x = static_cast<float>(xs - x);
    v.snap_y = static_cast<float>(ys - y);
    v.inv_w = inv_w;
    return v;
}

/// Sets up the triangle with screen vertices v[0..2]. Returns false (and counts why) when it is
/// culled: an invalid vertex, back/front facing per `cull`, zero area after snapping, or no pixel
/// of the viewport in its bounds.
bool setup_triangle(const std::array<ScreenVertex, 3>& v, const Viewport& viewport, CullMode cull, SetupTriangle& out,
                    SetupCounters& counters);

/// setup_triangle for triangles i < count ≤ 4 at once, triangle i's vertices *v[i][0..2], with
/// AVX2 (triangle_setup_avx2.cpp): for each, the same outcome, counts and, where it is set up,
/// the same bits in out[i] (its triangle, draw and clip_index left as they are). Returns the
/// set-up triangles' mask (bit i: triangle i). v[i] for i ≥ count is not read. Only where
/// setup_in_fours().
int setup_four_triangles(const ScreenVertex* const (&v)[4][3], int count, const Viewport& viewport, CullMode cull,
                         SetupTriangle (&out)[4], SetupCounters& counters);

/// For clip-space vertices p[0..3]: outcodes[i] = kNonFinite where a coordinate is NaN or
/// infinite, else outcode(p[i], volume), and where that is 0, screen[i] = project_vertex(p[i])
/// (else screen[i] is not written). With AVX2 (triangle_setup_avx2.cpp), the bits of the scalar
/// functions. Only where setup_in_fours().
void classify_and_project_four(const glm::dvec4* p, const ClipVolume& volume, const Viewport& viewport,
                               std::uint8_t* outcodes, ScreenVertex* screen);

/// Whether this CPU has setup_four_triangles and classify_and_project_four (AVX2).
bool setup_in_fours();

/// The same for clip-space vertices p[0..2], projected here.
bool setup_triangle(const std::array<glm::dvec4, 3>& p, const Viewport& viewport, CullMode cull, SetupTriangle& out,
                    SetupCounters& counters);

}  // namespace mipraster
