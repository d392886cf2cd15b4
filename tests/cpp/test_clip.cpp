// Clipping (DESIGN.md §2.2): near-plane clipping in homogeneous space draws exactly the part of a
// triangle in front of the near plane (checked against a double-precision ray caster), a shared
// edge clips to bit-identical vertices from either triangle, nothing behind the camera draws, and
// triangles far beyond the guard band cover exactly the samples of the unclipped triangle.
//
// Tolerance: the only allowed differences from the exact (unsnapped) geometry are samples within
// oracle::kSnapBandPx = √2/512 px of an edge: snapping moves every vertex, and so every point of
// an edge, by up to half a 1/256 step per axis. (1e-3 px would be below that error.) Their
// number must also be a tiny fraction of the samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "helpers.hpp"
#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/clip.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

/// Per-sample comparison of a render with an expected coverage that has a "near an edge" band.
struct BandCompare {
    std::size_t samples = 0, covered = 0, in_band = 0, band_mismatch = 0, hard_mismatch = 0, over_one = 0;
};

/// World position of a view-space point (own inverse of the view matrix).
glm::dvec3 to_world_d(const oracle::Mat4& inv_view, double x, double y, double z) {
    const auto p = oracle::apply(inv_view, {x, y, z, 1.0});
    return {p[0], p[1], p[2]};
}
glm::vec3 to_world(const oracle::Mat4& inv_view, double x, double y, double z) {
    return glm::vec3(to_world_d(inv_view, x, y, z));
}

// ---------------------------------------------------------------------------------------------
// Near plane, perspective, reverse-Z
// ---------------------------------------------------------------------------------------------

/// Random triangles crossing the near plane (and, when `far` is finite, the far plane), each
/// drawn alone with additive white: every sample matches the ray caster's "hit at a view distance
/// in [near, far]", except samples within the snapping band of the visible polygon's edges.
/// With `cull`, back faces (by their 3D normal) must draw nothing.
void expect_clipped_coverage_matches_ray_cast(const mr::Camera& cam, double near, double far, mr::CullMode cull,
                                              std::uint64_t seed) {
    const int W = 96, H = 64, S = 16;
    const oracle::RayCaster rc(cam.view, cam.projection, cam.depth_convention == mr::DepthConvention::reverse_z, W, H);
    const oracle::Mat4 inv_view = oracle::inverse(oracle::from_glm(cam.view));
    const oracle::Pattern grid = oracle::grid_pattern(4);
    const glm::dvec3 eye = to_world_d(inv_view, 0, 0, 0);
    const double tx = 1.0 / cam.projection[0][0], ty = 1.0 / cam.projection[1][1];  // tan of the half angles

    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    BandCompare total;
    int clipped_triangles = 0, culled = 0, kept = 0;
    std::uint64_t backface = 0;
    for (int t = 0; t < 24; ++t) {
        // One or two vertices between the near and far planes, the others behind the near plane
        // (some behind the eye) or, with a far plane, beyond it. Half of the triangles have their
        // vertex behind the near plane just before it and close to the view axis, so that the
        // line where the near plane cuts them projects into the viewport.
        const int in_front = 1 + static_cast<int>(rng() % 2);
        const bool cut_on_screen = (rng() & 1) != 0;
        std::vector<glm::vec3> pos;
        for (int i = 0; i < 3; ++i) {
            double d, s;  // view distance, lateral scale
            if (i < in_front) {
                d = near + 0.25 + (std::min(far, 4.0) - near - 0.5) * u(rng);
                s = std::max(d, 0.4);
            } else if (cut_on_screen) {
                d = near * (0.3 + 0.65 * u(rng));
                s = near;
            } else if (std::isfinite(far) && (rng() & 1)) {
                d = far * (1.2 + u(rng));
                s = d;
            } else {
                d = -1.5 + (1.5 + 0.8 * near) * u(rng);
                s = std::max(std::fabs(d), 0.4);
            }
            pos.push_back(to_world(inv_view, (2.4 * u(rng) - 1.2) * s * tx, (2.4 * u(rng) - 1.2) * s * ty, -d));
        }
        std::rotate(pos.begin(), pos.begin() + static_cast<long>(rng() % 3), pos.end());
        mr::Mesh m;
        m.positions = pos;
        add_triangle(m, 0, 1, 2);
        mr::DrawState st = no_depth(mr::BlendMode::add);
        st.cull = cull;
        const mr::RenderResult r =
            mr::render({make_draw(m, glm::dmat4(1.0), st)}, cam, settings(W, H, S, mr::PatternKind::grid));
        ASSERT_TRUE(same_offsets(to_oracle(r.pattern), grid));
        clipped_triangles += static_cast<int>(r.stats.triangles_clipped);
        backface += r.stats.triangles_backface;

        const std::array<glm::dvec3, 3> tri = {glm::dvec3(pos[0]), glm::dvec3(pos[1]), glm::dvec3(pos[2])};
        // Front faces are counter-clockwise seen from the eye: their normal points at it.
        const glm::dvec3 normal = oracle::RayCaster::cross3(tri[1] - tri[0], tri[2] - tri[0]);
        const bool front = oracle::RayCaster::dot3(normal, eye - tri[0]) > 0.0;
        const bool drawn = cull == mr::CullMode::none || (cull == mr::CullMode::back) == front;
        (drawn ? kept : culled) += 1;
        const std::vector<glm::dvec2> visible = oracle::visible_polygon(rc, tri, near, far);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                for (int s = 0; s < S; ++s) {
                    const oracle::Fixed2 q = oracle::sample_position(x, y, grid, s);
                    const double sx = q.x / 256.0, sy = q.y / 256.0;
                    const oracle::Hit h = rc.intersect(rc.ray(sx, sy), tri[0], tri[1], tri[2]);
                    const bool expected = drawn && h.hit && h.view_distance >= near && h.view_distance <= far;
                    const float got = sample_channel(r.framebuffer, x, y, s, 0);
                    ++total.samples;
                    total.covered += expected;
                    total.over_one += got > 1.0f;
                    const bool near_edge = visible.size() >= 3 && oracle::distance_to_boundary({sx, sy}, visible) <= oracle::kSnapBandPx;
                    total.in_band += near_edge;
                    if (got != (expected ? 1.0f : 0.0f)) {
                        if (near_edge && drawn) {
                            ++total.band_mismatch;
                        } else {
                            ++total.hard_mismatch;
                            if (total.hard_mismatch < 6)
                                ADD_FAILURE() << "triangle " << t << " pixel (" << x << ", " << y << ") sample " << s
                                              << ": got " << got << ", ray cast says " << expected
                                              << " (view distance " << h.view_distance << ")";
                        }
                    }
                }
    }
    EXPECT_EQ(clipped_triangles, 24);
    EXPECT_EQ(total.hard_mismatch, 0u);
    EXPECT_EQ(total.over_one, 0u);
    EXPECT_GT(total.covered, total.samples / 40) << "triangles cover too little to test";
    EXPECT_LE(total.band_mismatch, total.covered / 200) << "more than 0.5% of samples differ near edges";
    if (cull != mr::CullMode::none) {
        EXPECT_GT(culled, 4);
        EXPECT_GT(kept, 4);
        EXPECT_EQ(backface, static_cast<std::uint64_t>(culled)) << "each culled triangle counts once";
    }
}

TEST(Clip, TrianglesCrossingTheNearPlaneDrawExactlyThePartInFrontOfIt) {
    const double near = 0.05;
    const mr::Camera cam =
        mr::Camera::look_at_perspective({1.0, 2.0, 3.0}, {1.3, 1.8, 2.0}, {0.0, 1.0, 0.0}, 1.2, 96.0 / 64.0, near);
    ASSERT_EQ(cam.depth_convention, mr::DepthConvention::reverse_z);
    expect_clipped_coverage_matches_ray_cast(cam, near, mr::kInfiniteFar, mr::CullMode::none, 2024);
}

TEST(Clip, TrianglesCrossingTheNearAndFarPlanesDrawExactlyThePartBetweenThemInBothDepthConventions) {
    const double near = 0.05, far = 2.5, t = near * 0.6;
    for (auto c : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        SCOPED_TRACE(mr::to_string(c));
        const mr::Camera cam = mr::Camera::from_matrices(mr::look_at({-1.0, 0.5, 2.0}, {-0.7, 0.3, 1.0}, {0.0, 1.0, 0.0}),
                                                         mr::frustum(-1.5 * t, 1.5 * t, -t, t, near, far, c), c);
        expect_clipped_coverage_matches_ray_cast(cam, near, far, mr::CullMode::none, 77);
    }
}

TEST(Clip, FaceCullingOfTrianglesCrossingTheNearPlaneFollowsTheirFacingInSpace) {
    const double near = 0.05;
    const mr::Camera cam =
        mr::Camera::look_at_perspective({1.0, 2.0, 3.0}, {1.3, 1.8, 2.0}, {0.0, 1.0, 0.0}, 1.2, 96.0 / 64.0, near);
    expect_clipped_coverage_matches_ray_cast(cam, near, mr::kInfiniteFar, mr::CullMode::back, 31);
    expect_clipped_coverage_matches_ray_cast(cam, near, mr::kInfiniteFar, mr::CullMode::front, 32);
}

TEST(Clip, GroundGridCrossingTheNearPlaneAndTheGuardBandIsWatertight) {
    // A floor (y = 0) from behind the camera to 1e5 away and ±1e5 sideways, as a 40×40 grid of
    // quads with graded spacing: triangles cross the near plane, the eye plane and the guard band.
    const int W = 128, H = 96, S = 4;
    const double near = 0.05;
    const mr::Camera cam =
        mr::Camera::look_at_perspective({0.0, 1.0, 0.0}, {0.0, 0.55, -5.0}, {0.0, 1.0, 0.0}, 1.1, double(W) / H, near);
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    const int n = 40;
    auto graded = [](double t, double lo, double hi) {  // t in [0,1], dense around 0 of the world
        const double a = 8.0, s = std::sinh(a * (2.0 * t - 1.0)) / std::sinh(a);
        return s < 0 ? lo * s : hi * s;
    };
    mr::Mesh m;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            m.positions.push_back(glm::vec3(static_cast<float>(graded(i / double(n), 1e5, 1e5)), 0.0f,
                                            static_cast<float>(graded(j / double(n), 1e5, 3.0))));
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            add_triangle(m, a, b, c);
            add_triangle(m, a, c, d);
        }
    const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), no_depth(mr::BlendMode::add))}, cam,
                                          settings(W, H, S, mr::PatternKind::rotated));
    EXPECT_GT(r.stats.triangles_clipped, 0u);
    const oracle::Pattern p = to_oracle(r.pattern);
    ASSERT_TRUE(same_offsets(p, oracle::rotated_pattern()));

    // The floor's outline, for the near-edge band (interior edges are shared and may not differ).
    const float x0 = m.positions.front().x, x1 = m.positions[n].x;
    const float z0 = m.positions.front().z, z1 = m.positions.back().z;
    const std::vector<glm::dvec3> outline = {{x0, 0, z0}, {x1, 0, z0}, {x1, 0, z1}, {x0, 0, z1}};
    const std::vector<glm::dvec2> visible = oracle::visible_polygon(rc, outline, near);
    BandCompare c;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int s = 0; s < S; ++s) {
                const oracle::Fixed2 q = oracle::sample_position(x, y, p, s);
                const double sx = q.x / 256.0, sy = q.y / 256.0;
                const oracle::Ray ray = rc.ray(sx, sy);
                const oracle::Hit h1 = rc.intersect(ray, outline[0], outline[1], outline[2]);
                const oracle::Hit h2 = rc.intersect(ray, outline[0], outline[2], outline[3]);
                const bool expected = (h1.hit && h1.view_distance >= near) || (h2.hit && h2.view_distance >= near);
                const float got = sample_channel(r.framebuffer, x, y, s, 0);
                ++c.samples;
                c.covered += expected;
                c.over_one += got > 1.0f;
                if (got != (expected ? 1.0f : 0.0f)) {
                    if (oracle::distance_to_boundary({sx, sy}, visible) <= oracle::kSnapBandPx) {
                        ++c.band_mismatch;
                    } else if (++c.hard_mismatch < 6) {
                        ADD_FAILURE() << "pixel (" << x << ", " << y << ") sample " << s << ": got " << got
                                      << ", expected " << expected;
                    }
                }
            }
    EXPECT_EQ(c.over_one, 0u) << "samples covered twice: the clipped mesh is not watertight";
    EXPECT_EQ(c.hard_mismatch, 0u);
    EXPECT_GT(c.covered, c.samples / 4);
    EXPECT_LE(c.band_mismatch, c.covered / 200);
}

TEST(Clip, TrianglesBehindTheCameraOrBeforeTheNearPlaneDrawNothing) {
    const int W = 64, H = 64;
    const double near = 0.05;
    const mr::Camera rz = mr::Camera::look_at_perspective({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.0, 1.0, near);
    const mr::Camera gl = mr::Camera::from_matrices(
        glm::dmat4(1.0), mr::frustum(-near, near, -near, near, near, 100.0, mr::DepthConvention::opengl),
        mr::DepthConvention::opengl);
    // View space is world space for both cameras (eye at the origin looking down −z).
    const std::vector<std::vector<glm::vec3>> cases = {
        // entirely behind the eye, large: a projection without clipping would fill the screen (w < 0)
        {{-10, -10, 1}, {10, -10, 1}, {0, 10, 2}},
        {{-5, -5, 0.5f}, {5, -5, 3}, {0, 5, 0.1f}},
        // between the eye and the near plane
        {{-0.01f, -0.01f, -0.04f}, {0.01f, -0.01f, -0.03f}, {0, 0.01f, -0.049f}},
        // straddling the eye plane, every point nearer than the near plane
        {{-0.02f, -0.02f, -0.04f}, {0.03f, -0.01f, 0.5f}, {0, 0.03f, 0.02f}},
    };
    for (const mr::Camera& cam : {rz, gl}) {
        for (std::size_t k = 0; k < cases.size(); ++k) {
            SCOPED_TRACE("case " + std::to_string(k) + ", " + mr::to_string(cam.depth_convention));
            mr::Mesh m;
            m.positions = cases[k];
            add_triangle(m, 0, 1, 2);
            const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), no_depth(mr::BlendMode::add))}, cam,
                                                  settings(W, H, 4));
            EXPECT_EQ(r.stats.samples_covered, 0u);
            EXPECT_EQ(r.stats.triangles_rasterized, 0u);
            EXPECT_EQ(r.stats.triangles_outside, 1u);
            EXPECT_TRUE(std::all_of(r.framebuffer.color.begin(), r.framebuffer.color.end(), [](float v) { return v == 0.0f; }));
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Shared edges clip to the same bits
// ---------------------------------------------------------------------------------------------

/// Positions of the clipped polygon's vertices that lie on the edge between the triangle's
/// corners other than `apex` (weight of apex exactly 0), sorted.
std::vector<glm::dvec4> points_on_edge(mr::ClipOutcome outcome, const mr::ClipPolygon& poly,
                                       const std::array<glm::dvec4, 3>& input, int apex) {
    std::vector<glm::dvec4> pts;
    if (outcome == mr::ClipOutcome::inside) {
        for (int i = 0; i < 3; ++i)
            if (i != apex) pts.push_back(input[i]);
    } else if (outcome == mr::ClipOutcome::clipped) {
        for (int i = 0; i < poly.count; ++i)
            if (poly.vertices[i].weights[apex] == 0.0) pts.push_back(poly.vertices[i].position);
    }
    std::sort(pts.begin(), pts.end(), [](const glm::dvec4& a, const glm::dvec4& b) {
        for (int i = 0; i < 4; ++i)
            if (a[i] != b[i]) return a[i] < b[i];
        return false;
    });
    return pts;
}

TEST(Clip, SharedEdgeClipsToBitIdenticalVerticesFromEitherTriangle) {
    const int W = 640, H = 480;
    const mr::ClipVolume volume = mr::make_clip_volume(mr::DepthConvention::reverse_z, W, H);
    const double gx = 2.0 * mr::kGuardBandPx / W, gy = 2.0 * mr::kGuardBandPx / H;
    std::mt19937_64 rng(555);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    // Clip-space points: w from behind the eye to far in front, x and y up to 3× the guard band,
    // z on both sides of the near plane (z ≤ w) and of the far plane (z ≥ 0).
    auto random_point = [&]() {
        const double w = 1.5 + 2.0 * u(rng);
        return glm::dvec4(3.0 * gx * w * u(rng), 3.0 * gy * w * u(rng), (0.6 + 0.8 * u(rng)) * std::fabs(w), w);
    };
    int cases = 0, cut = 0, compared_points = 0;
    for (int k = 0; k < 2000; ++k) {
        const glm::dvec4 A = random_point(), B = random_point(), C = random_point(), D = random_point();
        // Triangle 1 (A, B, C), triangle 2 (B, A, D) as in a consistently wound mesh, plus rotations.
        const std::array<glm::dvec4, 3> t1 = {A, B, C}, t1r = {C, A, B}, t2 = {B, A, D}, t2r = {D, B, A};
        mr::ClipPolygon p1, p1r, p2, p2r;
        auto clip = [&](const std::array<glm::dvec4, 3>& t, mr::ClipPolygon& out) {
            const std::array<std::uint8_t, 3> codes = {mr::outcode(t[0], volume), mr::outcode(t[1], volume),
                                                       mr::outcode(t[2], volume)};
            return mr::clip_triangle(t, codes, volume, out);
        };
        const auto o1 = clip(t1, p1), o1r = clip(t1r, p1r), o2 = clip(t2, p2), o2r = clip(t2r, p2r);
        const auto e1 = points_on_edge(o1, p1, t1, 2), e1r = points_on_edge(o1r, p1r, t1r, 0);
        const auto e2 = points_on_edge(o2, p2, t2, 2), e2r = points_on_edge(o2r, p2r, t2r, 0);
        ++cases;
        // Points of the shared edge that clipping created (not A or B themselves).
        for (const auto& p : e1) cut += (std::memcmp(&p, &A, sizeof p) != 0 && std::memcmp(&p, &B, sizeof p) != 0);
        for (const auto* other : {&e1r, &e2, &e2r}) {
            ASSERT_EQ(other->size(), e1.size()) << "case " << k;
            for (std::size_t i = 0; i < e1.size(); ++i)
                EXPECT_EQ(std::memcmp(&(*other)[i], &e1[i], sizeof(glm::dvec4)), 0)
                    << "case " << k << " point " << i << ": (" << (*other)[i].x << ", " << (*other)[i].y << ", "
                    << (*other)[i].z << ", " << (*other)[i].w << ") vs (" << e1[i].x << ", " << e1[i].y << ", "
                    << e1[i].z << ", " << e1[i].w << ")";
        }
        compared_points += static_cast<int>(e1.size());
        // Every clipped polygon lies inside the volume (up to rounding) and has w > 0.
        for (const auto* poly : {&p1, &p2})
            if ((poly == &p1 ? o1 : o2) == mr::ClipOutcome::clipped)
                for (int i = 0; i < poly->count; ++i) {
                    const glm::dvec4& v = poly->vertices[i].position;
                    EXPECT_GT(v.w, 0.0);
                    for (const mr::ClipPlane& plane : volume.planes)
                        EXPECT_GE(plane.distance(v), -1e-9 * (std::fabs(v.x) + std::fabs(v.y) + std::fabs(v.z) + std::fabs(v.w)));
                }
    }
    EXPECT_EQ(cases, 2000);
    EXPECT_GT(cut, 500) << "too few shared edges were cut by a plane";
    EXPECT_GT(compared_points, 1000);
}

// ---------------------------------------------------------------------------------------------
// Far beyond the guard band
// ---------------------------------------------------------------------------------------------

/// Triangles with every vertex 2e6…1e7 px away (beyond the guard band, 2^20 px) and two edges
/// through the viewport, drawn one at a time: the samples match the exact unclipped triangle.
void expect_huge_triangles_match_exact_coverage(int W, int H, int S, int count, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double pi = 3.14159265358979323846;
    BandCompare c;
    int clipped = 0;
    for (int t = 0; t < count; ++t) {
        // A is far away; the edges A–B and A–C pass through random points of the viewport and B, C
        // lie far beyond them: two edges cross the viewport, every vertex is 2e6…1e7 px away.
        const double th = 2.0 * pi * u(rng), ra = 2e6 + 8e6 * u(rng);
        const glm::dvec2 centre(W / 2.0, H / 2.0);
        const glm::dvec2 A = centre + ra * glm::dvec2(std::cos(th), std::sin(th));
        const glm::dvec2 P1(W * u(rng), H * u(rng)), P2(W * u(rng), H * u(rng));
        const glm::dvec2 B = P1 + (2e6 + 8e6 * u(rng)) * (P1 - A) / std::hypot(P1.x - A.x, P1.y - A.y);
        const glm::dvec2 C = P2 + (2e6 + 8e6 * u(rng)) * (P2 - A) / std::hypot(P2.x - A.x, P2.y - A.y);
        mr::Mesh m;
        for (const glm::dvec2& v : {A, B, C})  // pixels → NDC, as float
            m.positions.push_back(glm::vec3(static_cast<float>(2.0 * v.x / W - 1.0), static_cast<float>(1.0 - 2.0 * v.y / H), 0.0f));
        add_triangle(m, 0, 1, 2);
        const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), no_depth(mr::BlendMode::add))},
                                              identity_camera(), settings(W, H, S));
        clipped += static_cast<int>(r.stats.triangles_clipped);
        const oracle::Pattern p = to_oracle(r.pattern);
        // The exact triangle: the float vertices in screen pixels (exact in double for
        // power-of-two W and H).
        std::array<glm::dvec2, 3> v;
        for (int i = 0; i < 3; ++i)
            v[i] = {oracle::ndc_to_screen_x(m.positions[i].x, W), oracle::ndc_to_screen_y(m.positions[i].y, H)};
        const double orient = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[1].y - v[0].y) * (v[2].x - v[0].x);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                for (int s = 0; s < S; ++s) {
                    const oracle::Fixed2 q = oracle::sample_position(x, y, p, s);
                    const glm::dvec2 sp(q.x / 256.0, q.y / 256.0);
                    double min_d = 1e300;
                    bool inside = true;
                    for (int i = 0; i < 3; ++i) {
                        double d = oracle::signed_line_distance(sp, v[i], v[(i + 1) % 3]);
                        if (orient < 0) d = -d;
                        inside &= d >= 0.0;
                        min_d = std::min(min_d, std::fabs(d));
                    }
                    const float got = sample_channel(r.framebuffer, x, y, s, 0);
                    ++c.samples;
                    c.covered += inside;
                    c.over_one += got > 1.0f;
                    if (got != (inside ? 1.0f : 0.0f)) {
                        if (min_d <= oracle::kSnapBandPx) {
                            ++c.band_mismatch;
                        } else if (++c.hard_mismatch < 6) {
                            ADD_FAILURE() << "triangle " << t << " pixel (" << x << ", " << y << ") sample " << s
                                          << ": got " << got << ", expected " << inside << ", distance " << min_d;
                        }
                    }
                }
    }
    EXPECT_EQ(clipped, count) << "every triangle should have been clipped to the guard band";
    EXPECT_EQ(c.hard_mismatch, 0u);
    EXPECT_EQ(c.over_one, 0u);
    EXPECT_GT(c.covered, c.samples / 10);
    EXPECT_LT(c.covered, c.samples - c.samples / 10);
    EXPECT_LE(c.band_mismatch, c.samples / 200);
}

TEST(Clip, TrianglesWithVerticesBeyondTheGuardBandCoverTheSamplesOfTheUnclippedTriangle) {
    expect_huge_triangles_match_exact_coverage(64, 64, 16, 30, 8080);
}

TEST(Clip, TrianglesBeyondTheGuardBandCoverTheExactSamplesInTheLargestViewport) {
    expect_huge_triangles_match_exact_coverage(32768, 8, 1, 8, 8181);
}

/// Squares of half-diagonal 5e6…1e7 px around a point of the viewport, split along a diagonal
/// through that point: after guard-band clipping every sample is still covered exactly once.
void expect_huge_quads_watertight(int W, int H, int S, int count, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double pi = 3.14159265358979323846;
    for (int k = 0; k < count; ++k) {
        // A square of half-diagonal R ≈ 1e7 px around a point in the viewport, rotated at random:
        // its diagonal A–C crosses the viewport.
        const glm::dvec2 c(W * u(rng), H * u(rng));
        const double R = 5e6 + 5e6 * u(rng), th = 2 * pi * u(rng);
        mr::Mesh m;
        for (int i = 0; i < 4; ++i) {
            const double a = th + i * pi / 2;
            const glm::dvec2 v = c + R * glm::dvec2(std::cos(a), std::sin(a));
            m.positions.push_back(glm::vec3(static_cast<float>(2.0 * v.x / W - 1.0), static_cast<float>(1.0 - 2.0 * v.y / H), 0.0f));
        }
        add_triangle(m, 0, 1, 2);
        add_triangle(m, 0, 2, 3);
        const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), no_depth(mr::BlendMode::add))},
                                              identity_camera(), settings(W, H, S));
        EXPECT_EQ(r.stats.triangles_clipped, 2u);
        EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(static_cast<std::size_t>(W) * H * S, 1.0f), 0,
                                  "coverage count"))
            << "quad " << k;
    }
}

TEST(Clip, HugeQuadsSplitAlongADiagonalThroughTheViewportStayWatertightAfterGuardBandClipping) {
    expect_huge_quads_watertight(64, 64, 16, 20, 99);
}

TEST(Clip, HugeQuadsStayWatertightInTheLargestViewport) {
    expect_huge_quads_watertight(32768, 8, 1, 6, 100);
}

TEST(Clip, StatsCountASubmittedTriangleOnceWhateverItsClippedPieces) {
    // A floor triangle crossing the near plane clips into a quadrilateral (two pieces); culled
    // as a front face, it is one culled triangle, not two.
    const mr::Camera cam = mr::Camera::look_at_perspective({0, 1, 0}, {0, 1, -1}, {0, 1, 0}, 1.0, 1.0, 0.1);
    mr::Mesh m;
    m.positions = {{-5, 0, -10}, {0, 0, 2}, {5, 0, -10}};
    add_triangle(m, 0, 1, 2);
    for (mr::CullMode cull : {mr::CullMode::front, mr::CullMode::back}) {
        mr::DrawState st = no_depth();
        st.cull = cull;
        const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), st)}, cam, settings(64, 64));
        EXPECT_EQ(r.stats.triangles_in, 1u);
        EXPECT_EQ(r.stats.triangles_clipped, 1u);
        // (p1 − p0) × (p2 − p0) = (0, 120, 0) points up at the camera: a front face.
        const bool culled = cull == mr::CullMode::front;
        EXPECT_EQ(r.stats.triangles_backface, culled ? 1u : 0u) << mr::to_string(cull);
        EXPECT_EQ(r.stats.triangles_rasterized, culled ? 0u : 2u) << mr::to_string(cull);
        EXPECT_EQ(r.stats.samples_covered > 0, !culled) << mr::to_string(cull);
    }
}

}  // namespace

namespace {

// A zero-area triangle reaching past the guard band used to be clipped first: the rounded crossing
// points left the line and the pieces got area, covering samples along it (stress suite, case 8:
// 434 samples from 400 collinear triangles). It is now culled before clipping, counted degenerate.
TEST(Clip, CollinearTrianglesReachingPastTheGuardBandCoverNothing) {
    const int W = 128;
    std::mt19937_64 rng(3);
    std::uniform_int_distribution<int> cell(0, W / 16 - 1), step(-4096, 4096);
    std::vector<glm::dvec4> clip;
    std::vector<glm::uvec3> tris;
    for (int k = 0; k < 400; ++k) {
        // Vertices c − 2^20·d, c, c + 2^20·d in 1/256 px units: exactly collinear in double NDC.
        const glm::dvec2 c(cell(rng) * 4096.0, cell(rng) * 4096.0), d(step(rng), step(rng));
        const std::uint32_t first = static_cast<std::uint32_t>(clip.size());
        for (const double t : {-1048576.0, 0.0, 1048576.0}) {
            const glm::dvec2 u = c + t * d;
            clip.push_back(glm::dvec4(u.x / (128.0 * W) - 1.0, 1.0 - u.y / (128.0 * W), 0.0, 1.0));
        }
        tris.push_back(glm::uvec3(first, first + 1, first + 2));
    }
    mr::RasterizeSettings rs;
    rs.width = rs.height = W;
    rs.samples = 16;
    rs.threads = 2;
    const mr::Visibility vis = mr::rasterize(clip, tris, rs);
    std::size_t covered = 0;
    for (const std::int32_t id : vis.triangle_id) covered += id >= 0;
    EXPECT_EQ(covered, 0u);
    EXPECT_EQ(vis.stats.samples_covered, 0u);
    EXPECT_EQ(vis.stats.triangles_degenerate, 400u);
}

TEST(Clip, ProjectsToALineFindsZeroAreaButNotThinTriangles) {
    // Collinear on screen with different w; in a plane through the eye; a point.
    EXPECT_TRUE(mr::projects_to_a_line({glm::dvec4(1, 2, 0, 1), glm::dvec4(4, 8, 5, 2), glm::dvec4(-3, -6, 1, -1)}));
    EXPECT_TRUE(mr::projects_to_a_line({glm::dvec4(0, 0, 0, 1), glm::dvec4(0, 0, 0.5, 2), glm::dvec4(0.5, 0, 0, 1)}));
    EXPECT_TRUE(mr::projects_to_a_line({glm::dvec4(3, 3, 0, 1), glm::dvec4(3, 3, 0, 1), glm::dvec4(3, 3, 0, 1)}));
    // A sliver 2^31 px long (NDC 2^24 at W = 256) and 10^-3 px wide is a triangle.
    const double half_px = 1.0 / 128.0;  // NDC per px at W = 256
    EXPECT_FALSE(mr::projects_to_a_line({glm::dvec4(-16777216.0, 0, 0, 1), glm::dvec4(16777216.0, 0, 0, 1),
                                         glm::dvec4(0.0, 1e-3 * half_px, 0, 1)}));
    // A sliver whose determinant is 10^-16 of its permanent, below double's rounding and far above
    // binary128's, is a triangle; exactly collinear points are not.
    EXPECT_FALSE(mr::projects_to_a_line({glm::dvec4(1, 1, 0, 1), glm::dvec4(2, 2, 0, 1),
                                         glm::dvec4(3, std::nextafter(3.0, 4.0), 0, 1)}));
    EXPECT_TRUE(mr::projects_to_a_line({glm::dvec4(1, 1, 0, 1), glm::dvec4(2, 2, 0, 1), glm::dvec4(3, 3, 0, 1)}));
}

TEST(Clip, ProjectsToALineGivesTheSameAnswerAtAnyScale) {
    // The same line and the same triangle with every coordinate scaled by 10^-200 … 10^200, and
    // with each vertex scaled by its own factor (the same projective point): products of 10^160
    // overflowed and of 10^-200 vanished, and the triangle counted as a line.
    for (const double scale : {1e-200, 1e-100, 1.0, 1e100, 1e160, 1e200}) {
        for (const double own : {1.0, 1e-50, 1e50}) {
            const glm::dvec4 a = glm::dvec4(1, 2, 0, 1) * scale, c = glm::dvec4(-3, -6, 0, 1) * scale;
            EXPECT_TRUE(mr::projects_to_a_line({a, glm::dvec4(2, 4, 0, 1) * scale * own, c})) << scale << " " << own;
            EXPECT_FALSE(mr::projects_to_a_line({a, glm::dvec4(2, 5, 0, 1) * scale * own, c})) << scale << " " << own;
        }
    }
}

TEST(Clip, ATriangleWhoseWLieBelowTheSmallestClipWIsScaledNotCutAway) {
    // Clip-space w of 10^-40 (below kMinClipW = 10^-30), x, y and z in proportion: projected, the
    // triangle lies inside the viewport. It comes out whole (no vertex moved on screen or in
    // depth, the weights its own), where the absolute plane w ≥ kMinClipW cut it all away.
    const mr::ClipVolume volume = mr::make_clip_volume(mr::DepthConvention::reverse_z, 64, 64);
    const double w = 1e-40;
    const std::array<glm::dvec4, 3> p = {glm::dvec4(-0.5 * w, -0.5 * w, 0.25 * w, w),
                                         glm::dvec4(0.5 * w, -0.5 * w, 0.5 * w, w),
                                         glm::dvec4(0.0, 0.5 * w, 0.75 * w, 2 * w)};
    const std::array<std::uint8_t, 3> codes = {mr::outcode(p[0], volume), mr::outcode(p[1], volume),
                                               mr::outcode(p[2], volume)};
    ASSERT_NE(codes[0] & codes[1] & codes[2], 0);  // every vertex outside w ≥ kMinClipW
    mr::ClipPolygon polygon;
    ASSERT_EQ(mr::clip_triangle(p, codes, volume, polygon), mr::ClipOutcome::clipped);
    ASSERT_EQ(polygon.count, 3);
    for (int k = 0; k < 3; ++k) {
        const glm::dvec4 q = polygon.vertices[k].position;
        EXPECT_EQ(q.x / q.w, p[k].x / p[k].w) << k;
        EXPECT_EQ(q.y / q.w, p[k].y / p[k].w) << k;
        EXPECT_EQ(q.z / q.w, p[k].z / p[k].w) << k;
        EXPECT_EQ(polygon.vertices[k].weights[k], 1.0) << k;
        EXPECT_EQ(polygon.vertices[k].weights[(k + 1) % 3], 0.0) << k;
    }
    // Its w, all scaled by one power of two, keep their ratios (perspective-correct weights).
    EXPECT_EQ(polygon.vertices[2].position.w, 2 * polygon.vertices[0].position.w);
    EXPECT_GE(polygon.vertices[2].position.w, 1.0);
}

}  // namespace

namespace {

// Guard-band clipping computes the crossing point in long double: from endpoints 10^15 px away a
// double a + t·(b − a) lands up to ~0.1 px off the edge's line (double's ulp there is 1/8 px), and
// the clipped edge crossed the viewport that far from where it should (stress suite, case 3: 102
// samples of 16 such triangles wrong by more than 2/256 px). Every sample farther than 2/256 px
// from the exact edge must now agree with the exact coverage of the unclipped triangle.
TEST(Clip, EdgesOfTrianglesReaching1e15PixelsCrossTheViewportWhereTheyShould) {
    const int W = 256;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> pos(0.1, 0.9), angle(0.0, 6.283185307179586);
    mr::RasterizeSettings rs;
    rs.width = rs.height = W;
    rs.samples = 4;
    rs.pattern = mr::PatternKind::rotated;
    rs.threads = 2;
    const oracle::Pattern pattern = oracle::rotated_pattern();
    std::size_t wrong = 0, covered = 0;
    for (int k = 0; k < 16; ++k) {
        const glm::dvec2 q(pos(rng) * W, pos(rng) * W);
        const double a = angle(rng);
        const glm::dvec2 d(std::cos(a), std::sin(a)), n(-d.y, d.x);
        const glm::dvec2 p[3] = {q - 1e15 * d, q + 1e15 * d, q + 1e15 * n};
        std::vector<glm::dvec4> clip;
        std::array<oracle::Fixed2, 3> v;
        for (int i = 0; i < 3; ++i) {
            const glm::dvec4 c(2.0 * p[i].x / W - 1.0, 1.0 - 2.0 * p[i].y / W, 0.0, 1.0);
            clip.push_back(c);
            v[i] = {oracle::snap((c.x + 1.0) * (0.5 * W) * 256.0), oracle::snap((1.0 - c.y) * (0.5 * W) * 256.0)};
        }
        const mr::Visibility vis = mr::rasterize(clip, {glm::uvec3(0, 1, 2)}, rs);
        ASSERT_TRUE(same_offsets(to_oracle(vis.pattern), pattern));
        for (int y = 0; y < W; ++y)
            for (int x = 0; x < W; ++x)
                for (int s = 0; s < 4; ++s) {
                    const std::int64_t X = x * 256 + vis.pattern.x[s], Y = y * 256 + vis.pattern.y[s];
                    const bool want = oracle::covers(v, X, Y);
                    covered += want;
                    if ((vis.triangle_id[(std::size_t(y) * W + x) * 4 + s] == 0) == want) continue;
                    bool near_edge = false;
                    for (int dy = -2; dy <= 2; dy += 2)
                        for (int dx = -2; dx <= 2; dx += 2) near_edge = near_edge || oracle::covers(v, X + dx, Y + dy) != want;
                    wrong += !near_edge;
                }
    }
    EXPECT_GT(covered, 100000u);
    EXPECT_EQ(wrong, 0u);
}

}  // namespace

namespace {

// Triangles with a vertex 10^2…10^30 behind the eye. A crossing used to be computed from the
// lexicographically smaller endpoint; when that was the far vertex, the crossing's w was the
// difference of two numbers that large and came out 0 or negative (a fuzzed scene rendered NaN
// colours from it). Each clipped vertex must lie in the clip volume, have w > 0 and be the point
// its weights make of the triangle's vertices (the sum in long double, to 10^-9 of its terms).
TEST(Clip, CrossingsNextToVerticesFarBehindTheEyeLieOnTheClipVolumeAndTheirEdges) {
    const int W = 64, H = 48;
    std::mt19937_64 rng(1234);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int clipped = 0;
    for (const mr::DepthConvention c : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        SCOPED_TRACE(mr::to_string(c));
        const double far = c == mr::DepthConvention::reverse_z ? mr::kInfiniteFar : 100.0;
        const glm::dmat4 proj = mr::perspective(1.0, double(W) / H, 0.01, far, c);
        const mr::ClipVolume volume = mr::make_clip_volume(c, W, H);
        for (int k = 0; k < 3000; ++k) {
            // Two vertices 0.005…4 in front of the eye, one 10^2…10^30 behind it, in any order.
            std::array<glm::dvec4, 3> p;
            for (int i = 0; i < 3; ++i) {
                const double d = i < 2 ? 2.0 + 1.995 * u(rng) : -std::pow(10.0, 16.0 + 14.0 * u(rng));
                p[i] = proj * glm::dvec4(u(rng) * std::fabs(d), u(rng) * std::fabs(d), -d, 1.0);
            }
            std::rotate(p.begin(), p.begin() + static_cast<long>(rng() % 3), p.end());
            const std::array<std::uint8_t, 3> codes = {mr::outcode(p[0], volume), mr::outcode(p[1], volume),
                                                       mr::outcode(p[2], volume)};
            mr::ClipPolygon poly;
            if (mr::clip_triangle(p, codes, volume, poly) != mr::ClipOutcome::clipped) continue;
            ++clipped;
            for (int i = 0; i < poly.count; ++i) {
                const glm::dvec4& v = poly.vertices[i].position;
                const glm::dvec3& w = poly.vertices[i].weights;
                ASSERT_GT(v.w, 0.0) << "case " << k << " vertex " << i;
                const double size = std::fabs(v.x) + std::fabs(v.y) + std::fabs(v.z) + std::fabs(v.w);
                for (const mr::ClipPlane& plane : volume.planes)
                    ASSERT_GE(plane.distance(v), -1e-9 * size) << "case " << k << " vertex " << i;
                for (int j = 0; j < 4; ++j) {
                    long double sum = 0, terms = 0;
                    for (int m = 0; m < 3; ++m) {
                        sum += static_cast<long double>(w[m]) * p[m][j];
                        terms += std::fabs(static_cast<long double>(w[m]) * p[m][j]);
                    }
                    ASSERT_LE(std::fabs(static_cast<double>(sum - v[j])), 1e-9 * static_cast<double>(terms) + 1e-300)
                        << "case " << k << " vertex " << i << " coordinate " << j;
                }
            }
        }
    }
    EXPECT_GT(clipped, 5000);
}

// The fuzzed scene itself: a camera at the origin (to subnormal offsets) looking along the
// triangle's plane, so the triangle projects to a line, one vertex 10^20 behind the eye. It covers
// nothing; vertex colours came out NaN on 32 pixels of 64.
TEST(Clip, ATriangleInAPlaneThroughTheEyeReachingFarBehindItDrawsNothing) {
    const mr::Camera cam = mr::Camera::look_at_perspective({9.54368e-41, 7.20267e-43, 2.26001e-41},
                                                           {2.26001e-41, 2.26001e-41, 2.26001e-41}, {0.0, 1.0, 0.0},
                                                           1.0471975511965976, 1.0, 0.01);
    for (const double y : {-1e16, -1e20, -2.4e24, -1e30}) {
        mr::Mesh m;
        m.positions = {{-0.5f, -0.5f, 0.0f}, {0.5f, static_cast<float>(y), 0.0f}, {0.0f, 0.5f, 0.0f}};
        m.colors = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}};
        add_triangle(m, 0, 1, 2);
        mr::DrawState st = no_depth(mr::BlendMode::add);
        st.cull = mr::CullMode::none;
        const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), st)}, cam, settings(8, 8));
        EXPECT_EQ(r.stats.samples_covered, 0u) << "y = " << y;
        for (const float v : r.color.pixels) ASSERT_EQ(v, 0.0f) << "y = " << y;
    }
}

}  // namespace
