#pragma once
// Homogeneous clipping: always against the near (and far) plane, against the sides only where a
// triangle leaves the guard band, so that every coordinate after it fits the fixed-point range.
#include <array>
#include <cstdint>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mipraster/scene/camera.hpp"

namespace mipraster {

/// A clip-space vertex and its weights of the original triangle's three vertices.
struct ClipVertex {
    glm::dvec4 position;
    glm::dvec3 weights;
};

/// Inside the volume ⇔ dot(normal, p) + offset ≥ 0 for every plane.
struct ClipPlane {
    glm::dvec4 normal;
    double offset = 0.0;
    double distance(const glm::dvec4& p) const {  // (inline: seven per vertex)
        return normal.x * p.x + normal.y * p.y + normal.z * p.z + normal.w * p.w + offset;
    }
};

inline constexpr int kClipPlaneCount = 7;  // near, far, w > 0, and four guard-band sides
static_assert(kClipPlaneCount <= 8, "outcodes are 8-bit masks");

struct ClipVolume {
    std::array<ClipPlane, kClipPlaneCount> planes;
};

/// The clip volume of a viewport: depth range of `convention`, w ≥ kMinClipW, and sides at
/// the guard band (kGuardBandPx from the viewport centre).
ClipVolume make_clip_volume(DepthConvention convention, int width, int height);

/// A clipped convex polygon: at most 3 + one vertex per plane.
struct ClipPolygon {
    int count = 0;
    std::array<ClipVertex, 3 + kClipPlaneCount> vertices;
};

enum class ClipOutcome { inside, outside, clipped };

/// The outcode of a vertex with a NaN or infinite coordinate (e.g. from a degenerate matrix):
/// no plane's bit.
inline constexpr std::uint8_t kNonFinite = 0x80;
static_assert(kClipPlaneCount < 8, "kNonFinite must not collide with a plane bit");

/// Bit i set ⇔ p is outside plane i. Computed once per vertex; a triangle is trivially inside
/// when its vertices' outcodes OR to 0 and trivially outside when they AND to non-zero.
inline std::uint8_t outcode(const glm::dvec4& p, const ClipVolume& volume) {
    std::uint8_t code = 0;
    for (int i = 0; i < kClipPlaneCount; ++i)
        if (!(volume.planes[i].distance(p) >= 0.0)) code |= static_cast<std::uint8_t>(1u << i);
    return code;
}

/// Whether the triangle projects to a line (or a point): its homogeneous vertices (x, y, w) are
/// linearly dependent — collinear on screen, or in a plane through the eye — up to the rounding
/// of the 3×3 determinant in double. Clipping such a triangle rounds its new vertices off the line
/// and gives it area it does not have, so it is culled before clipping; an unclipped one is
/// found exactly by setup's integer area.
bool projects_to_a_line(const std::array<glm::dvec4, 3>& p);

/// Classifies the triangle by its vertices' outcodes; when it crosses a plane, fills `out` with
/// the clipped polygon (Sutherland–Hodgman). Each crossing point is computed from its edge's
/// endpoints in a fixed order, so a shared edge clips to bit-identical vertices from either
/// triangle.
ClipOutcome clip_triangle(const std::array<glm::dvec4, 3>& p, const std::array<std::uint8_t, 3>& outcodes,
                          const ClipVolume& volume, ClipPolygon& out);

}  // namespace mipraster
