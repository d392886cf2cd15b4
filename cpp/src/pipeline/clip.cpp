#include "mipraster/pipeline/clip.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

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
constexpr Quad kQuadEpsilon = 0x1p-112;
#else
using Quad = long double;
constexpr Quad kQuadEpsilon = std::numeric_limits<long double>::epsilon();
#endif

// Coordinate i of the point where edge (a, b) crosses the plane, whose distances from it are da and
// db (of opposite signs): (da·b − db·a)/(da − db), written as Σ_j n_j·(a_j·b_i − b_j·a_i) plus the
// offset's term over da − db. Each 2×2 minor is a difference of exact products, rounded once, so
// it keeps its own relative precision however large a and b are; a + t·(b − a) did not: with
// both endpoints 10^50 × w out and the crossing near the guard band, t rounded to ½ and the
// crossing landed at the viewport's centre (half a covering triangle was lost).
Quad wide_crossing(const ClipPlane& plane, const glm::dvec4& a, const glm::dvec4& b, Quad da, Quad db, int i) {
    Quad sum = Quad(plane.offset) * (Quad(b[i]) - Quad(a[i]));
    for (int j = 0; j < 4; ++j)
        if (j != i && plane.normal[j] != 0.0)
            sum += Quad(plane.normal[j]) * (Quad(a[j]) * Quad(b[i]) - Quad(b[j]) * Quad(a[i]));
    return sum / (da - db);
}

// The point where edge (a, b) crosses the plane, always computed from the endpoint nearer the
// plane (on a tie, the lexicographically smaller) so that (a, b) and (b, a) give the same bits.
// From the far endpoint, a crossing next to a vertex 10^20 behind the eye came out as the
// difference of two numbers of 10^19, rounded to w = 0. Position and weights are computed in long
// double and rounded once: an endpoint 10^15 px away has a double ulp of 1/8 px, and
// a + t·(b − a) in double would move the crossing that far off the edge's line (stress suite,
// case 3); the crossing itself lies near the guard band, where double is ample. Endpoints beyond
// kWideCrossingRatio take Quad throughout, the distances included (exact products of doubles),
// and the position from the edge's 2×2 minors (wide_crossing).
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
        for (int i = 0; i < 4; ++i)
            out.position[i] = wide && wa != wb ? static_cast<double>(wide_crossing(plane, a.position, b.position,
                                                                                   Quad(wa), Quad(wb), i))
                                               : along(a.position[i], b.position[i]);
        for (int i = 0; i < 3; ++i) out.weights[i] = along(a.weights[i], b.weights[i]);
        return out;
    };
    return wide ? crossing(Quad(0)) : crossing(static_cast<long double>(0));
}

}  // namespace

namespace {

// det[x y w] by the first column, and the same sum over absolute values (the permanent), in T:
// the evaluation's rounding error is at most a few ulps of T of the permanent. (In Quad, each
// 2×2 minor is a difference of exact products.)
template <class T>
bool determinant_below_rounding(const std::array<glm::dvec3, 3>& p) {
    const auto minor = [&](int i, int j, T& bound) {
        const T a = T(p[1][i]) * T(p[2][j]), b = T(p[1][j]) * T(p[2][i]);
        bound = (a < 0 ? -a : a) + (b < 0 ? -b : b);
        return a - b;
    };
    T n0, n1, n2;
    const T m0 = minor(1, 2, n0), m1 = minor(0, 2, n1), m2 = minor(0, 1, n2);
    const T det = T(p[0].x) * m0 - T(p[0].y) * m1 + T(p[0].z) * m2;
    const T permanent = T(std::fabs(p[0].x)) * n0 + T(std::fabs(p[0].y)) * n1 + T(std::fabs(p[0].z)) * n2;
    const T epsilon = std::is_same_v<T, double> ? T(std::numeric_limits<double>::epsilon()) : T(kQuadEpsilon);
    return (det < 0 ? -det : det) <= T(kProjectedAreaRoundingUlps) * epsilon * permanent;
}

}  // namespace

bool projects_to_a_line(const std::array<glm::dvec4, 3>& clip) {
    // Each vertex scaled by the power of two that brings its largest |x|, |y|, |w| into [1, 2):
    // both sides of the test scale alike with a vertex, and the products then neither overflow
    // nor vanish (vertices 10^160 × w out made the determinant infinite, and the triangle was
    // dropped as degenerate).
    std::array<glm::dvec3, 3> p;
    for (int k = 0; k < 3; ++k) {
        const glm::dvec3 v(clip[k].x, clip[k].y, clip[k].w);
        const double largest = std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
        const int exponent = largest > 0.0 ? std::ilogb(largest) : 0;
        p[k] = {std::ldexp(v.x, -exponent), std::ldexp(v.y, -exponent), std::ldexp(v.z, -exponent)};
    }
    // What double cannot tell from a line, Quad looks at again: a sliver 10^-17 of its extent
    // thick, with vertices 10^152 px out, still covers half the image (binary128 resolves about
    // 10^-32 of the permanent; thinner ones count as lines).
    return determinant_below_rounding<double>(p) && determinant_below_rounding<Quad>(p);
}

ClipOutcome clip_triangle(const std::array<glm::dvec4, 3>& clip, const std::array<std::uint8_t, 3>& outcodes,
                          const ClipVolume& volume, ClipPolygon& out) {
    if ((outcodes[0] | outcodes[1] | outcodes[2]) == 0) return ClipOutcome::inside;
    // A triangle whose |w| all lie below kTinyClipScale (within 10^-20 of the eye, or from a
    // model matrix that scales w down) is clipped scaled up by a power of two: the plane
    // w ≥ kMinClipW is absolute and cut all of it away. One positive scale for all three vertices
    // leaves its projection, depth and perspective-correct weights as they were.
    std::array<glm::dvec4, 3> p = clip;
    std::array<std::uint8_t, 3> codes = outcodes;
    const double largest = std::max({std::fabs(clip[0].w), std::fabs(clip[1].w), std::fabs(clip[2].w)});
    if (largest > 0.0 && largest < kTinyClipScale) {
        const int exponent = std::ilogb(largest);
        for (int k = 0; k < 3; ++k) {
            for (int i = 0; i < 4; ++i) p[k][i] = std::ldexp(clip[k][i], -exponent);
            codes[k] = outcode(p[k], volume);
        }
    }
    if ((codes[0] & codes[1] & codes[2]) != 0) return ClipOutcome::outside;

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
