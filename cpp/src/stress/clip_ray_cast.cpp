#include "mipraster/stress/clip_ray_cast.hpp"

#include <cmath>

namespace mipraster::stress {

ClipHit ray_cast_clip(const std::array<glm::dvec4, 3>& p, double x, double y, bool reverse_z) {
    ClipHit h;
    // Rows: Σ b_i·r_i = 0, Σ b_i·s_i = 0, Σ b_i = 1.
    double r[3], s[3];
    for (int i = 0; i < 3; ++i) {
        r[i] = p[i].x - x * p[i].w;
        s[i] = p[i].y - y * p[i].w;
    }
    // Cramer: b_i is the cofactor of the (1, 1, 1) row, over the determinant.
    const double c0 = r[1] * s[2] - r[2] * s[1];
    const double c1 = r[2] * s[0] - r[0] * s[2];
    const double c2 = r[0] * s[1] - r[1] * s[0];
    const double det = c0 + c1 + c2;
    if (det == 0.0 || !std::isfinite(det)) return h;
    h.weights = glm::dvec3(c0, c1, c2) / det;
    h.w = h.weights.x * p[0].w + h.weights.y * p[1].w + h.weights.z * p[2].w;
    const double z = h.weights.x * p[0].z + h.weights.y * p[1].z + h.weights.z * p[2].z;
    const bool inside = h.weights.x >= 0.0 && h.weights.y >= 0.0 && h.weights.z >= 0.0;
    const bool in_depth = reverse_z ? (z >= 0.0 && z <= h.w) : (z >= -h.w && z <= h.w);
    h.hit = inside && h.w > 0.0 && in_depth;
    h.window_depth = h.w > 0.0 ? (reverse_z ? z / h.w : 0.5 * z / h.w + 0.5) : 0.0;
    return h;
}

}  // namespace mipraster::stress
