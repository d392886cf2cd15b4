#include "mipraster/pipeline/clip.hpp"

#include "mipraster/core/constants.hpp"

namespace mipraster {

double ClipPlane::distance(const glm::dvec4& p) const {
    return normal.x * p.x + normal.y * p.y + normal.z * p.z + normal.w * p.w + offset;
}

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

// The point where edge (a, b) crosses the plane, always computed from the lexicographically
// smaller endpoint so that (a, b) and (b, a) give the same bits.
ClipVertex intersect(const ClipVertex& a, double da, const ClipVertex& b, double db) {
    if (lexicographically_less(b.position, a.position)) return intersect(b, db, a, da);
    const double t = da / (da - db);
    return {a.position + t * (b.position - a.position), a.weights + t * (b.weights - a.weights)};
}

}  // namespace

ClipOutcome clip_triangle(const glm::dvec4& p0, const glm::dvec4& p1, const glm::dvec4& p2, const ClipVolume& volume,
                          ClipPolygon& out) {
    // Trivial accept / reject by the per-plane outcodes.
    bool crosses = false;
    for (const ClipPlane& plane : volume.planes) {
        const int inside = (plane.distance(p0) >= 0.0) + (plane.distance(p1) >= 0.0) + (plane.distance(p2) >= 0.0);
        if (inside == 0) return ClipOutcome::outside;
        crosses |= inside != 3;
    }
    if (!crosses) return ClipOutcome::inside;

    // Sutherland–Hodgman, one plane at a time, ping-ponging between two polygons.
    ClipPolygon scratch;
    ClipPolygon* src = &out;
    ClipPolygon* dst = &scratch;
    src->count = 3;
    src->vertices[0] = {p0, {1, 0, 0}};
    src->vertices[1] = {p1, {0, 1, 0}};
    src->vertices[2] = {p2, {0, 0, 1}};
    for (const ClipPlane& plane : volume.planes) {
        dst->count = 0;
        for (int i = 0; i < src->count; ++i) {
            const ClipVertex& a = src->vertices[i];
            const ClipVertex& b = src->vertices[(i + 1) % src->count];
            const double da = plane.distance(a.position), db = plane.distance(b.position);
            if (da >= 0.0) dst->vertices[dst->count++] = a;
            if ((da >= 0.0) != (db >= 0.0)) dst->vertices[dst->count++] = intersect(a, da, b, db);
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
