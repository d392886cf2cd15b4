// The primitive layer (renderer.hpp rasterize): clip-space triangles in, per-sample triangle id,
// perspective-correct barycentrics and depth out. Checked against the exact top-left coverage
// oracle and against an exact clip-space solve for the barycentrics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "mipraster/pipeline/renderer.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;

mr::RasterizeSettings raster_settings(int W, int H, int S, mr::PatternKind kind = mr::PatternKind::automatic) {
    mr::RasterizeSettings s;
    s.width = W;
    s.height = H;
    s.samples = S;
    s.pattern = kind;
    s.threads = 2;
    return s;
}

oracle::Pattern to_oracle(const mr::SamplePattern& p) { return oracle::Pattern{p.x, p.y}; }

std::array<oracle::Fixed2, 3> snapped(const std::vector<glm::dvec4>& clip, const glm::uvec3& t, int W, int H) {
    std::array<oracle::Fixed2, 3> v;
    for (int i = 0; i < 3; ++i) {
        const glm::dvec4& p = clip[t[i]];
        v[i] = oracle::snap_ndc(p.x / p.w, p.y / p.w, W, H);
    }
    return v;
}

/// Weights (β0, β1, β2) of the clip-space vertices whose combination projects to the NDC point
/// (X, Y): Σβ_i (x_i − X·w_i) = 0, Σβ_i (y_i − Y·w_i) = 0, Σβ_i = 1 (Cramer's rule, double).
glm::dvec3 clip_space_weights(const std::array<glm::dvec4, 3>& p, double X, double Y) {
    double m[3][3];
    for (int i = 0; i < 3; ++i) {
        m[0][i] = p[i].x - X * p[i].w;
        m[1][i] = p[i].y - Y * p[i].w;
        m[2][i] = 1.0;
    }
    auto det = [](const double a[3][3]) {
        return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    const double d = det(m);
    glm::dvec3 beta;
    for (int c = 0; c < 3; ++c) {
        double mc[3][3];
        std::memcpy(mc, m, sizeof m);
        for (int r = 0; r < 3; ++r) mc[r][c] = r == 2 ? 1.0 : 0.0;
        beta[c] = det(mc) / d;
    }
    return beta;
}

double sample_ndc_x(const oracle::Fixed2& q, int W) { return q.x / 256.0 / W * 2.0 - 1.0; }
double sample_ndc_y(const oracle::Fixed2& q, int H) { return 1.0 - q.y / 256.0 / H * 2.0; }

TEST(Rasterize, TriangleIdsMatchTheExactCoverageOracleAndTheNearestTriangleWins) {
    const int W = 64, H = 48;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.2, 1.2);
    std::vector<glm::dvec4> clip;
    std::vector<glm::uvec3> tris;
    // 150 overlapping triangles, each at its own constant depth, so the nearest is unambiguous.
    for (std::uint32_t t = 0; t < 150; ++t) {
        const double z = -0.95 + 1.9 * ((t * 37) % 150) / 150.0;
        for (int i = 0; i < 3; ++i) clip.push_back({u(rng), u(rng), z, 1.0});
        tris.push_back({3 * t, 3 * t + 1, 3 * t + 2});
    }
    for (int S : {1, 4, 16}) {
        SCOPED_TRACE("samples " + std::to_string(S));
        const mr::Visibility v = mr::rasterize(clip, tris, raster_settings(W, H, S));
        ASSERT_EQ(v.triangle_id.size(), std::size_t(W) * H * S);
        const oracle::Pattern p = to_oracle(v.pattern);
        std::size_t covered = 0, bad = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                for (int s = 0; s < S; ++s) {
                    const oracle::Fixed2 q = oracle::sample_position(x, y, p, s);
                    int want = -1;
                    for (std::size_t t = 0; t < tris.size(); ++t)
                        if (oracle::covers(snapped(clip, tris[t], W, H), q.x, q.y) &&
                            (want < 0 || clip[tris[t][0]].z < clip[tris[want][0]].z))
                            want = static_cast<int>(t);
                    const std::size_t i = (std::size_t(y) * W + x) * S + s;
                    covered += want >= 0;
                    const float want_depth = want < 0 ? 1.0f : static_cast<float>(0.5 * clip[tris[want][0]].z + 0.5);
                    if ((v.triangle_id[i] != want || std::fabs(v.depth[i] - want_depth) > 1e-7f) && ++bad < 6)
                        ADD_FAILURE() << "pixel (" << x << ", " << y << ") sample " << s << ": triangle "
                                      << v.triangle_id[i] << " depth " << v.depth[i] << ", oracle " << want << " depth "
                                      << want_depth;
                }
        EXPECT_EQ(bad, 0u);
        EXPECT_GT(covered, std::size_t(W) * H * S / 2);
        EXPECT_EQ(v.stats.samples_covered >= covered, true);
    }
}

/// Renders each triangle alone and compares every covered sample's barycentrics with the exact
/// clip-space solve. The rasterized triangle has snapped vertices, so the weights are those of a
/// point moved by at most √2/512 px: the tolerance is that times the weights' screen gradient.
void expect_barycentrics_match(const std::array<glm::dvec4, 3>& p, int W, int H, int S, std::size_t& checked) {
    const std::vector<glm::dvec4> clip(p.begin(), p.end());
    const std::vector<glm::uvec3> tris = {{0, 1, 2}};
    const mr::Visibility v = mr::rasterize(clip, tris, raster_settings(W, H, S));
    const oracle::Pattern pat = to_oracle(v.pattern);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int s = 0; s < S; ++s) {
                const std::size_t i = (std::size_t(y) * W + x) * S + s;
                if (v.triangle_id[i] < 0) continue;
                const oracle::Fixed2 q = oracle::sample_position(x, y, pat, s);
                const double X = sample_ndc_x(q, W), Y = sample_ndc_y(q, H);
                const glm::dvec3 b = clip_space_weights(p, X, Y);
                const double e = 1.0 / 64;  // px, by central differences
                const glm::dvec3 gx = (clip_space_weights(p, X + 2 * e / W, Y) - clip_space_weights(p, X - 2 * e / W, Y)) / (2 * e);
                const glm::dvec3 gy = (clip_space_weights(p, X, Y - 2 * e / H) - clip_space_weights(p, X, Y + 2 * e / H)) / (2 * e);
                for (int k = 1; k <= 2; ++k) {
                    const double tol = std::hypot(gx[k], gy[k]) * oracle::kSnapBandPx * 1.01 + 2e-6;
                    const float got = v.barycentrics[2 * i + (k - 1)];
                    EXPECT_NEAR(got, b[k], tol) << "pixel (" << x << ", " << y << ") sample " << s << " weight " << k;
                    // Inside the triangle every weight is in [0, 1] (up to the same tolerance).
                    EXPECT_GE(got, -tol);
                    EXPECT_LE(got, 1.0 + tol);
                }
                ++checked;
            }
}

TEST(Rasterize, BarycentricsArePerspectiveCorrectAgainstAnExactClipSpaceSolve) {
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> u(-0.9, 0.9), w(0.3, 6.0);
    std::size_t checked = 0;
    for (int t = 0; t < 40; ++t) {
        std::array<glm::dvec4, 3> p;
        for (auto& v : p) {
            const double wi = w(rng);  // different w per vertex: strongly non-affine
            v = {u(rng) * wi, u(rng) * wi, 0.2 * wi, wi};
        }
        expect_barycentrics_match(p, 40, 32, t % 2 ? 4 : 1, checked);
    }
    EXPECT_GT(checked, 5000u);
}

TEST(Rasterize, ClippedTrianglesReportTheWeightsOfTheSubmittedVertices) {
    // One vertex behind the eye (w < 0), one behind the near plane: only the part with z ≥ −w
    // draws, and its weights still refer to the three submitted vertices.
    std::size_t checked = 0;
    const std::array<glm::dvec4, 3> a = {glm::dvec4(-0.5, -0.5, 0.5, 1.0), glm::dvec4(0.6, -0.4, 1.0, 2.0),
                                         glm::dvec4(0.1, 0.8, 0.5, -1.0)};
    expect_barycentrics_match(a, 48, 48, 4, checked);
    const std::array<glm::dvec4, 3> b = {glm::dvec4(-2.0, -1.0, 2.5, 3.0), glm::dvec4(1.5, -1.0, -0.9, 0.8),
                                         glm::dvec4(0.0, 1.0, -1.2, 1.0)};
    expect_barycentrics_match(b, 48, 48, 1, checked);
    EXPECT_GT(checked, 300u);
    const mr::Visibility v = mr::rasterize({a.begin(), a.end()}, {{0, 1, 2}}, raster_settings(48, 48, 4));
    EXPECT_EQ(v.stats.triangles_clipped, 1u);
}

TEST(Rasterize, ThreadCountsGiveBitIdenticalOutput) {
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> u(-1.5, 1.5), w(0.5, 3.0);
    std::vector<glm::dvec4> clip;
    std::vector<glm::uvec3> tris;
    for (std::uint32_t t = 0; t < 20000; ++t) {
        for (int i = 0; i < 3; ++i) {
            const double wi = w(rng);
            clip.push_back({u(rng) * wi, u(rng) * wi, u(rng) * wi * 0.6, wi});
        }
        tris.push_back({3 * t, 3 * t + 1, 3 * t + 2});
    }
    auto s = raster_settings(96, 64, 4);
    s.threads = 1;
    const mr::Visibility one = mr::rasterize(clip, tris, s);
    for (int threads : {2, 4}) {
        s.threads = threads;
        const mr::Visibility many = mr::rasterize(clip, tris, s);
        EXPECT_EQ(many.triangle_id, one.triangle_id) << threads;
        EXPECT_EQ(0, std::memcmp(many.barycentrics.data(), one.barycentrics.data(), one.barycentrics.size() * 4)) << threads;
        EXPECT_EQ(0, std::memcmp(many.depth.data(), one.depth.data(), one.depth.size() * 4)) << threads;
    }
}

TEST(Rasterize, BadInputThrowsNamingTheElement) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    auto message = [](const std::vector<glm::dvec4>& clip, const std::vector<glm::uvec3>& tris, mr::RasterizeSettings s) {
        try {
            mr::rasterize(clip, tris, s);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::vector<glm::dvec4> ok = {{0, 0, 0, 1}, {1, 0, 0, 1}, {0, 1, 0, 1}};
    EXPECT_NE(message({{0, 0, 0, 1}, {1, 0, 0, nan}, {0, 1, 0, 1}}, {{0, 1, 2}}, raster_settings(8, 8, 1))
                  .find("clip_positions[1][3]"),
              std::string::npos);
    EXPECT_NE(message(ok, {{0, 1, 3}}, raster_settings(8, 8, 1)).find("triangles[0][2] = 3"), std::string::npos);
    EXPECT_NE(message(ok, {{0, 1, 2}}, raster_settings(0, 8, 1)).find("width"), std::string::npos);
    EXPECT_NE(message(ok, {{0, 1, 2}}, raster_settings(8, 8, 65)).find("samples"), std::string::npos);
    // Nothing to draw is not an error: every sample is empty.
    const mr::Visibility empty = mr::rasterize({}, {}, raster_settings(4, 4, 4));
    EXPECT_EQ(empty.triangle_id, std::vector<std::int32_t>(64, -1));
    EXPECT_EQ(empty.depth, std::vector<float>(64, 1.0f));
}

}  // namespace
