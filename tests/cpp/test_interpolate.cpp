// Interpolation (DESIGN.md §2.4): perspective-correct vertex colours match a double-precision ray
// cast and stay inside the vertex values' range; screen-space (affine) interpolation matches the
// formula on the exact edge values of the snapped triangle; flat shading takes the first vertex;
// blending of premultiplied colours follows its formula. u and v travel in the r and g channels,
// as a texture lookup would use them.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <glm/common.hpp>

#include "helpers.hpp"
#include "mipraster/pipeline/blend.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;
using oracle::Fixed2;

constexpr int W = 64, H = 64;

/// Screen barycentrics of the sample q in the snapped triangle v, from exact integer edge values.
glm::dvec3 exact_screen_weights(const std::array<Fixed2, 3>& v, const Fixed2& q) {
    const double area = static_cast<double>(oracle::cross(v[0], v[1], v[2].x, v[2].y));
    return {static_cast<double>(oracle::cross(v[1], v[2], q.x, q.y)) / area,
            static_cast<double>(oracle::cross(v[2], v[0], q.x, q.y)) / area,
            static_cast<double>(oracle::cross(v[0], v[1], q.x, q.y)) / area};
}

/// A world point on the ray through a screen point (pixels) at the given view distance.
glm::dvec3 point_at_distance(const oracle::RayCaster& rc, double sx, double sy, double distance) {
    const oracle::Ray r = rc.ray(sx, sy);
    const double d0 = rc.view_distance(r.origin), d1 = rc.view_distance(r.origin + r.direction);
    return r.origin + ((distance - d0) / (d1 - d0)) * r.direction;
}

/// A planar, strongly tilted quad whose corners project exactly onto the 1/256 grid (so the
/// snapped triangles are the exact ones): three corners chosen on screen with their view
/// distances, the fourth where its screen point's ray meets their plane. Colours (u, v, b, 1).
struct GridQuad {
    mr::Mesh mesh;
    std::array<glm::dvec2, 4> screen;  ///< pixels
    std::array<Fixed2, 4> fixed;
};

const std::array<glm::dvec2, 4> kCorners = {glm::dvec2(6.25, 9.5), glm::dvec2(58.75, 4.0), glm::dvec2(55.5, 60.25),
                                            glm::dvec2(3.0, 52.75)};
const std::array<glm::vec4, 4> kColors = {glm::vec4(0, 0, 0.9f, 1), glm::vec4(1, 0, 0.1f, 1), glm::vec4(1, 1, 0.5f, 1),
                                          glm::vec4(0, 1, 0.3f, 1)};

mr::Camera test_camera() {
    return mr::Camera::look_at_perspective({0.2, 0.1, 0.5}, {0.3, 0.0, -3.0}, {0.0, 1.0, 0.0}, 0.9, double(W) / H, 0.1);
}

GridQuad grid_quad(const oracle::RayCaster& rc, const std::array<double, 3>& distances) {
    GridQuad q;
    q.screen = kCorners;
    std::array<glm::dvec3, 4> p;
    for (int i = 0; i < 3; ++i) p[i] = point_at_distance(rc, q.screen[i].x, q.screen[i].y, distances[i]);
    const glm::dvec3 n = oracle::RayCaster::cross3(p[1] - p[0], p[2] - p[0]);
    const oracle::Ray r = rc.ray(q.screen[3].x, q.screen[3].y);
    p[3] = r.origin + (oracle::RayCaster::dot3(n, p[0] - r.origin) / oracle::RayCaster::dot3(n, r.direction)) * r.direction;
    for (int i = 0; i < 4; ++i) {
        q.mesh.positions.push_back(glm::vec3(p[i]));
        q.fixed[i] = {static_cast<std::int64_t>(q.screen[i].x * 256), static_cast<std::int64_t>(q.screen[i].y * 256)};
    }
    q.mesh.colors.assign(kColors.begin(), kColors.end());
    add_triangle(q.mesh, 0, 1, 2);
    add_triangle(q.mesh, 0, 2, 3);
    return q;
}

mr::DrawState shading(mr::Interpolation mode) {
    mr::DrawState st = no_depth();
    st.interpolation = mode;
    return st;
}

/// Everything the oracles know about one covered sample of the quad.
struct QuadSample {
    int x, y, s, triangle;
    Fixed2 q;
    double edge_distance;  ///< to the nearest projected edge (pixels), diagonal included
};

std::vector<QuadSample> covered_samples(const GridQuad& quad, const oracle::Pattern& p) {
    std::vector<QuadSample> out;
    const std::array<Fixed2, 3> t[2] = {{quad.fixed[0], quad.fixed[1], quad.fixed[2]},
                                        {quad.fixed[0], quad.fixed[2], quad.fixed[3]}};
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int s = 0; s < p.count(); ++s) {
                const Fixed2 q = oracle::sample_position(x, y, p, s);
                for (int k = 0; k < 2; ++k) {
                    if (!oracle::covers(t[k], q.x, q.y)) continue;
                    const glm::dvec2 sp(q.x / 256.0, q.y / 256.0);
                    double d = oracle::distance_to_segment(sp, quad.screen[0], quad.screen[2]);
                    for (int i = 0; i < 4; ++i)
                        d = std::min(d, oracle::distance_to_segment(sp, quad.screen[i], quad.screen[(i + 1) % 4]));
                    out.push_back({x, y, s, k, q, d});
                }
            }
    return out;
}

TEST(Interpolate, TestQuadCornersSnapExactlyToTheirGridPoints) {
    const mr::Camera cam = test_camera();
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    const GridQuad quad = grid_quad(rc, {1.2, 6.0, 9.0});
    const oracle::Mat4 mvp = oracle::model_view_projection(cam.projection, cam.view, glm::dmat4(1.0));
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(oracle::project_and_snap(mvp, glm::dvec3(quad.mesh.positions[i]), W, H), quad.fixed[i]) << "corner " << i;
        const glm::dvec3 s = rc.project(glm::dvec3(quad.mesh.positions[i]));
        EXPECT_NEAR(s.x, quad.screen[i].x, 1e-4);
        EXPECT_NEAR(s.y, quad.screen[i].y, 1e-4);
        EXPECT_GT(s.z, 1.0);  // w: in front of the near plane
    }
    // Strongly tilted: the corners' depths differ by up to 7.5×.
    const double d0 = rc.view_distance(glm::dvec3(quad.mesh.positions[0]));
    const double d2 = rc.view_distance(glm::dvec3(quad.mesh.positions[2]));
    EXPECT_GT(d2 / d0, 7.0);
}

/// Renders the quad (perspective-correct colours) through `cam` and compares every covered
/// sample away from the edges with the ray cast; returns the samples checked.
std::size_t check_quad_against_ray_cast(const mr::Camera& cam, int spp) {
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    const GridQuad quad = grid_quad(rc, {1.2, 6.0, 9.0});
    const mr::RenderResult r = mr::render({make_draw(quad.mesh, glm::dmat4(1.0), shading(mr::Interpolation::perspective))},
                                          cam, settings(W, H, spp, mr::PatternKind::grid));
    const oracle::Pattern p = to_oracle(r.pattern);
    std::array<glm::dvec3, 4> world;
    for (int i = 0; i < 4; ++i) world[i] = glm::dvec3(quad.mesh.positions[i]);
    std::size_t checked = 0, bad = 0;
    double worst = 0;
    for (const QuadSample& qs : covered_samples(quad, p)) {
        if (qs.edge_distance < 1e-3) continue;
        const glm::uvec3 t = quad.mesh.triangles[qs.triangle];
        const oracle::Hit h = rc.intersect(rc.ray(qs.q.x / 256.0, qs.q.y / 256.0), world[t[0]], world[t[1]], world[t[2]]);
        EXPECT_TRUE(h.hit) << "ray caster misses a sample " << qs.edge_distance << " px inside the triangle";
        if (!h.hit) return checked;
        const glm::vec4 got = sample_color(r.framebuffer, qs.x, qs.y, qs.s);
        for (int c = 0; c < 3; ++c) {
            const double exact = h.bary.x * kColors[t[0]][c] + h.bary.y * kColors[t[1]][c] + h.bary.z * kColors[t[2]][c];
            const double err = std::fabs(got[c] - exact);
            worst = std::max(worst, err / std::max(std::fabs(exact), 0.1));
            if (err > std::max(1e-5 * std::fabs(exact), 1e-6) && ++bad < 8)
                ADD_FAILURE() << "pixel (" << qs.x << ", " << qs.y << ") sample " << qs.s << " channel " << c << ": got "
                              << got[c] << ", ray cast " << exact;
        }
        EXPECT_EQ(got.a, 1.0f);
        ++checked;
    }
    EXPECT_EQ(bad, 0u) << "worst relative error " << worst;
    return checked;
}

TEST(Interpolate, PerspectiveCorrectColoursMatchTheDoublePrecisionRayCast) {
    EXPECT_GT(check_quad_against_ray_cast(test_camera(), 16), 20000u);
}

// Under an orthographic camera every vertex has clip w = 1, so the pipeline interpolates a
// perspective-correct draw affinely (no division per sample): the colours of a strongly tilted
// quad still match the ray cast.
TEST(Interpolate, OrthographicPerspectiveDrawsMatchTheRayCastWithoutTheDivision) {
    mr::Camera cam;
    cam.view = mr::look_at({0.2, 0.1, 0.5}, {0.3, 0.0, -3.0}, {0.0, 1.0, 0.0});
    cam.projection = mr::orthographic(-1.5, 1.5, -1.5, 1.5, 0.1, 20.0);
    EXPECT_GT(check_quad_against_ray_cast(cam, 4), 5000u);
}

// The choice itself: affine exactly when every clip w is the same number.
TEST(Interpolate, PerspectiveBecomesAffineExactlyWhenEveryClipWIsEqual) {
    using I = mr::Interpolation;
    const std::vector<glm::dvec4> ortho = {{0, 0, 0, 1}, {1, 2, 3, 1}, {-4, 5, 0.5, 1}};
    const std::vector<glm::dvec4> scaled = {{0, 0, 0, 2.5}, {1, 2, 3, 2.5}};
    const std::vector<glm::dvec4> tilted = {{0, 0, 0, 1}, {1, 2, 3, 1}, {-4, 5, 0.5, 1.0000000000000002}};
    const std::vector<glm::dvec4> nan_w = {{0, 0, 0, std::nan("")}, {1, 2, 3, std::nan("")}};
    EXPECT_EQ(mr::effective_interpolation(I::perspective, ortho.data(), ortho.size()), I::screen);
    EXPECT_EQ(mr::effective_interpolation(I::perspective, scaled.data(), scaled.size()), I::screen);
    EXPECT_EQ(mr::effective_interpolation(I::perspective, tilted.data(), tilted.size()), I::perspective);
    EXPECT_EQ(mr::effective_interpolation(I::perspective, nan_w.data(), nan_w.size()), I::perspective);
    EXPECT_EQ(mr::effective_interpolation(I::perspective, ortho.data(), 0), I::perspective);
    EXPECT_EQ(mr::effective_interpolation(I::flat, ortho.data(), ortho.size()), I::flat);
    EXPECT_EQ(mr::effective_interpolation(I::screen, tilted.data(), tilted.size()), I::screen);
}

TEST(Interpolate, PerspectiveCorrectColoursMatchTheExactEdgeValueFormula) {
    // λ_i from exact integer edge values of the snapped triangle, then λ_i/w_i normalized.
    const mr::Camera cam = test_camera();
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    const GridQuad quad = grid_quad(rc, {1.2, 6.0, 9.0});
    const mr::RenderResult r = mr::render({make_draw(quad.mesh, glm::dmat4(1.0), shading(mr::Interpolation::perspective))},
                                          cam, settings(W, H, 4, mr::PatternKind::rotated));
    const oracle::Pattern p = to_oracle(r.pattern);
    std::size_t bad = 0, checked = 0;
    for (const QuadSample& qs : covered_samples(quad, p)) {
        const glm::uvec3 t = quad.mesh.triangles[qs.triangle];
        const glm::dvec3 l = exact_screen_weights({quad.fixed[t[0]], quad.fixed[t[1]], quad.fixed[t[2]]}, qs.q);
        glm::dvec3 m;
        for (int i = 0; i < 3; ++i) m[i] = l[i] / rc.project(glm::dvec3(quad.mesh.positions[t[i]])).z;
        m /= (m.x + m.y + m.z);
        const glm::vec4 got = sample_color(r.framebuffer, qs.x, qs.y, qs.s);
        for (int c = 0; c < 4; ++c) {
            const double exact = m.x * kColors[t[0]][c] + m.y * kColors[t[1]][c] + m.z * kColors[t[2]][c];
            if (std::fabs(got[c] - exact) > 1e-6 && ++bad < 8)
                ADD_FAILURE() << "pixel (" << qs.x << ", " << qs.y << ") sample " << qs.s << " channel " << c << ": got "
                              << got[c] << ", expected " << exact;
        }
        ++checked;
    }
    EXPECT_EQ(bad, 0u);
    EXPECT_GT(checked, 5000u);
}

TEST(Interpolate, ScreenSpaceInterpolationIsAffineInTheExactEdgeValues) {
    const mr::Camera cam = test_camera();
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    const GridQuad quad = grid_quad(rc, {1.2, 6.0, 9.0});
    const mr::RenderResult r = mr::render({make_draw(quad.mesh, glm::dmat4(1.0), shading(mr::Interpolation::screen))},
                                          cam, settings(W, H, 16, mr::PatternKind::grid));
    std::size_t bad = 0, checked = 0;
    for (const QuadSample& qs : covered_samples(quad, to_oracle(r.pattern))) {
        const glm::uvec3 t = quad.mesh.triangles[qs.triangle];
        const glm::dvec3 l = exact_screen_weights({quad.fixed[t[0]], quad.fixed[t[1]], quad.fixed[t[2]]}, qs.q);
        const glm::vec4 got = sample_color(r.framebuffer, qs.x, qs.y, qs.s);
        for (int c = 0; c < 4; ++c) {
            const double exact = l.x * kColors[t[0]][c] + l.y * kColors[t[1]][c] + l.z * kColors[t[2]][c];
            if (std::fabs(got[c] - exact) > 1e-6 && ++bad < 8)
                ADD_FAILURE() << "pixel (" << qs.x << ", " << qs.y << ") sample " << qs.s << " channel " << c
                              << ": got " << got[c] << ", expected " << exact;
        }
        ++checked;
    }
    EXPECT_EQ(bad, 0u);
    EXPECT_GT(checked, 20000u);
}

TEST(Interpolate, ScreenAndPerspectiveInterpolationDifferOnTheTiltedQuad) {
    // The quad is tilted enough that affine interpolation is visibly wrong: the two modes must
    // differ by more than 0.05 in u somewhere (otherwise the comparisons above prove little).
    const mr::Camera cam = test_camera();
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    const GridQuad quad = grid_quad(rc, {1.2, 6.0, 9.0});
    const auto s = settings(W, H, 1);
    const mr::RenderResult a = mr::render({make_draw(quad.mesh, glm::dmat4(1.0), shading(mr::Interpolation::screen))}, cam, s);
    const mr::RenderResult b =
        mr::render({make_draw(quad.mesh, glm::dmat4(1.0), shading(mr::Interpolation::perspective))}, cam, s);
    float most = 0.0f;
    for (std::size_t i = 0; i < a.color.pixels.size(); i += 4) most = std::max(most, std::fabs(a.color.pixels[i] - b.color.pixels[i]));
    EXPECT_GT(most, 0.05f);
}

// VertexValues' range is glm's component-wise min and max, bit for bit: random values with ties,
// signed zeros, infinities and NaNs in every position (the selections must match glm's, which
// keep the first argument unless the second compares less or greater).
TEST(Interpolate, VertexValuesRangeIsGlmsMinAndMax) {
    const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, std::numeric_limits<float>::infinity(),
                             -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), 1e-40f};
    std::mt19937 rng(15);
    std::uniform_int_distribution<int> pick(0, 8);
    const auto bits = [](float x) {
        std::uint32_t b;
        std::memcpy(&b, &x, 4);
        return b;
    };
    for (int trial = 0; trial < 20000; ++trial) {
        glm::vec4 a, b, c;
        for (int k = 0; k < 4; ++k) a[k] = special[pick(rng)], b[k] = special[pick(rng)], c[k] = special[pick(rng)];
        const mr::VertexValues values(a, b, c);
        const glm::vec4 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
        for (int k = 0; k < 4; ++k) {
            ASSERT_EQ(bits(values.lo[k]), bits(lo[k])) << "trial " << trial << " component " << k;
            ASSERT_EQ(bits(values.hi[k]), bits(hi[k])) << "trial " << trial << " component " << k;
        }
    }
}

// VertexValues::one against its definition per component (a == b == c, finite, nonzero): colours
// that are one colour, and one colour with one component of one vertex changed to a special value
// (signed zeros, infinities, a NaN) or to the next float; where it holds, the clamped weighted sum
// at random finite weights is that colour, bit for bit.
TEST(Interpolate, VertexValuesOneIsOneFiniteNonzeroColour) {
    const float special[] = {0.0f, -0.0f, std::numeric_limits<float>::infinity(),
                             -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), 1e-40f};
    std::mt19937 rng(16);
    std::uniform_real_distribution<float> value(-2.0f, 2.0f);
    std::uniform_real_distribution<double> weight(-3.0, 3.0);
    int ones = 0, others = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        glm::vec4 a;
        for (int k = 0; k < 4; ++k) a[k] = trial % 7 == 0 ? special[rng() % 6] : value(rng);
        glm::vec4 v[3] = {a, a, a};
        if (trial % 2) {  // one component of one vertex changed
            float& x = v[rng() % 3][static_cast<int>(rng() % 4)];
            x = rng() % 2 ? special[rng() % 6] : std::nextafter(x, 3.0f);
        }
        bool want = true;
        for (int k = 0; k < 4; ++k)
            want = want && v[0][k] == v[1][k] && v[1][k] == v[2][k] && v[0][k] != 0.0f && std::isfinite(v[0][k]);
        const mr::VertexValues values(v[0], v[1], v[2]);
        ASSERT_EQ(values.one, want) << "trial " << trial;
        (want ? ones : others) += 1;
        if (!want) continue;
        const glm::vec4 sum = values.interpolate(glm::dvec3(weight(rng), weight(rng), weight(rng)));
        for (int k = 0; k < 4; ++k) {
            std::uint32_t got_bits, want_bits;
            std::memcpy(&got_bits, &sum[k], 4);
            std::memcpy(&want_bits, &v[0][k], 4);
            ASSERT_EQ(got_bits, want_bits) << "trial " << trial << " component " << k;
        }
    }
    EXPECT_GT(ones, 8000);
    EXPECT_GT(others, 8000);
}

// VertexValues::interpolate (four components at once) against its definition per component,
// std::clamp(float(w.x·v0 + w.y·v1 + w.z·v2), lo, hi), bit for bit: weights inside and outside
// [0, 1] (so that the clamp acts at both ends), values of large and mixed magnitudes (so that the
// order of the sum shows), ±0, ±∞ and NaN.
TEST(Interpolate, VertexValuesInterpolateIsTheClampedWeightedSum) {
    const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 3e15f, -3e15f, 1e-40f,
                             std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()};
    std::mt19937 rng(16);
    std::uniform_int_distribution<int> pick(0, 9);
    std::uniform_real_distribution<double> weight(-0.5, 1.5), value(-2.0, 2.0);
    const auto bits = [](float x) {
        std::uint32_t b;
        std::memcpy(&b, &x, 4);
        return b;
    };
    int clamped_low = 0, clamped_high = 0;
    for (int trial = 0; trial < 100000; ++trial) {
        glm::vec4 v[3];
        for (auto& x : v)
            for (int k = 0; k < 4; ++k)
                x[k] = trial % 4 ? float(value(rng)) * (trial % 3 ? 1.0f : 1e15f) : special[pick(rng)];
        const mr::VertexValues values(v[0], v[1], v[2]);
        const double w0 = weight(rng), w1 = weight(rng);
        const glm::dvec3 w(w0, w1, trial % 2 ? 1.0 - w0 - w1 : weight(rng));
        const glm::vec4 got = values.interpolate(w);
        for (int k = 0; k < 4; ++k) {
            const float sum = static_cast<float>(w.x * v[0][k] + w.y * v[1][k] + w.z * v[2][k]);
            const float want = std::clamp(sum, values.lo[k], values.hi[k]);
            clamped_low += sum < values.lo[k];
            clamped_high += values.hi[k] < sum;
            // A NaN's sign and payload depend on which operand of a sum the compiler puts first
            // (IEEE leaves them open; the sanitizer build ordered this sum differently): a NaN only
            // has to stay a NaN.
            if (std::isnan(want)) {
                ASSERT_TRUE(std::isnan(got[k])) << "trial " << trial << " component " << k;
                continue;
            }
            ASSERT_EQ(bits(got[k]), bits(want)) << "trial " << trial << " component " << k;
        }
    }
    EXPECT_GE(clamped_low, 10000);
    EXPECT_GE(clamped_high, 10000);
}

TEST(Interpolate, InterpolatedValuesStayWithinTheVertexValuesRange) {
    // Extreme depth ratio (1e-1 … 1e4) and colours spanning a tiny range near 1 and a range
    // crossing zero: every interpolated value stays within [min, max] of its vertices.
    const mr::Camera cam = test_camera();
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    GridQuad quad = grid_quad(rc, {0.15, 900.0, 3000.0});
    quad.mesh.colors = {glm::vec4(0.9999999f, -0.5f, 3.0f, 0.25f), glm::vec4(1.0f, 0.5f, 1e-7f, 0.5f),
                        glm::vec4(0.99999994f, -1e-3f, 7.0f, 1.0f), glm::vec4(1.0f, 2.0f, 0.0f, 0.75f)};
    for (mr::Interpolation mode : {mr::Interpolation::perspective, mr::Interpolation::screen}) {
        for (mr::AntiAliasing aa : {mr::AntiAliasing::ssaa, mr::AntiAliasing::msaa}) {
            auto s = settings(W, H, 16, mr::PatternKind::grid);
            s.anti_aliasing = aa;
            const mr::RenderResult r = mr::render({make_draw(quad.mesh, glm::dmat4(1.0), shading(mode))}, cam, s);
            std::size_t checked = 0;
            for (const QuadSample& qs : covered_samples(quad, to_oracle(r.pattern))) {
                const glm::uvec3 t = quad.mesh.triangles[qs.triangle];
                const glm::vec4 got = sample_color(r.framebuffer, qs.x, qs.y, qs.s);
                for (int c = 0; c < 4; ++c) {
                    const float lo = std::min({quad.mesh.colors[t[0]][c], quad.mesh.colors[t[1]][c], quad.mesh.colors[t[2]][c]});
                    const float hi = std::max({quad.mesh.colors[t[0]][c], quad.mesh.colors[t[1]][c], quad.mesh.colors[t[2]][c]});
                    EXPECT_TRUE(got[c] >= lo && got[c] <= hi)
                        << mr::to_string(mode) << " " << mr::to_string(aa) << " pixel (" << qs.x << ", " << qs.y
                        << ") channel " << c << ": " << got[c] << " outside [" << lo << ", " << hi << "]";
                }
                ++checked;
            }
            EXPECT_GT(checked, 10000u);
        }
    }
}

TEST(Interpolate, PerspectiveCorrectColoursOfAQuadClippedByTheNearPlaneMatchTheRayCast) {
    // The quad runs from in front of the camera to behind it; the clipped sub-triangles carry the
    // original vertices' weights. Their clipped vertices are snapped, which evaluates the exact
    // attribute at a point moved by ≤ √2/512 px: tolerance |∇value|·√2/512 + 1e-5 relative.
    const double near = 0.1;
    const mr::Camera cam = mr::Camera::look_at_perspective({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.0, 1.0, near);
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    mr::Mesh m;
    m.positions = {{-2.0f, -0.6f, 0.8f}, {2.0f, -0.6f, 0.8f}, {1.5f, 0.2f, -6.0f}, {-1.5f, 0.4f, -6.0f}};
    m.colors.assign(kColors.begin(), kColors.end());
    add_triangle(m, 0, 1, 2);
    add_triangle(m, 0, 2, 3);
    const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), shading(mr::Interpolation::perspective))}, cam,
                                          settings(W, H, 4, mr::PatternKind::rotated));
    EXPECT_EQ(r.stats.triangles_clipped, 2u);
    const oracle::Pattern p = to_oracle(r.pattern);
    std::array<glm::dvec3, 4> world;
    for (int i = 0; i < 4; ++i) world[i] = glm::dvec3(m.positions[i]);
    auto value = [&](double sx, double sy, int c, bool& hit) {
        const oracle::Ray ray = rc.ray(sx, sy);
        for (const auto& t : m.triangles) {
            const oracle::Hit h = rc.intersect(ray, world[t[0]], world[t[1]], world[t[2]]);
            if (h.hit && h.view_distance >= near) {
                hit = true;
                return h.bary.x * kColors[t[0]][c] + h.bary.y * kColors[t[1]][c] + h.bary.z * kColors[t[2]][c];
            }
        }
        hit = false;
        return 0.0;
    };
    const std::vector<glm::dvec2> visible =
        oracle::visible_polygon(rc, std::vector<glm::dvec3>(world.begin(), world.end()), near);
    std::size_t checked = 0, bad = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int s = 0; s < p.count(); ++s) {
                const Fixed2 q = oracle::sample_position(x, y, p, s);
                const double sx = q.x / 256.0, sy = q.y / 256.0;
                if (oracle::distance_to_boundary({sx, sy}, visible) < 0.05) continue;
                const glm::vec4 got = sample_color(r.framebuffer, x, y, s);
                for (int c = 0; c < 2; ++c) {
                    bool hit = false, h1, h2, h3, h4;
                    const double exact = value(sx, sy, c, hit);
                    if (!hit) continue;
                    const double e = 1.0 / 64;
                    const double gx = (value(sx + e, sy, c, h1) - value(sx - e, sy, c, h2)) / (2 * e);
                    const double gy = (value(sx, sy + e, c, h3) - value(sx, sy - e, c, h4)) / (2 * e);
                    const double tol = std::hypot(gx, gy) * oracle::kSnapBandPx * 1.01 + 1e-5 * std::fabs(exact) + 1e-6;
                    ++checked;
                    if (std::fabs(got[c] - exact) > tol && ++bad < 8)
                        ADD_FAILURE() << "pixel (" << x << ", " << y << ") sample " << s << " channel " << c << ": got "
                                      << got[c] << ", ray cast " << exact << " (tolerance " << tol << ")";
                }
            }
    EXPECT_EQ(bad, 0u);
    EXPECT_GT(checked, 5000u);
}

TEST(Interpolate, FlatShadingUsesTheFirstVertexColourTimesTheDrawColour) {
    const mr::Camera cam = test_camera();
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    GridQuad quad = grid_quad(rc, {1.2, 6.0, 9.0});
    // Provoking vertices 2 and 3: rotate the index order so it is not vertex 0 for both.
    quad.mesh.triangles = {glm::uvec3(2, 0, 1), glm::uvec3(3, 0, 2)};
    const glm::vec4 draw_color(0.5f, 0.75f, 0.25f, 1.0f);
    for (mr::AntiAliasing aa : {mr::AntiAliasing::ssaa, mr::AntiAliasing::msaa}) {
        auto s = settings(W, H, 4, mr::PatternKind::rotated);
        s.anti_aliasing = aa;
        const mr::RenderResult r =
            mr::render({make_draw(quad.mesh, glm::dmat4(1.0), shading(mr::Interpolation::flat), draw_color)}, cam, s);
        std::size_t checked = 0;
        for (const QuadSample& qs : covered_samples(quad, to_oracle(r.pattern))) {
            // covered_samples numbers triangles (0,1,2) and (0,2,3): the same regions as the mesh's.
            const glm::vec4 want = draw_color * kColors[qs.triangle == 0 ? 2 : 3];
            EXPECT_EQ(sample_color(r.framebuffer, qs.x, qs.y, qs.s), want)
                << mr::to_string(aa) << " pixel (" << qs.x << ", " << qs.y << ") sample " << qs.s;
            ++checked;
        }
        EXPECT_GT(checked, 5000u);
    }
}

// ---------------------------------------------------------------------------------------------
// Blending premultiplied colours
// ---------------------------------------------------------------------------------------------

// blend_into_samples against blend_into slot by slot: every mask of 16 slots (and the whole 64,
// and random ones), each blend mode, slots outside the mask untouched, bit for bit.
TEST(Interpolate, BlendingASamplesMaskIsBlendingEachOfItsSlots) {
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<std::uint64_t> masks;
    for (std::uint64_t m = 0; m < (1u << 16); ++m) masks.push_back(m);
    masks.push_back(~std::uint64_t{0});
    for (int k = 0; k < 2000; ++k) masks.push_back(rng() >> (rng() % 64));
    std::vector<float> start(4 * 64), got, expected;
    for (float& f : start) f = unit(rng);
    const auto check = [&](auto mode) {
        constexpr mr::BlendMode kMode = decltype(mode)::value;
        for (const std::uint64_t m : masks) {
            const glm::vec4 src(unit(rng), unit(rng), unit(rng), unit(rng));
            got = expected = start;
            mr::blend_into_samples<kMode>(got.data(), m, src);
            for (int s = 0; s < 64; ++s)
                if (m >> s & 1) mr::blend_into<kMode>(expected.data() + 4 * s, src);
            ASSERT_EQ(std::memcmp(got.data(), expected.data(), 4 * 64 * sizeof(float)), 0)
                << "mode " << static_cast<int>(kMode) << ", mask " << std::hex << m;
        }
    };
    check(std::integral_constant<mr::BlendMode, mr::BlendMode::replace>{});
    check(std::integral_constant<mr::BlendMode, mr::BlendMode::add>{});
    check(std::integral_constant<mr::BlendMode, mr::BlendMode::over>{});
}

TEST(Interpolate, OverAndAddBlendingOfPremultipliedColoursFollowTheirFormulas) {
    // Identity camera; three overlapping triangles in 1/256 px units: a background drawn with
    // replace, a vertex-coloured premultiplied triangle drawn `over` it (screen interpolation), and
    // a constant colour added on top.
    const int w = 32, h = 32, S = 4;
    mr::Mesh back, over_tri, add_tri;
    back.positions = {{-512, -512, 0}, {40 * 256, -512, 0}, {-512, 40 * 256, 0}};
    add_triangle(back, 0, 1, 2);
    over_tri.positions = {{300, 500, 0}, {30 * 256 + 17, 2 * 256, 0}, {5 * 256, 31 * 256 + 100, 0}};
    over_tri.colors = {glm::vec4(0.4f, 0.1f, 0.05f, 0.5f), glm::vec4(0.0f, 0.3f, 0.2f, 0.3f),
                       glm::vec4(0.6f, 0.6f, 0.6f, 0.9f)};
    add_triangle(over_tri, 0, 1, 2);
    add_tri.positions = {{10 * 256, 0, 0}, {32 * 256, 0, 0}, {32 * 256, 32 * 256, 0}};
    add_triangle(add_tri, 0, 1, 2);
    const glm::vec4 clear(0.05f, 0.1f, 0.15f, 0.25f), back_color(0.2f, 0.3f, 0.1f, 0.5f), add_color(0.01f, 0.02f, 0.03f, 0.04f);
    mr::DrawState over_state = no_depth(mr::BlendMode::over);
    over_state.interpolation = mr::Interpolation::screen;
    auto s = settings(w, h, S, mr::PatternKind::rotated);
    s.clear_color = clear;
    const glm::dmat4 model = fixed_to_ndc(w, h);
    const mr::RenderResult r = mr::render({make_draw(back, model, no_depth(mr::BlendMode::replace), back_color),
                                           make_draw(over_tri, model, over_state),
                                           make_draw(add_tri, model, no_depth(mr::BlendMode::add), add_color)},
                                          identity_camera(), s);
    const oracle::Pattern p = to_oracle(r.pattern);
    const std::array<Fixed2, 3> tb = snapped_triangle(back, 0), to = snapped_triangle(over_tri, 0), ta = snapped_triangle(add_tri, 0);
    std::size_t bad = 0, all_three = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < S; ++k) {
                const Fixed2 q = oracle::sample_position(x, y, p, k);
                glm::dvec4 dst(clear);
                if (oracle::covers(tb, q.x, q.y)) dst = glm::dvec4(back_color);
                const bool in_over = oracle::covers(to, q.x, q.y), in_add = oracle::covers(ta, q.x, q.y);
                if (in_over) {
                    const glm::dvec3 l = exact_screen_weights(to, q);
                    const glm::dvec4 src = l.x * glm::dvec4(over_tri.colors[0]) + l.y * glm::dvec4(over_tri.colors[1]) +
                                           l.z * glm::dvec4(over_tri.colors[2]);
                    dst = src + (1.0 - src.a) * dst;  // premultiplied over
                }
                if (in_add) dst += glm::dvec4(add_color);
                all_three += in_over && in_add;
                const glm::vec4 got = sample_color(r.framebuffer, x, y, k);
                for (int c = 0; c < 4; ++c)
                    if (std::fabs(got[c] - dst[c]) > 1e-6 && ++bad < 8)
                        ADD_FAILURE() << "pixel (" << x << ", " << y << ") sample " << k << " channel " << c << ": got "
                                      << got[c] << ", expected " << dst[c];
            }
    EXPECT_EQ(bad, 0u);
    EXPECT_GT(all_three, 200u);
}

}  // namespace
