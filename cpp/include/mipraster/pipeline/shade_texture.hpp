#pragma once
// Texture shading: uv of a sample from the triangle's planes, its screen-space derivatives
// (analytic chain rule, or 2×2-quad finite differences), and the debug views.
#include <cstdint>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/draw.hpp"
#include "mipraster/pipeline/interpolate.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace mipraster {

/// How uv derivatives are computed: analytically from the 1/w and uv/w planes (the seeds'
/// chain rule; exact per sample), or as differences between the pixel centres of the 2×2 pixel
/// quad holding the pixel, the way GPUs do (coarse derivatives; the triangle's planes are
/// evaluated at quad pixels outside it, as GPU helper invocations do).
enum class DerivativeMode { analytic, quad };

/// Replace the texture lookup of textured draws by a picture of what it would do: the colour
/// of the mip level λ selects (blended between levels for fractional λ, the notes' "visualization
/// of mip-map level"), or uv as colour (fract(u), fract(v), 0).
enum class DebugView { none, mip_level, uv };

std::string to_string(DerivativeMode mode);
std::string to_string(DebugView view);
DerivativeMode parse_derivative_mode(const std::string& name);
DebugView parse_debug_view(const std::string& name);

/// Colour of λ in the mip-level view: a fixed palette per level, linear between levels.
glm::vec4 mip_level_colour(double lambda);

/// uv at a point and its change per pixel step in x and y.
struct UvSample {
    glm::dvec2 uv{0.0}, dx{0.0}, dy{0.0};
};

/// The uvs of a set-up triangle's three vertices (mapped through the clip weights when it is a
/// clipped piece), the provoking vertex's uv for flat interpolation, and the screen weights'
/// change per pixel step (for the derivatives; once per triangle rather than per sample).
struct TriangleUvs {
    glm::dvec2 v[3];
    glm::dvec2 flat;
    glm::dvec3 lx, ly;  // ∂λ_i/∂x = a_i·256/2A, ∂λ_i/∂y = b_i·256/2A
    // Perspective-correct uv = N/D with N = Σ λ_i q_i uv_i and D = Σ λ_i q_i (q_i = 1/w_i): their
    // changes per pixel step are constant over the triangle.
    glm::dvec2 numerator_dx, numerator_dy;  // Σ ∂λ_i/∂x·q_i·uv_i, and along y
    double denominator_dx, denominator_dy;  // Σ ∂λ_i/∂x·q_i, and along y

    TriangleUvs() = default;
    TriangleUvs(const SetupTriangle& t, const glm::uvec3& tri, const glm::vec2* uvs, const ClipWeights* clip_weights) {
        const glm::dvec2 o[3] = {glm::dvec2(uvs[tri[0]]), glm::dvec2(uvs[tri[1]]), glm::dvec2(uvs[tri[2]])};
        flat = o[0];
        const double k = static_cast<double>(kSubpixelOne) * t.inv_area2;
        lx = glm::dvec3(t.edge_a[0] * k, t.edge_a[1] * k, t.edge_a[2] * k);
        ly = glm::dvec3(t.edge_b[0] * k, t.edge_b[1] * k, t.edge_b[2] * k);
        for (int i = 0; i < 3; ++i) {
            if (t.clip_index < 0) {
                v[i] = o[i];
            } else {
                const glm::dvec3 w(clip_weights[t.clip_index][i]);
                v[i] = w.x * o[0] + w.y * o[1] + w.z * o[2];
            }
        }
        const glm::dvec3 q(t.inv_w[0], t.inv_w[1], t.inv_w[2]);
        const glm::dvec3 qx = lx * q, qy = ly * q;
        numerator_dx = qx.x * v[0] + qx.y * v[1] + qx.z * v[2];
        numerator_dy = qy.x * v[0] + qy.y * v[1] + qy.z * v[2];
        denominator_dx = qx.x + qx.y + qx.z;
        denominator_dy = qy.x + qy.y + qy.z;
    }
};

/// uv at screen-space weights l with analytic derivatives. Screen weights are affine in the
/// pixel position: ∂λ_i/∂x = a_i·256/2A. Perspective-correct uv = N/D = Σλ_i q_i uv_i / Σλ_i q_i
/// with q_i = 1/w_i, so ∂uv/∂x = (∂N/∂x − uv·∂D/∂x) / D (the quotient rule), with ∂N/∂x and ∂D/∂x
/// the triangle's constants.
/// Without kDerivatives only uv is computed (dx, dy stay zero).
template <bool kDerivatives = true>
inline UvSample interpolate_uv(const SetupTriangle& t, const TriangleUvs& uvs, const glm::dvec3& l,
                               Interpolation mode) {
    UvSample s;
    if (mode == Interpolation::flat) {
        s.uv = uvs.flat;
        return s;
    }
    if constexpr (!kDerivatives) {
        const glm::dvec3 q = mode == Interpolation::screen ? l : perspective_weights(t, l);
        s.uv = q.x * uvs.v[0] + q.y * uvs.v[1] + q.z * uvs.v[2];
        return s;
    }
    const glm::dvec3& lx = uvs.lx;
    const glm::dvec3& ly = uvs.ly;
    if (mode == Interpolation::screen) {
        s.uv = l.x * uvs.v[0] + l.y * uvs.v[1] + l.z * uvs.v[2];
        s.dx = lx.x * uvs.v[0] + lx.y * uvs.v[1] + lx.z * uvs.v[2];
        s.dy = ly.x * uvs.v[0] + ly.y * uvs.v[1] + ly.z * uvs.v[2];
        return s;
    }
    const glm::dvec3 q(l.x * t.inv_w[0], l.y * t.inv_w[1], l.z * t.inv_w[2]);
    const double inv_d = 1.0 / (q.x + q.y + q.z);
    s.uv = (q.x * uvs.v[0] + q.y * uvs.v[1] + q.z * uvs.v[2]) * inv_d;
    s.dx = (uvs.numerator_dx - s.uv * uvs.denominator_dx) * inv_d;
    s.dy = (uvs.numerator_dy - s.uv * uvs.denominator_dy) * inv_d;
    return s;
}

/// Derivatives as differences of uv between the centres of the 2×2 quad holding pixel (px, py):
/// ∂x from its top pair, ∂y from its left pair (coarse derivatives, one per quad). Falls back to
/// the analytic ones when the planes give a non-finite value outside the triangle (e.g. beyond
/// its horizon line).
inline void quad_derivatives(const SetupTriangle& t, const TriangleUvs& uvs, Interpolation mode, int px, int py,
                             UvSample& s) {
    const std::int64_t half = kSubpixelOne / 2;
    const std::int64_t X = std::int64_t{px & ~1} * kSubpixelOne + half, Y = std::int64_t{py & ~1} * kSubpixelOne + half;
    auto uv_at = [&](std::int64_t x, std::int64_t y) {
        const std::int64_t e0 = t.edge_a[0] * x + t.edge_b[0] * y + t.edge_c[0];
        const std::int64_t e1 = t.edge_a[1] * x + t.edge_b[1] * y + t.edge_c[1];
        const std::int64_t e2 = t.edge_a[2] * x + t.edge_b[2] * y + t.edge_c[2];
        return interpolate_uv<false>(t, uvs, screen_weights(t, e0, e1, e2), mode).uv;
    };
    const glm::dvec2 base = uv_at(X, Y);
    const glm::dvec2 dx = uv_at(X + kSubpixelOne, Y) - base, dy = uv_at(X, Y + kSubpixelOne) - base;
    if (std::isfinite(dx.x) && std::isfinite(dx.y) && std::isfinite(dy.x) && std::isfinite(dy.y)) {
        s.dx = dx;
        s.dy = dy;
    }
}

}  // namespace mipraster
