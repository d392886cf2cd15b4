// Texture shading: uv and its screen-space derivatives at a sample, against an independent oracle —
// the perspective-correct uv of the snapped triangle computed from double-precision cross products,
// differentiated numerically (central differences) — and the quad finite differences.
#include <array>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/interpolate.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace mr = mipraster;

namespace {

constexpr int kW = 256, kH = 192;

// The snapped screen position (pixels, y down) of a clip-space vertex, as setup computes it.
glm::dvec2 snapped(const glm::dvec4& p) {
    const double x = std::nearbyint((p.x / p.w + 1.0) * 0.5 * kW * 256.0) / 256.0;
    const double y = std::nearbyint((1.0 - p.y / p.w) * 0.5 * kH * 256.0) / 256.0;
    return {x, y};
}

// Perspective-correct (or affine) uv at screen point q of the snapped triangle: barycentrics from
// signed areas, weighted by 1/w — written from the definition, not from the library's edge form.
glm::dvec2 oracle_uv(const std::array<glm::dvec4, 3>& p, const std::array<glm::dvec2, 3>& uv, glm::dvec2 q,
                     bool perspective) {
    const glm::dvec2 a = snapped(p[0]), b = snapped(p[1]), c = snapped(p[2]);
    auto area = [](glm::dvec2 u, glm::dvec2 v, glm::dvec2 w) { return (v.x - u.x) * (w.y - u.y) - (v.y - u.y) * (w.x - u.x); };
    const double total = area(a, b, c);
    double l[3] = {area(q, b, c) / total, area(a, q, c) / total, area(a, b, q) / total};
    if (perspective) {
        double sum = 0.0;
        for (int i = 0; i < 3; ++i) sum += (l[i] /= p[i].w);
        for (double& li : l) li /= sum;
    }
    return l[0] * uv[0] + l[1] * uv[1] + l[2] * uv[2];
}

struct Case {
    std::array<glm::dvec4, 3> clip;
    std::array<glm::dvec2, 3> uv;
    mr::SetupTriangle setup;
};

// A random triangle well inside the viewport with w in [0.3, 30] (strong perspective).
bool random_case(std::mt19937_64& rng, Case& c) {
    std::uniform_real_distribution<double> ndc(-0.9, 0.9), w(0.3, 30.0), uv(-3.0, 3.0);
    for (int i = 0; i < 3; ++i) {
        const double wi = w(rng);
        c.clip[i] = {ndc(rng) * wi, ndc(rng) * wi, 0.5 * wi, wi};
        c.uv[i] = {uv(rng), uv(rng)};
    }
    mr::SetupCounters counters;
    c.setup.clip_index = -1;  // not a clipped piece (the renderer sets this, not setup)
    return mr::setup_triangle(c.clip, {kW, kH, mr::DepthConvention::opengl}, mr::CullMode::none, c.setup, counters) &&
           c.setup.max_x - c.setup.min_x > 8 && c.setup.max_y - c.setup.min_y > 8;
}

// Edge values at the fixed-point position (X, Y).
glm::dvec3 weights_at(const mr::SetupTriangle& t, std::int64_t X, std::int64_t Y) {
    std::int64_t e[3];
    for (int i = 0; i < 3; ++i) e[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
    return mr::screen_weights(t, e[0], e[1], e[2]);
}

mr::TriangleUvs triangle_uvs(const Case& c) {
    const glm::vec2 uvs[3] = {glm::vec2(c.uv[0]), glm::vec2(c.uv[1]), glm::vec2(c.uv[2])};
    mr::TriangleUvs t(c.setup, glm::uvec3(0, 1, 2), uvs, nullptr);
    return t;
}

}  // namespace

TEST(ShadeTexture, AnalyticDerivativesMatchCentralDifferencesOfThePerspectiveCorrectUv) {
    std::mt19937_64 rng(7);
    double worst = 0.0;
    int checked = 0;
    for (int n = 0; n < 400 && checked < 4000; ++n) {
        Case c;
        if (!random_case(rng, c)) continue;
        // The oracle uses the float uvs the library stores.
        for (auto& uv : c.uv) uv = glm::dvec2(glm::vec2(uv));
        const mr::TriangleUvs uvs = triangle_uvs(c);
        for (const bool perspective : {true, false}) {
            const mr::Interpolation mode = perspective ? mr::Interpolation::perspective : mr::Interpolation::screen;
            for (int py = c.setup.min_y; py <= c.setup.max_y; py += 3)
                for (int px = c.setup.min_x; px <= c.setup.max_x; px += 3) {
                    const std::int64_t X = px * std::int64_t{256} + 128, Y = py * std::int64_t{256} + 128;
                    const glm::dvec3 l = weights_at(c.setup, X, Y);
                    if (l.x < 0 || l.y < 0 || l.z < 0) continue;
                    const mr::UvSample s = mr::interpolate_uv(c.setup, uvs, l, mode);
                    const glm::dvec2 q(px + 0.5, py + 0.5);
                    const double h = 1e-3;
                    const glm::dvec2 dx = (oracle_uv(c.clip, c.uv, q + glm::dvec2(h, 0), perspective) -
                                           oracle_uv(c.clip, c.uv, q - glm::dvec2(h, 0), perspective)) / (2 * h);
                    const glm::dvec2 dy = (oracle_uv(c.clip, c.uv, q + glm::dvec2(0, h), perspective) -
                                           oracle_uv(c.clip, c.uv, q - glm::dvec2(0, h), perspective)) / (2 * h);
                    const glm::dvec2 uv = oracle_uv(c.clip, c.uv, q, perspective);
                    const double scale = 1.0 + glm::length(dx) + glm::length(dy);
                    for (int k = 0; k < 2; ++k) {
                        worst = std::max({worst, std::abs(s.dx[k] - dx[k]) / scale, std::abs(s.dy[k] - dy[k]) / scale});
                        // 1/w is stored as float: uv agrees to float precision.
                        ASSERT_NEAR(s.uv[k], uv[k], 1e-6 * (1.0 + std::abs(uv[k])));
                    }
                    ++checked;
                }
        }
    }
    EXPECT_GT(checked, 1000);
    // Central differences with h = 1e-3 px are accurate to ~1e-7 relative here; 1/w is a float.
    EXPECT_LT(worst, 1e-5) << "worst relative derivative error " << worst;
    RecordProperty("worst_relative_derivative_error", std::to_string(worst));
}

TEST(ShadeTexture, DerivativesDoNotChangeWhenEveryUvIsShiftedFarFromZero) {
    // uv + c changes by what uv changes by: the derivatives of a triangle with its uvs moved by
    // 2^16 (exact in float: the uvs are multiples of 1/64) are those of the unmoved one to 1e-9
    // relative (seen: 3e-12), although the sums that form them hold terms 2^16 times larger.
    std::mt19937_64 rng(11);
    std::uniform_int_distribution<int> sixty_fourths(-192, 192);
    double worst = 0.0;
    int checked = 0;
    for (int n = 0; n < 300 && checked < 3000; ++n) {
        Case c;
        if (!random_case(rng, c)) continue;
        Case moved = c;
        for (int i = 0; i < 3; ++i) {
            c.uv[i] = {sixty_fourths(rng) / 64.0, sixty_fourths(rng) / 64.0};
            moved.uv[i] = c.uv[i] + 65536.0;
        }
        const mr::TriangleUvs uvs = triangle_uvs(c), moved_uvs = triangle_uvs(moved);
        for (int py = c.setup.min_y; py <= c.setup.max_y; py += 3)
            for (int px = c.setup.min_x; px <= c.setup.max_x; px += 3) {
                const glm::dvec3 l = weights_at(c.setup, px * std::int64_t{256} + 128, py * std::int64_t{256} + 128);
                if (l.x < 0 || l.y < 0 || l.z < 0) continue;
                const mr::UvSample s = mr::interpolate_uv(c.setup, uvs, l, mr::Interpolation::perspective);
                const mr::UvSample m = mr::interpolate_uv(c.setup, moved_uvs, l, mr::Interpolation::perspective);
                const double scale = 1.0 + glm::length(s.dx) + glm::length(s.dy);
                for (int k = 0; k < 2; ++k)
                    worst = std::max({worst, std::abs(m.dx[k] - s.dx[k]) / scale, std::abs(m.dy[k] - s.dy[k]) / scale});
                ++checked;
            }
    }
    EXPECT_GT(checked, 1000);
    EXPECT_LT(worst, 1e-9) << "worst relative derivative change " << worst;
    RecordProperty("worst_relative_derivative_change", std::to_string(worst));
}

TEST(ShadeTexture, FlatInterpolationUsesTheProvokingVertexUvWithZeroDerivatives) {
    std::mt19937_64 rng(3);
    Case c;
    while (!random_case(rng, c)) {}
    const mr::TriangleUvs uvs = triangle_uvs(c);
    const mr::UvSample s = mr::interpolate_uv(c.setup, uvs, glm::dvec3(0.2, 0.3, 0.5), mr::Interpolation::flat);
    EXPECT_NEAR(s.uv.x, c.uv[0].x, 1e-6 * (1 + std::abs(c.uv[0].x)));  // the float-stored uv
    EXPECT_NEAR(s.uv.y, c.uv[0].y, 1e-6 * (1 + std::abs(c.uv[0].y)));
    EXPECT_EQ(s.dx, glm::dvec2(0.0));
    EXPECT_EQ(s.dy, glm::dvec2(0.0));
}

TEST(ShadeTexture, QuadDerivativesAreDifferencesBetweenTheQuadsPixelCentres) {
    std::mt19937_64 rng(11);
    int checked = 0;
    for (int n = 0; n < 200; ++n) {
        Case c;
        if (!random_case(rng, c)) continue;
        for (auto& uv : c.uv) uv = glm::dvec2(glm::vec2(uv));
        const mr::TriangleUvs uvs = triangle_uvs(c);
        const int px = (c.setup.min_x + c.setup.max_x) / 2, py = (c.setup.min_y + c.setup.max_y) / 2;
        mr::UvSample s;
        mr::quad_derivatives(c.setup, uvs, mr::Interpolation::perspective, px, py, s);
        // The quad's top-left pixel centre and its right and lower neighbours.
        const glm::dvec2 q((px & ~1) + 0.5, (py & ~1) + 0.5);
        const glm::dvec2 base = oracle_uv(c.clip, c.uv, q, true);
        const glm::dvec2 dx = oracle_uv(c.clip, c.uv, q + glm::dvec2(1, 0), true) - base;
        const glm::dvec2 dy = oracle_uv(c.clip, c.uv, q + glm::dvec2(0, 1), true) - base;
        // Differences of uvs that agree to float precision (1/w is stored as float).
        const double tolerance = 1e-6 * (1.0 + std::abs(base.x) + std::abs(base.y));
        for (int k = 0; k < 2; ++k) {
            EXPECT_NEAR(s.dx[k], dx[k], tolerance);
            EXPECT_NEAR(s.dy[k], dy[k], tolerance);
        }
        // Every pixel of the quad gets the same (coarse) derivatives.
        mr::UvSample other;
        mr::quad_derivatives(c.setup, uvs, mr::Interpolation::perspective, px | 1, py | 1, other);
        EXPECT_EQ(other.dx, s.dx);
        EXPECT_EQ(other.dy, s.dy);
        ++checked;
    }
    EXPECT_GT(checked, 50);
}

TEST(ShadeTexture, MipLevelColoursAreDistinctPerLevelAndBlendBetweenLevels) {
    for (int k = 0; k < 8; ++k) {
        const glm::vec4 a = mr::mip_level_colour(k), b = mr::mip_level_colour(k + 1);
        EXPECT_NE(a, b) << k;
        const glm::vec4 mid = mr::mip_level_colour(k + 0.5);
        for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(mid[c], 0.5f * (a[c] + b[c]));
    }
    EXPECT_EQ(mr::mip_level_colour(std::nan("")), mr::mip_level_colour(0.0));
    EXPECT_EQ(mr::mip_level_colour(1e30), mr::mip_level_colour(100.0));
}
