// Depth (DESIGN.md §2.3): reverse-Z float32 depth keeps surfaces 1e-6 apart (relative) in order
// from 1e-2 to 1e5 with near = 1e-3; the OpenGL convention (LESS, clear 1) works over a normal
// range; stored depth matches the ray-cast window depth; no depth buffer exists when nothing
// tests depth. Expected colours come from oracle coverage and the ray caster.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "helpers.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

const glm::vec4 kRed(1, 0, 0, 1), kGreen(0, 1, 0, 1), kClear(0, 0, 0, 0);

/// A quad of half-size 0.3 around (0, 0, −1), optionally tilted, two triangles.
mr::Mesh unit_quad() {
    mr::Mesh m;
    m.positions = {{-0.3f, -0.3f, 0.0f}, {0.3f, -0.3f, 0.0f}, {0.3f, 0.3f, 0.0f}, {-0.3f, 0.3f, 0.0f}};
    add_triangle(m, 0, 1, 2);
    add_triangle(m, 0, 2, 3);
    return m;
}

/// Model matrix: the quad rotated (about y by `yaw`, then x by `pitch`), moved to z = −1, then
/// everything scaled by `s` about the eye (the origin): scaling keeps every vertex on its ray.
glm::dmat4 quad_model(double s, double yaw, double pitch) {
    glm::dmat4 m = glm::scale(glm::dmat4(1.0), glm::dvec3(s));
    m = glm::translate(m, glm::dvec3(0.0, 0.0, -1.0));
    m = glm::rotate(m, pitch, glm::dvec3(1.0, 0.0, 0.0));
    m = glm::rotate(m, yaw, glm::dvec3(0.0, 1.0, 0.0));
    return m;
}

/// Oracle coverage counts of a mesh drawn with `model` through `cam` (vertices in front of it).
std::vector<int> coverage(const mr::Mesh& mesh, const glm::dmat4& model, const mr::Camera& cam, int W, int H,
                          const oracle::Pattern& p) {
    const oracle::Mat4 mvp = oracle::model_view_projection(cam.projection, cam.view, model);
    std::vector<int> counts(static_cast<std::size_t>(W) * H * p.count(), 0);
    for (const auto& t : mesh.triangles) {
        std::array<oracle::Fixed2, 3> v;
        for (int i = 0; i < 3; ++i) v[i] = oracle::project_and_snap(mvp, glm::dvec3(mesh.positions[t[i]]), W, H);
        oracle::accumulate_coverage(v, W, H, p, counts);
    }
    return counts;
}

/// Draws `near_model` in red and `far_model` in green, in both orders, with the depth test, and
/// checks that every sample shows red where the near surface covers it, else green where the far
/// one does, else the clear colour.
void expect_nearer_wins(const mr::Camera& cam, const mr::Mesh& quad, const glm::dmat4& near_model,
                        const glm::dmat4& far_model, mr::AntiAliasing aa, const std::string& what) {
    const int W = 64, H = 64, S = 4;
    auto s = settings(W, H, S, mr::PatternKind::rotated);
    s.anti_aliasing = aa;
    mr::DrawState st;  // depth test and write on, replace
    const mr::Draw near_draw = make_draw(quad, near_model, st, kRed), far_draw = make_draw(quad, far_model, st, kGreen);
    const oracle::Pattern p = oracle::rotated_pattern();
    const std::vector<int> cn = coverage(quad, near_model, cam, W, H, p), cf = coverage(quad, far_model, cam, W, H, p);
    std::size_t red = 0;
    for (int order = 0; order < 2; ++order) {
        const mr::RenderResult r = mr::render(order == 0 ? std::vector<mr::Draw>{near_draw, far_draw}
                                                         : std::vector<mr::Draw>{far_draw, near_draw},
                                              cam, s);
        ASSERT_TRUE(same_offsets(to_oracle(r.pattern), p));
        ASSERT_TRUE(r.framebuffer.has_depth());
        std::vector<float> expect_r(cn.size()), expect_g(cn.size());
        for (std::size_t i = 0; i < cn.size(); ++i) {
            const glm::vec4 c = cn[i] ? kRed : cf[i] ? kGreen : kClear;
            expect_r[i] = c.r;
            expect_g[i] = c.g;
            red += order == 0 && cn[i];
        }
        EXPECT_TRUE(samples_equal(r.framebuffer, expect_r, 0, what + (order ? ", far first: red" : ", near first: red")));
        EXPECT_TRUE(samples_equal(r.framebuffer, expect_g, 1, what + (order ? ", far first: green" : ", near first: green")));
    }
    EXPECT_GT(red, 1000u) << what << ": the quads cover too little to test";
}

constexpr double kNear = 1e-3, kFovy = 1.0;

mr::Camera reverse_z_camera(int W, int H) {
    return mr::Camera::look_at_perspective({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, kFovy, double(W) / H, kNear);
}

TEST(Depth, FacingQuadsOneMillionthApartStayOrderedFrom1eMinus2To1e5WithNearOneThousandth) {
    const mr::Camera cam = reverse_z_camera(64, 64);
    const mr::Mesh quad = unit_quad();
    for (int e = -2; e <= 5; ++e) {
        const double d = std::pow(10.0, e);
        expect_nearer_wins(cam, quad, quad_model(d, 0, 0), quad_model(d * (1.0 + 1e-6), 0, 0), mr::AntiAliasing::ssaa,
                           "distance 1e" + std::to_string(e));
    }
}

TEST(Depth, TiltedQuadsOneMillionthApartStayOrderedFrom1eMinus2To1e5) {
    const mr::Camera cam = reverse_z_camera(64, 64);
    const mr::Mesh quad = unit_quad();
    for (int e = -2; e <= 5; ++e) {
        const double d = std::pow(10.0, e);
        expect_nearer_wins(cam, quad, quad_model(d, 1.05, 0.35), quad_model(d * (1.0 + 1e-6), 1.05, 0.35),
                           mr::AntiAliasing::ssaa, "tilted, distance 1e" + std::to_string(e));
    }
}

TEST(Depth, TiltedQuadsStayOrderedWithMsaaDepthPerSample) {
    const mr::Camera cam = reverse_z_camera(64, 64);
    const mr::Mesh quad = unit_quad();
    for (int e : {-2, 1, 5}) {
        const double d = std::pow(10.0, e);
        expect_nearer_wins(cam, quad, quad_model(d, -0.9, 0.5), quad_model(d * (1.0 + 1e-6), -0.9, 0.5),
                           mr::AntiAliasing::msaa, "msaa, distance 1e" + std::to_string(e));
    }
}

TEST(Depth, OpenGlConventionWithLessTestKeepsTheNearerSurfaceFromNear0p1ToFar100) {
    const double n = 0.1, f = 100.0, t = n * std::tan(kFovy / 2);
    const mr::Camera cam = mr::Camera::from_matrices(mr::look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}),
                                                     mr::frustum(-t, t, -t, t, n, f, mr::DepthConvention::opengl),
                                                     mr::DepthConvention::opengl);
    const mr::Mesh quad = unit_quad();
    for (double d : {0.5, 5.0, 50.0, 90.0})
        expect_nearer_wins(cam, quad, quad_model(d, 0.0, 0.0), quad_model(d * (1.0 + 1e-3), 0.0, 0.0),
                           mr::AntiAliasing::ssaa, "opengl, distance " + std::to_string(d));
    // Tilted, the quad spans ±30% in depth: keep it all before the far plane (100).
    for (double d : {0.5, 5.0, 50.0, 75.0})
        expect_nearer_wins(cam, quad, quad_model(d, 0.8, -0.4), quad_model(d * (1.0 + 1e-3), 0.8, -0.4),
                           mr::AntiAliasing::ssaa, "opengl tilted, distance " + std::to_string(d));
}

TEST(Depth, OrthographicCameraKeepsTheNearerSurfaceInBothConventions) {
    // Orthographic: depth is linear in view z; quads 1e-5 of the depth range apart.
    const mr::Mesh quad = unit_quad();
    for (auto c : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = mr::Camera::from_matrices(mr::look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}),
                                                         mr::orthographic(-0.5, 0.5, -0.5, 0.5, 1.0, 11.0, c), c);
        for (double d : {1.5, 6.0, 10.5}) {
            glm::dmat4 near_model = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, 1.0 - d));
            glm::dmat4 far_model = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, 1.0 - d - 1e-4));
            near_model = near_model * quad_model(1.0, 0.3, 0.2);
            far_model = far_model * quad_model(1.0, 0.3, 0.2);
            expect_nearer_wins(cam, quad, near_model, far_model, mr::AntiAliasing::ssaa,
                               "orthographic " + mr::to_string(c) + ", distance " + std::to_string(d));
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Stored depth against the ray caster
// ---------------------------------------------------------------------------------------------

/// Checks the stored depth of every covered sample against the ray-cast window depth, and the
/// clear value elsewhere. Window depth is affine in screen space and is interpolated on the
/// snapped vertices, which is the exact depth at a point moved by at most √2/512 px: the allowed
/// error is |∇depth|·√2/512 (from the ray caster, per sample) plus `rel_tol` of float rounding.
void expect_depth_matches_ray_cast(const mr::Camera& cam, const glm::dmat4& model, double rel_tol, float clear) {
    const int W = 48, H = 48, S = 4;
    const mr::Mesh quad = unit_quad();
    const bool reverse = cam.depth_convention == mr::DepthConvention::reverse_z;
    const mr::RenderResult r = mr::render({make_draw(quad, model, mr::DrawState{})}, cam,
                                          settings(W, H, S, mr::PatternKind::rotated));
    const oracle::RayCaster rc(cam.view, cam.projection, reverse, W, H);
    const oracle::Pattern p = to_oracle(r.pattern);
    const std::vector<int> cov = coverage(quad, model, cam, W, H, p);
    std::array<glm::dvec3, 4> world;
    for (int i = 0; i < 4; ++i) {
        const glm::dvec4 w = model * glm::dvec4(glm::dvec3(quad.positions[i]), 1.0);
        world[i] = glm::dvec3(w);
    }
    std::size_t checked = 0, bad = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int s = 0; s < S; ++s) {
                const std::size_t i = r.framebuffer.sample_index(x, y, s);
                const float got = r.framebuffer.depth[i];
                if (!cov[i]) {
                    EXPECT_EQ(got, clear);
                    continue;
                }
                const oracle::Fixed2 q = oracle::sample_position(x, y, p, s);
                const oracle::Ray ray = rc.ray(q.x / 256.0, q.y / 256.0);
                oracle::Hit h = rc.intersect(ray, world[0], world[1], world[2]);
                if (!h.hit) h = rc.intersect(ray, world[0], world[2], world[3]);
                const double expected = rc.window_depth(h.point);
                // Depth gradient (per pixel) of the quad's plane at the sample, by central differences.
                auto depth_at = [&](double sx, double sy) {
                    return rc.window_depth(rc.intersect(rc.ray(sx, sy), world[0], world[1], world[2]).point);
                };
                const double e = 1.0 / 64, sx = q.x / 256.0, sy = q.y / 256.0;
                const double gx = (depth_at(sx + e, sy) - depth_at(sx - e, sy)) / (2 * e);
                const double gy = (depth_at(sx, sy + e) - depth_at(sx, sy - e)) / (2 * e);
                const double tol = std::hypot(gx, gy) * oracle::kSnapBandPx * 1.01 + rel_tol * std::fabs(expected);
                ++checked;
                if (std::fabs(got - expected) > tol && ++bad < 6)
                    ADD_FAILURE() << "pixel (" << x << ", " << y << ") sample " << s << ": depth " << got
                                  << ", ray cast " << expected;
            }
    EXPECT_EQ(bad, 0u);
    EXPECT_GT(checked, 500u);
}

TEST(Depth, StoredReverseZDepthOfAFacingQuadIsNearOverDistanceToFloatPrecision) {
    const mr::Camera cam = reverse_z_camera(48, 48);
    for (int e = -2; e <= 5; ++e) {
        SCOPED_TRACE("distance 1e" + std::to_string(e));
        // Constant depth n/d: exact up to the float rounding (one ulp ≈ 1.2e-7 relative).
        expect_depth_matches_ray_cast(cam, quad_model(std::pow(10.0, e), 0, 0), 1.2e-7, 0.0f);
    }
}

TEST(Depth, StoredDepthOfATiltedQuadMatchesTheRayCastWindowDepth) {
    expect_depth_matches_ray_cast(reverse_z_camera(48, 48), quad_model(3.0, 0.7, 0.3), 3e-7, 0.0f);
    const double n = 0.1, t = n * std::tan(kFovy / 2);
    const mr::Camera gl = mr::Camera::from_matrices(mr::look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}),
                                                    mr::frustum(-t, t, -t, t, n, 100.0, mr::DepthConvention::opengl),
                                                    mr::DepthConvention::opengl);
    expect_depth_matches_ray_cast(gl, quad_model(3.0, 0.7, 0.3), 3e-7, 1.0f);
}

/// The per-pixel depth output: each pixel's view-space depth (−z_view) is that of its nearest
/// covered sample by the ray cast, +inf where no sample is covered; in the tile-buffer and kept-
/// sample paths alike. The tolerance is the snapping band times the view-depth gradient plus
/// `rel_tol` for the float window depth it is decoded from.
void expect_view_depth_matches_ray_cast(const mr::Camera& cam, const glm::dmat4& model, double rel_tol) {
    const int W = 48, H = 48;
    const mr::Mesh quad = unit_quad();
    const bool reverse = cam.depth_convention == mr::DepthConvention::reverse_z;
    const oracle::RayCaster rc(cam.view, cam.projection, reverse, W, H);
    std::array<glm::dvec3, 4> world;
    for (int i = 0; i < 4; ++i) world[i] = glm::dvec3(model * glm::dvec4(glm::dvec3(quad.positions[i]), 1.0));
    auto depth_at = [&](double sx, double sy) {
        const oracle::Ray ray = rc.ray(sx, sy);
        oracle::Hit h = rc.intersect(ray, world[0], world[1], world[2]);
        if (!h.hit) h = rc.intersect(ray, world[0], world[2], world[3]);
        return h;
    };
    for (int S : {1, 4}) {
        for (bool keep : {false, true}) {
            SCOPED_TRACE("samples " + std::to_string(S) + (keep ? ", kept samples" : ", tile buffers"));
            auto st = settings(W, H, S);
            st.keep_samples = keep;
            st.depth_output = true;
            const mr::RenderResult r = mr::render({make_draw(quad, model, mr::DrawState{})}, cam, st);
            ASSERT_EQ(r.depth.width, W);
            ASSERT_EQ(r.depth.channels, 1);
            const oracle::Pattern p = to_oracle(r.pattern);
            const std::vector<int> cov = coverage(quad, model, cam, W, H, p);
            std::size_t checked = 0, empty = 0, bad = 0;
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    double expected = std::numeric_limits<double>::infinity(), tol = 0.0;
                    for (int s = 0; s < S; ++s) {
                        if (!cov[(static_cast<std::size_t>(y) * W + x) * S + s]) continue;
                        const oracle::Fixed2 q = oracle::sample_position(x, y, p, s);
                        const double sx = q.x / 256.0, sy = q.y / 256.0, e = 1.0 / 64;
                        const double d = depth_at(sx, sy).view_distance;
                        const double gx = (depth_at(sx + e, sy).view_distance - depth_at(sx - e, sy).view_distance) / (2 * e);
                        const double gy = (depth_at(sx, sy + e).view_distance - depth_at(sx, sy - e).view_distance) / (2 * e);
                        expected = std::min(expected, d);
                        tol = std::max(tol, std::hypot(gx, gy) * oracle::kSnapBandPx * 1.01 + rel_tol * d);
                    }
                    const float got = r.depth.at(x, y, 0);
                    if (std::isinf(expected)) {
                        ++empty;
                        EXPECT_TRUE(std::isinf(got) && got > 0) << "pixel (" << x << ", " << y << ") is empty but has " << got;
                        continue;
                    }
                    ++checked;
                    if (!(std::fabs(got - expected) <= tol) && ++bad < 6)
                        ADD_FAILURE() << "pixel (" << x << ", " << y << "): view depth " << got << ", ray cast " << expected;
                }
            EXPECT_EQ(bad, 0u);
            EXPECT_GT(checked, 300u);
            EXPECT_GT(empty, 100u);
        }
    }
}

TEST(Depth, ViewDepthOutputIsTheNearestSamplesRayCastDepthAndInfinityWhereEmpty) {
    expect_view_depth_matches_ray_cast(reverse_z_camera(48, 48), quad_model(3.0, 0.7, 0.3), 1e-6);
    expect_view_depth_matches_ray_cast(reverse_z_camera(48, 48), quad_model(2000.0, 0.4, 0.9), 1e-6);
    const double n = 0.1, t = n * std::tan(kFovy / 2);
    const mr::Camera gl = mr::Camera::from_matrices(mr::look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}),
                                                    mr::frustum(-t, t, -t, t, n, 100.0, mr::DepthConvention::opengl),
                                                    mr::DepthConvention::opengl);
    expect_view_depth_matches_ray_cast(gl, quad_model(3.0, 0.7, 0.3), 2e-5);
}

TEST(Depth, ViewDepthOutputIsLeftOutUnlessAskedAndRefusedForProjectionsItCannotInvert) {
    const mr::Mesh quad = unit_quad();
    const mr::Camera cam = reverse_z_camera(16, 16);
    auto st = settings(16, 16);
    EXPECT_EQ(mr::render({make_draw(quad, quad_model(3.0, 0, 0), mr::DrawState{})}, cam, st).depth.pixels.size(), 0u);
    st.depth_output = true;
    EXPECT_EQ(mr::render({make_draw(quad, quad_model(3.0, 0, 0), mr::DrawState{})}, cam, st).depth.pixels.size(), 256u);
    // A projection whose w row depends on x has no per-pixel inverse from window depth alone.
    mr::Camera skew = cam;
    skew.projection[0][3] = 0.1;
    try {
        mr::render({make_draw(quad, quad_model(3.0, 0, 0), mr::DrawState{})}, skew, st);
        ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("depth output"), std::string::npos) << e.what();
    }
}

TEST(Depth, IntersectingQuadsShowTheSurfaceTheRayCasterFindsNearer) {
    const int W = 64, H = 64, S = 4;
    const mr::Camera cam = reverse_z_camera(W, H);
    const mr::Mesh quad = unit_quad();
    const glm::dmat4 ma = quad_model(2.0, 0.6, 0.1), mb = quad_model(2.0, -0.5, -0.2);
    const mr::RenderResult r =
        mr::render({make_draw(quad, ma, mr::DrawState{}, kRed), make_draw(quad, mb, mr::DrawState{}, kGreen)}, cam,
                   settings(W, H, S, mr::PatternKind::rotated));
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    const oracle::Pattern p = to_oracle(r.pattern);
    const std::vector<int> ca = coverage(quad, ma, cam, W, H, p), cb = coverage(quad, mb, cam, W, H, p);
    auto world = [&](const glm::dmat4& m, int i) { return glm::dvec3(m * glm::dvec4(glm::dvec3(quad.positions[i]), 1.0)); };
    auto distance = [&](const oracle::Ray& ray, const glm::dmat4& m) {
        for (const auto& t : quad.triangles) {
            const oracle::Hit h = rc.intersect(ray, world(m, t[0]), world(m, t[1]), world(m, t[2]));
            if (h.hit) return h.view_distance;
        }
        return std::numeric_limits<double>::infinity();
    };
    std::size_t both = 0, skipped = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int s = 0; s < S; ++s) {
                const std::size_t i = r.framebuffer.sample_index(x, y, s);
                if (!(ca[i] && cb[i])) continue;  // coverage alone is tested elsewhere
                const oracle::Fixed2 q = oracle::sample_position(x, y, p, s);
                const oracle::Ray ray = rc.ray(q.x / 256.0, q.y / 256.0);
                const double da = distance(ray, ma), db = distance(ray, mb);
                // Near the intersection line snapping and float depth may decide either way.
                if (!std::isfinite(da) || !std::isfinite(db) || std::fabs(da - db) < 1e-4 * da) {
                    ++skipped;
                    continue;
                }
                ++both;
                const glm::vec4 want = da < db ? kRed : kGreen;
                EXPECT_EQ(sample_color(r.framebuffer, x, y, s), want) << "pixel (" << x << ", " << y << ") sample " << s;
            }
    EXPECT_GT(both, 1000u);
    EXPECT_LT(skipped, both / 20);
}

// ---------------------------------------------------------------------------------------------
// Depth state and the depth buffer itself
// ---------------------------------------------------------------------------------------------

TEST(Depth, NoDepthBufferIsAllocatedWhenNoDrawTestsDepth) {
    const mr::Mesh quad = unit_quad();
    const mr::Camera cam = reverse_z_camera(32, 32);
    const mr::RenderResult none = mr::render({make_draw(quad, quad_model(2, 0, 0), no_depth()),
                                              make_draw(quad, quad_model(3, 0, 0), no_depth())},
                                             cam, settings(32, 32, 4));
    EXPECT_FALSE(none.framebuffer.has_depth());
    EXPECT_TRUE(none.framebuffer.depth.empty());
    EXPECT_GT(none.stats.samples_covered, 0u);

    // One draw that tests depth is enough to allocate it, cleared to the convention's far value.
    const mr::RenderResult one = mr::render({make_draw(quad, quad_model(2, 0, 0), no_depth()),
                                             make_draw(quad, quad_model(50, 0, 0), mr::DrawState{})},
                                            cam, settings(32, 32, 4));
    ASSERT_EQ(one.framebuffer.depth.size(), std::size_t{32} * 32 * 4);
    EXPECT_EQ(one.framebuffer.depth[0], 0.0f);  // corner sample: uncovered, reverse-Z clear
    const mr::Camera gl = mr::Camera::from_matrices(glm::dmat4(1.0), glm::dmat4(1.0), mr::DepthConvention::opengl);
    mr::Mesh small;
    small.positions = {{-0.1f, -0.1f, 0.0f}, {0.1f, -0.1f, 0.0f}, {0.0f, 0.1f, 0.0f}};
    add_triangle(small, 0, 1, 2);
    const mr::RenderResult cleared = mr::render({make_draw(small, glm::dmat4(1.0), mr::DrawState{})}, gl, settings(8, 8, 1));
    ASSERT_EQ(cleared.framebuffer.depth.size(), 64u);
    EXPECT_EQ(cleared.framebuffer.depth[0], 1.0f);  // OpenGL clear
}

TEST(Depth, DrawWithoutDepthWriteLeavesTheDepthBufferForLaterDraws) {
    const int W = 32, H = 32;
    const mr::Camera cam = reverse_z_camera(W, H);
    const mr::Mesh quad = unit_quad();
    mr::DrawState test_only;
    test_only.depth_write = false;
    // Near red quad tests but does not write; the far green quad drawn after it still passes.
    const mr::RenderResult r = mr::render({make_draw(quad, quad_model(2, 0, 0), test_only, kRed),
                                           make_draw(quad, quad_model(3, 0, 0), mr::DrawState{}, kGreen)},
                                          cam, settings(W, H, 1));
    const std::vector<int> cn = coverage(quad, quad_model(2, 0, 0), cam, W, H, oracle::center_pattern());
    const std::vector<int> cf = coverage(quad, quad_model(3, 0, 0), cam, W, H, oracle::center_pattern());
    std::vector<float> er(cn.size()), eg(cn.size());
    for (std::size_t i = 0; i < cn.size(); ++i) {
        er[i] = (cn[i] && !cf[i]) ? 1.0f : 0.0f;
        eg[i] = cf[i] ? 1.0f : 0.0f;
    }
    EXPECT_TRUE(samples_equal(r.framebuffer, er, 0, "red"));
    EXPECT_TRUE(samples_equal(r.framebuffer, eg, 1, "green"));
}

}  // namespace
