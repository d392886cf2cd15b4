// The vector paths of setup (triangle_setup_avx2.cpp) against the scalar functions (DESIGN.md
// §2.8: every SIMD path gives the scalar path's bits). classify_and_project_four against outcode
// and project_vertex: the same outcodes, and the same screen vertices, on vertices past every
// plane, non-finite ones, 1/w not normal and ties of the 1/256 px rounding. setup_four_triangles
// against setup_triangle, triangle by triangle: the same outcome, the same counts and, for each
// triangle set up, the same bits in every field, on random triangles from clip space through
// project_vertex, and screen vertices made by hand for the cases the arithmetic has to get right:
// areas past 2⁵³ (int64 → double rounding), coordinates at ±kMaxFixedCoordinate, every culling
// reason, invalid vertices, unsnapped triangles of no area (infinite or NaN depth shifts), signed
// zero depths and 1/w spanning the double range.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "mipraster/pipeline/clip.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace {

namespace mr = mipraster;

template <typename T>
bool same_bits(const T& a, const T& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// Every field setup_triangle writes, bit for bit; empty when they agree.
std::string field_difference(const mr::SetupTriangle& a, const mr::SetupTriangle& b) {
    if (!same_bits(a.edge_a, b.edge_a)) return "edge_a";
    if (!same_bits(a.edge_b, b.edge_b)) return "edge_b";
    if (!same_bits(a.edge_c, b.edge_c)) return "edge_c";
    if (!same_bits(a.bias, b.bias)) return "bias";
    if (a.min_x != b.min_x || a.min_y != b.min_y || a.max_x != b.max_x || a.max_y != b.max_y) return "bounds";
    if (!same_bits(a.inv_area2, b.inv_area2)) return "inv_area2";
    if (!same_bits(a.z0, b.z0)) return "z0";
    if (!same_bits(a.dz1, b.dz1)) return "dz1";
    if (!same_bits(a.dz2, b.dz2)) return "dz2";
    if (!same_bits(a.inv_w, b.inv_w)) return "inv_w";
    return "";
}

struct Tally {
    long groups = 0, triangles = 0, set_up = 0, culled = 0;
    long huge = 0;  // set up with |area2| > 2^53: int64 → double rounds
};

// Sets up the triangles in groups of `count` both ways and compares them.
void expect_fours_agree(const std::vector<std::array<mr::ScreenVertex, 3>>& triangles, const mr::Viewport& viewport,
                        mr::CullMode cull, int count, Tally& tally) {
    for (std::size_t first = 0; first < triangles.size(); first += static_cast<std::size_t>(count)) {
        const int n = static_cast<int>(std::min<std::size_t>(count, triangles.size() - first));
        const mr::ScreenVertex* v[4][3] = {};  // (past n: null, not read)
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k) v[i][k] = &triangles[first + static_cast<std::size_t>(i)][k];
        mr::SetupTriangle four[4];
        mr::SetupCounters four_counts;
        const int mask = mr::setup_four_triangles(v, n, viewport, cull, four, four_counts);
        mr::SetupCounters one_counts;
        for (int i = 0; i < n; ++i) {
            mr::SetupTriangle one;
            const bool set_up = mr::setup_triangle(triangles[first + static_cast<std::size_t>(i)], viewport, cull, one,
                                                   one_counts);
            ASSERT_EQ(set_up, (mask >> i & 1) != 0) << "triangle " << first + static_cast<std::size_t>(i);
            if (set_up) {
                ASSERT_EQ(field_difference(four[i], one), "") << "triangle " << first + static_cast<std::size_t>(i);
                ++tally.set_up;
                if (one.inv_area2 < 0x1p-53) ++tally.huge;
            } else {
                ++tally.culled;
            }
        }
        ASSERT_EQ(mask >> n, 0) << "lanes past the count";
        ASSERT_EQ(four_counts.dropped_nonfinite, one_counts.dropped_nonfinite);
        ASSERT_EQ(four_counts.culled_degenerate, one_counts.culled_degenerate);
        ASSERT_EQ(four_counts.culled_backface, one_counts.culled_backface);
        ASSERT_EQ(four_counts.culled_outside, one_counts.culled_outside);
        ASSERT_EQ(four_counts.culled_between_samples, one_counts.culled_between_samples);
        ++tally.groups;
        tally.triangles += n;
    }
}

void expect_fours_agree_everywhere(const std::vector<std::array<mr::ScreenVertex, 3>>& triangles,
                                   const mr::Viewport& viewport, Tally& tally) {
    for (const mr::CullMode cull : {mr::CullMode::none, mr::CullMode::back, mr::CullMode::front})
        for (int count = 1; count <= 4; ++count) expect_fours_agree(triangles, viewport, cull, count, tally);
}

TEST(TriangleSetupFours, RandomClipSpaceTrianglesGiveTheScalarBitsOutcomesAndCounts) {
    if (!mr::setup_in_fours()) GTEST_SKIP() << "no AVX2 on this CPU: setup_four_triangles has no vector path here";
    std::mt19937_64 rng(20261129);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), w_of(0.01, 50.0), log_scale(-12.0, 3.0);
    Tally tally;
    // (With the whole pixel for the samples, and the extents of a centre sample, the rotated
    // pattern and an uneven one.)
    const mr::Viewport viewports[] = {{1920, 1080, mr::DepthConvention::opengl},
                                      {1, 1, mr::DepthConvention::reverse_z},
                                      {333, 7, mr::DepthConvention::reverse_z},
                                      {mr::kMaxDimension, mr::kMaxDimension, mr::DepthConvention::opengl},
                                      {1920, 1080, mr::DepthConvention::opengl, 128, 128, 128, 128},
                                      {2, 3, mr::DepthConvention::reverse_z, 128, 128, 128, 128},
                                      {640, 480, mr::DepthConvention::reverse_z, 32, 224, 32, 224},
                                      {mr::kMaxDimension, 999, mr::DepthConvention::opengl, 3, 255, 0, 97}};
    for (const mr::Viewport& viewport : viewports) {
        std::vector<std::array<mr::ScreenVertex, 3>> triangles;
        for (int t = 0; t < 4000; ++t) {
            // Small triangles around a random centre (a mesh's), big ones, and slivers.
            const double size = std::pow(10.0, log_scale(rng));
            const glm::dvec4 centre(unit(rng) * 1.3, unit(rng) * 1.3, unit(rng), w_of(rng));
            std::array<mr::ScreenVertex, 3> v;
            for (int k = 0; k < 3; ++k) {
                glm::dvec4 p = centre;
                p.x += unit(rng) * size * p.w, p.y += unit(rng) * size * p.w, p.z += unit(rng) * 0.01 * p.w;
                if (t % 7 == 0) p.w *= std::pow(10.0, 3.0 * unit(rng));  // very different depths and 1/w
                v[k] = mr::project_vertex(p, viewport);
            }
            if (t % 11 == 0) v[2] = v[1];  // degenerate
            triangles.push_back(v);
        }
        expect_fours_agree_everywhere(triangles, viewport, tally);
    }
    // Most are set up; every reason to refuse one occurs.
    EXPECT_GT(tally.set_up, tally.triangles / 5) << tally.set_up << " of " << tally.triangles;
    EXPECT_GT(tally.culled, 1000);
}

TEST(TriangleSetupFours, ClassifyAndProjectFourGivesTheScalarOutcodesAndScreenVertices) {
    if (!mr::setup_in_fours()) GTEST_SKIP() << "no AVX2 on this CPU: classify_and_project_four has no vector path here";
    std::mt19937_64 rng(2911);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), exponent(-300.0, 300.0);
    std::uniform_int_distribution<int> tie(-600, 600);
    long inside = 0, projected = 0, refused = 0, nonfinite = 0;
    for (const auto& [width, height] : std::vector<std::pair<int, int>>{{2, 2}, {1920, 1080}, {7, 333},
                                                                       {mr::kMaxDimension, mr::kMaxDimension}})
        for (const mr::DepthConvention convention : {mr::DepthConvention::opengl, mr::DepthConvention::reverse_z}) {
            const mr::Viewport viewport{width, height, convention};
            const mr::ClipVolume volume = mr::make_clip_volume(convention, width, height);
            std::vector<glm::dvec4> p(8000);
            for (std::size_t i = 0; i < p.size(); ++i) {
                double w = std::pow(10.0, unit(rng) * 2.0);
                if (i % 23 == 0) w = std::pow(10.0, exponent(rng));  // 1/w subnormal, huge or beyond
                if (i % 29 == 0) w = -w;
                if (i % 31 == 0) w = mr::kMinClipW;  // on the w plane
                glm::dvec4 q(unit(rng) * 1.2 * w, unit(rng) * 1.2 * w, unit(rng) * w, w);
                if (i % 5 == 0) q.z = convention == mr::DepthConvention::opengl ? -w : 0.0;  // on the near/far plane
                if (i % 3 == 0) q.x *= std::pow(10.0, 7.0 * std::abs(unit(rng)));  // out to past the guard band
                if (i % 4 == 0) q.y *= std::pow(10.0, 7.0 * std::abs(unit(rng)));
                if (i % 7 == 0 && width == 2)  // on a half 1/256 px: nearbyint's ties go to even
                    q = glm::dvec4((tie(rng) + 0.5) / 256.0, (tie(rng) + 0.5) / 256.0, 0.5, 1.0);
                if (i % 41 == 0) q = glm::dvec4(0.0, 0.0, 0.0, i % 2 ? 1e308 : 4e307);  // 1/w not normal, or just
                if (i % 37 == 0) q[static_cast<int>(i / 37 % 4)] = i % 2 ? std::nan("") : -INFINITY;
                p[i] = q;
            }
            std::vector<std::uint8_t> codes(p.size(), 0xFF);
            std::vector<mr::ScreenVertex> screen(p.size(), mr::ScreenVertex{});
            for (std::size_t i = 0; i < p.size(); i += 4)
                mr::classify_and_project_four(&p[i], volume, viewport, &codes[i], &screen[i]);
            for (std::size_t i = 0; i < p.size(); ++i) {
                const bool finite = std::isfinite(p[i].x) && std::isfinite(p[i].y) && std::isfinite(p[i].z) &&
                                    std::isfinite(p[i].w);
                const std::uint8_t expected = finite ? mr::outcode(p[i], volume) : mr::kNonFinite;
                ASSERT_EQ(codes[i], expected) << "vertex " << i;
                nonfinite += !finite;
                if (expected != 0) {
                    ASSERT_TRUE(same_bits(screen[i], mr::ScreenVertex{})) << "written outside the volume: " << i;
                    continue;
                }
                ++inside;
                const mr::ScreenVertex v = mr::project_vertex(p[i], viewport);
                ASSERT_TRUE(same_bits(screen[i], v)) << "vertex " << i << " (" << p[i].x << ", " << p[i].y << ", "
                                                     << p[i].z << ", " << p[i].w << ")";
                (v.valid() ? projected : refused) += 1;
            }
        }
    EXPECT_GT(inside, 10000);
    EXPECT_GT(projected, 10000);
    EXPECT_GT(refused, 20);  // inside the volume, but 1/w not normal
    EXPECT_GT(nonfinite, 500);
}

// A screen vertex made by hand (x, y in 1/256 px).
mr::ScreenVertex vertex(std::int32_t x, std::int32_t y, double depth, double inv_w, float snap_x = 0.0f,
                        float snap_y = 0.0f) {
    mr::ScreenVertex v{};
    v.x = x, v.y = y, v.depth = depth, v.inv_w = inv_w, v.snap_x = snap_x, v.snap_y = snap_y;
    return v;
}

TEST(TriangleSetupFours, ExtremeVerticesGiveTheScalarBitsOutcomesAndCounts) {
    if (!mr::setup_in_fours()) GTEST_SKIP() << "no AVX2 on this CPU: setup_four_triangles has no vector path here";
    const auto M = static_cast<std::int32_t>(mr::kMaxFixedCoordinate);
    const mr::Viewport viewport{mr::kMaxDimension, mr::kMaxDimension, mr::DepthConvention::opengl};
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<std::int32_t> coordinate(-M, M), near_edge(M - 4096, M);
    std::uniform_real_distribution<float> snap(-0.5f, 0.5f);
    std::uniform_real_distribution<double> depth(0.0, 1.0), exponent(-300.0, 300.0);
    std::vector<std::array<mr::ScreenVertex, 3>> triangles;
    for (int t = 0; t < 6000; ++t) {
        std::array<mr::ScreenVertex, 3> v;
        for (int k = 0; k < 3; ++k) {
            std::int32_t x = coordinate(rng), y = coordinate(rng);
            if (t % 3 == 0) {  // at the coordinate limits: areas up to 2^60, past 2^53
                x = (k == 1 ? -1 : 1) * near_edge(rng);
                y = (k == 2 ? -1 : 1) * near_edge(rng);
            }
            if (t % 5 == 0) x = x / 256 * 256, y = y / 256 * 256;  // on pixel corners
            double inv_w = std::pow(10.0, exponent(rng) * (t % 4 == 0 ? 1.0 : 0.01));
            if (t % 13 == 0 && k == 1) inv_w = 0.0;  // an invalid vertex
            double z = depth(rng);
            if (t % 9 == 0) z = (k == 0 ? -0.0 : 0.0);  // signed zeros: the depth range is ±0
            const bool snapped_exactly = t % 6 == 0;
            v[k] = vertex(x, y, z, inv_w, snapped_exactly ? 0.0f : snap(rng), snapped_exactly ? 0.0f : snap(rng));
        }
        if (t % 17 == 0) {  // unsnapped on a line (no area), snapped not: NaN or infinite depth shifts
            const std::int32_t x = 25600 + t, y = 12800 - t;  // (offsets below in 1/256 px)
            v[0] = vertex(x, y, 0.25, 1.0);
            if (t % 34 == 0) {  // unsnapped (0, 0), (3, 1), (4.5, 1.5): the last snaps to (4, 2), shift +∞
                v[1] = vertex(x + 3, y + 1, 0.5, 1.0);
                v[2] = vertex(x + 4, y + 2, 0.75, 1.0, -0.5f, 0.5f);
            } else {  // unsnapped (0, 0), (2, 1), (5, 2.5): the last snaps to (5, 2), shifts ∞ · 0 = NaN
                v[1] = vertex(x + 2, y + 1, 0.5, 1.0);
                v[2] = vertex(x + 5, y + 2, 0.75, 1.0, 0.0f, -0.5f);
            }
        }
        if (t % 19 == 0)  // (nearly) collinear
            v[2] = vertex(v[0].x / 2 + v[1].x / 2, v[0].y / 2 + v[1].y / 2, 0.5, 1.0);
        triangles.push_back(v);
    }
    // Outside the viewport on every side, and bounds clamped to it.
    for (const auto& [dx, dy] : std::vector<std::pair<int, int>>{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        const std::int32_t x0 = dx < 0 ? -5000 : dx > 0 ? 256 * (mr::kMaxDimension + 3) : 256;
        const std::int32_t y0 = dy < 0 ? -5000 : dy > 0 ? 256 * (mr::kMaxDimension + 3) : 256;
        const mr::ScreenVertex a = vertex(x0, y0, 0.5, 1.0), b = vertex(x0 + 1000, y0, 0.5, 1.0),
                               c = vertex(x0, y0 + 1000, 0.5, 1.0);
        triangles.push_back({a, b, c});
        triangles.push_back({a, c, b});
    }
    Tally tally;
    expect_fours_agree_everywhere(triangles, viewport, tally);
    EXPECT_GT(tally.set_up, 1000);
    EXPECT_GT(tally.huge, 1000);
    EXPECT_GT(tally.culled, 1000);
}

}  // namespace
