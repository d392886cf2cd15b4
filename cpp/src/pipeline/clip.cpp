#include "mipraster/pipeline/clip.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mipraster/core/constants.hpp"

namespace mipraster {

ClipVolume make_clip_volume(DepthConvention convention, int width, int height) {
    // |x_ndc| ≤ gx keeps the screen x within kGuardBandPx of the viewport centre.
    const double gx = 2.0 * kGuardBandPx / width, gy = 2.0 * kGuardBandPx / height;
    ClipVolume v;
    if (convention == DepthConvention::opengl) {
        v.planes[0] = {{0, 0, 1, 1}, 0.0};   // near: z ≥ −w
        v.planes[1] = {{0, 0, -1, 1}, 0.0};  // far: z ≤ w
    } else {
        v.planes[0] = {{0, 0, -1, 1}, 0.0};  // near: z ≤ w
        v.planes[1] = {{0, 0, 1, 0}, 0.0};   // far: z ≥ 0
    }
    v.planes[2] = {{0, 0, 0, 1}, -kMinClipW};  // w ≥ kMinClipW: nothing at or behind the eye
    v.planes[3] = {{-1, 0, 0, gx}, 0.0};
    v.planes[4] = {{1, 0, 0, gx}, 0.0};
    v.planes[5] = {{0, -1, 0, gy}, 0.0};
    v.planes[6] = {{0, 1, 0, gy}, 0.0};
    return v;
}

namespace {

bool lexicographically_less(const glm::dvec4& a, const glm::dvec4& b) {
    for (int i = 0; i < 4; ++i)
        if (a[i] != b[i]) return a[i] < b[i];
    return false;
}

#if defined(__SIZEOF_FLOAT128__)
using Quad = __float128;  // (IEEE binary128 in software: 113-bit significands)
#else
using Quad = long double;
#endif

// The point where edge (a, b) crosses the plane, always computed from the endpoint nearer the
// plane (on a tie, the lexicographically smaller) so that (a, b) and (b, a) give the same bits.
// From the far endpoint, a crossing next to a vertex 10^20 behind the eye came out as the
// difference of two numbers of 10^19, rounded to w = 0. Position and weights are computed in long
// double and rounded once: an endpoint 10^15 px away has a double ulp of 1/8 px, and
// a + t·(b − a) in double would move the crossing that far off the edge's line (stress suite,
// case 3); the crossing itself lies near the guard band, where double is ample. Endpoints beyond
// kWideCrossingRatio take Quad throughout, the distances included (exact products of doubles).
ClipVertex intersect(const ClipPlane& plane, const ClipVertex& a, double da, const ClipVertex& b, double db) {
    const double off_a = std::fabs(da), off_b = std::fabs(db);  // distances from the plane
    if (off_b < off_a || (off_b == off_a && lexicographically_less(b.position, a.position)))
        return intersect(plane, b, db, a, da);
    double size = 0.0;
    for (int i = 0; i < 4; ++i) size = std::max({size, std::fabs(a.position[i]), std::fabs(b.position[i])});
    const bool wide = !(size <= kWideCrossingRatio * std::min(std::fabs(a.position.w), std::fabs(b.position.w)));
    const auto crossing = [&](auto wide_zero) {
        using Wide = decltype(wide_zero);
        const auto distance = [&](const glm::dvec4& p) {
            Wide d = Wide(plane.offset);
            for (int i = 0; i < 4; ++i) d += Wide(plane.normal[i]) * Wide(p[i]);
            return d;
        };
        // The edge's parameter from the double distances, or in Quad from the distances again.
        // (The double distances chose the edge; in Quad the crossing may land a hair beyond an
        // endpoint, or their difference be 0: kept on the edge.)
        const Wide wa = wide ? distance(a.position) : Wide(da), wb = wide ? distance(b.position) : Wide(db);
        const Wide t = !wide ? wa / (wa - wb) : wa == wb ? Wide(0) : std::clamp(wa / (wa - wb), Wide(0), Wide(1));
        const auto along = [&](double from, double to) {
            return static_cast<double>(Wide(from) + t * (Wide(to) - Wide(from)));
        };
        ClipVertex out;
        for (int i = 0; i < 4; ++i) out.position[i] = along(a.position[i], b.position[i]);
        for (int i = 0; i < 3; ++i) out.weights[i] = along(a.weights[i], b.weights[i]);
        return out;
    };
    return wide ? crossing(Quad(0)) : crossing(static_cast<long double>(0));
}

}  // namespace

bool projects_to_a_line(const std::array<glm::dvec4, 3>& p) {
    // det[x y w] by the first column, and the same sum over absolute values (the permanent): the
    // evaluation's rounding error is at most a few ulps of the permanent.
    const double m0 = p[1].y * p[2].w - p[1].w * p[2].y, n0 = std::fabs(p[1].y * p[2].w) + std::fabs(p[1].w * p[2].y);
    const double m1 = p[1].x * p[2].w - p[1].w * p[2].x, n1 = std::fabs(p[1].x * p[2].w) + std::fabs(p[1].w * p[2].x);
    const double m2 = p[1].x * p[2].y - p[1].y * p[2].x, n2 = std::fabs(p[1].x * p[2].y) + std::fabs(p[1].y * p[2].x);
    const double det = p[0].x * m0 - p[0].y * m1 + p[0].w * m2;
    const double permanent = std::fabs(p[0].x) * n0 + std::fabs(p[0].y) * n1 + std::fabs(p[0].w) * n2;
    return std::fabs(det) <= kProjectedAreaRoundingUlps * std::numeric_limits<double>::epsilon() * permanent;
}

ClipOutcome clip_triangle(const std::array<glm::dvec4, 3>& p, const std::array<std::uint8_t, 3>& outcodes,
                          const ClipVolume& volume, ClipPolygon& out) {
    if ((outcodes[0] | outcodes[1] | outcodes[2]) == 0) return ClipOutcome::inside;
    if ((outcodes[0] & outcodes[1] & outcodes[2]) != 0) return ClipOutcome::outside;

    // Sutherland–Hodgman, one plane at a time, ping-ponging between two polygons.
    ClipPolygon scratch;
    ClipPolygon* src = &out;
    ClipPolygon* dst = &scratch;
    src->count = 3;
    src->vertices[0] = {p[0], {1, 0, 0}};
    src->vertices[1] = {p[1], {0, 1, 0}};
    src->vertices[2] = {p[2], {0, 0, 1}};
    // Every plane, even one no input vertex crosses: a rounded crossing point may lie a hair
    // outside it, and a neighbour sharing the edge must make the same cut.
    for (const ClipPlane& plane : volume.planes) {
        dst->count = 0;
        for (int i = 0; i < src->count; ++i) {
            const ClipVertex& a = src->vertices[i];
            const ClipVertex& b = src->vertices[(i + 1) % src->count];
            const double da = plane.distance(a.position), db = plane.distance(b.position);
            if (da >= 0.0) dst->vertices[dst->count++] = a;
            if ((da >= 0.0) != (db >= 0.0)) dst->vertices[dst->count++] = intersect(plane, a, da, b, db);
        }
        std::swap(src, dst);
        if (src->count < 3) {
            out.count = 0;
            return ClipOutcome::outside;
        }
    }
    if (src != &out) out = *src;
    return ClipOutcome::clipped;
}

}  // namespace mipraster
