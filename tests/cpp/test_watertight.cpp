// Watertight coverage (DESIGN.md §2.1): every sample of a mesh with shared edges is covered exactly
// once. Each mesh is drawn with additive white (no depth test), so a sample's red value is the
// number of triangles that covered it; it must equal, sample for sample, the count of the exact
// top-left oracle (oracle.hpp) on the snapped vertices, and the oracle itself never counts a
// sample twice for these conforming meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "helpers.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

constexpr double kPi = 3.14159265358979323846;

/// What a pattern should be, for the offsets the render reports.
enum class Expect { center, grid4, rotated, stratified4x4 };

void check_pattern(const oracle::Pattern& got, Expect expect) {
    switch (expect) {
        case Expect::center: ASSERT_TRUE(same_offsets(got, oracle::center_pattern())); break;
        case Expect::grid4: ASSERT_TRUE(same_offsets(got, oracle::grid_pattern(4))); break;
        case Expect::rotated: ASSERT_TRUE(same_offsets(got, oracle::rotated_pattern())); break;
        case Expect::stratified4x4: {
            // One sample in each of the 4×4 strata of 64×64 units.
            ASSERT_EQ(got.count(), 16);
            std::vector<int> per_stratum(16, 0);
            for (int s = 0; s < 16; ++s) {
                ASSERT_GE(got.x[s], 0);
                ASSERT_LT(got.x[s], 256);
                ASSERT_GE(got.y[s], 0);
                ASSERT_LT(got.y[s], 256);
                ++per_stratum[(got.y[s] / 64) * 4 + got.x[s] / 64];
            }
            for (int n : per_stratum) ASSERT_EQ(n, 1);
            break;
        }
    }
}

/// Renders `mesh` (positions in 1/256 px units) additively and compares every sample's count with
/// the oracle. With `full`, every sample of the viewport must be covered exactly once.
void expect_watertight(const mr::Mesh& mesh, int W, int H, int S, mr::PatternKind kind, Expect expect, bool full,
                       std::uint64_t pattern_seed = 0) {
    auto s = settings(W, H, S, kind);
    s.pattern_seed = pattern_seed;
    const mr::RenderResult r =
        mr::render({make_draw(mesh, fixed_to_ndc(W, H), no_depth(mr::BlendMode::add))}, identity_camera(), s);
    ASSERT_EQ(r.framebuffer.samples, S);
    const oracle::Pattern pattern = to_oracle(r.pattern);
    check_pattern(pattern, expect);
    if (::testing::Test::HasFatalFailure()) return;

    std::vector<int> counts(static_cast<std::size_t>(W) * H * S, 0);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        oracle::accumulate_coverage(snapped_triangle(mesh, t), W, H, pattern, counts);
    std::size_t covered = 0, twice = 0, uncovered = 0;
    for (int c : counts) {
        covered += c > 0;
        twice += c > 1;
        uncovered += c == 0;
    }
    // The meshes are conforming: the oracle counts no sample twice (a check of the test mesh).
    ASSERT_EQ(twice, 0u) << "test mesh is not conforming";
    if (full) {
        ASSERT_EQ(uncovered, 0u) << "test mesh does not cover the viewport";
    }
    ASSERT_GT(covered, counts.size() / 10) << "test mesh covers too little to be a test";

    const std::vector<float> expected(counts.begin(), counts.end());
    EXPECT_TRUE(samples_equal(r.framebuffer, expected, 0, "red = coverage count"));
    EXPECT_TRUE(samples_equal(r.framebuffer, expected, 3, "alpha = coverage count"));
    EXPECT_EQ(r.stats.samples_covered, covered);
}

/// A fan of n triangles around `centre` (1/256 px units) with rim radius `radius` px; odd
/// triangles are wound the other way (coverage must not depend on winding).
mr::Mesh fan_mesh(glm::dvec2 centre, double radius, int n) {
    mr::Mesh m;
    m.positions.push_back(glm::vec3(static_cast<float>(centre.x), static_cast<float>(centre.y), 0.0f));
    for (int k = 0; k < n; ++k) {
        const double a = 2.0 * kPi * k / n;
        m.positions.push_back(glm::vec3(static_cast<float>(centre.x + radius * 256.0 * std::cos(a)),
                                        static_cast<float>(centre.y + radius * 256.0 * std::sin(a)), 0.0f));
    }
    for (int k = 0; k < n; ++k) {
        const std::uint32_t a = 1 + k, b = 1 + (k + 1) % n;
        if (k % 2) {
            add_triangle(m, 0, b, a);
        } else {
            add_triangle(m, 0, a, b);
        }
    }
    return m;
}

struct GridSpec {
    int nx = 0, ny = 0;        ///< quads
    double x0 = 0, y0 = 0;     ///< top-left corner, 1/256 px units
    double x1 = 0, y1 = 0;     ///< bottom-right corner
    double jitter = 0.2;       ///< fraction of a cell, each axis
    bool main_diagonal = true; ///< split quads along (i,j)–(i+1,j+1), else (i+1,j)–(i,j+1)
    bool random_diagonals = false;
    bool integer_positions = false;  ///< vertices on the 1/256 grid
    std::uint64_t seed = 1;
};

/// A jittered grid of quads, each split into two triangles with random winding; shared vertices.
/// About one vertex in eight is moved exactly onto a sample position of `on_sample` when that is
/// a small move.
mr::Mesh grid_mesh(const GridSpec& g, const oracle::Pattern& on_sample) {
    std::mt19937_64 rng(g.seed);
    std::uniform_real_distribution<double> jit(-g.jitter, g.jitter);
    std::uniform_int_distribution<int> pick_sample(0, on_sample.count() - 1);
    const double cx = (g.x1 - g.x0) / g.nx, cy = (g.y1 - g.y0) / g.ny;
    mr::Mesh m;
    for (int j = 0; j <= g.ny; ++j)
        for (int i = 0; i <= g.nx; ++i) {
            double x = g.x0 + (i + jit(rng)) * cx, y = g.y0 + (j + jit(rng)) * cy;
            if (g.integer_positions) {
                x = std::round(x);
                y = std::round(y);
            }
            if (rng() % 8 == 0) {
                const int s = pick_sample(rng);
                const double sx = std::floor(x / 256.0) * 256.0 + on_sample.x[s];
                const double sy = std::floor(y / 256.0) * 256.0 + on_sample.y[s];
                if (std::fabs(sx - x) < 0.15 * cx && std::fabs(sy - y) < 0.15 * cy) {
                    x = sx;
                    y = sy;
                }
            }
            m.positions.push_back(glm::vec3(static_cast<float>(x), static_cast<float>(y), 0.0f));
        }
    auto idx = [&](int i, int j) { return static_cast<std::uint32_t>(j * (g.nx + 1) + i); };
    for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) {
            const std::uint32_t a = idx(i, j), b = idx(i + 1, j), c = idx(i + 1, j + 1), d = idx(i, j + 1);
            const bool main = g.random_diagonals ? (rng() & 1) : g.main_diagonal;
            const std::uint32_t t[2][3] = {{a, b, main ? c : d}, {main ? a : b, c, d}};
            for (const auto& tri : t) {
                if (rng() & 1) add_triangle(m, tri[0], tri[1], tri[2]);
                else add_triangle(m, tri[0], tri[2], tri[1]);
            }
        }
    return m;
}

/// Every snapped triangle of a jittered grid must keep a non-zero area (else the mesh folded and
/// the test mesh is invalid).
void assert_no_degenerate(const mr::Mesh& m) {
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        ASSERT_FALSE(oracle::is_degenerate(snapped_triangle(m, t))) << "test mesh triangle " << t << " folded";
}

// --- fans -------------------------------------------------------------------------------------

TEST(Watertight, FanOf1000TrianglesCentredOnAPixelCentreCoversEachSampleOnceAt1Sample) {
    const int W = 128, H = 128;
    // Centre of pixel (64, 64): (64.5 px, 64.5 px) = 16512 units, exactly the S = 1 sample.
    const mr::Mesh fan = fan_mesh({64 * 256 + 128, 64 * 256 + 128}, 50.0, 1000);
    ASSERT_EQ(fan.triangles.size(), 1000u);
    expect_watertight(fan, W, H, 1, mr::PatternKind::center, Expect::center, false);

    // The centre sample itself: all 1000 triangles meet there and exactly one owns it.
    int owners = 0;
    for (std::size_t t = 0; t < fan.triangles.size(); ++t)
        owners += oracle::covers(snapped_triangle(fan, t), 64 * 256 + 128, 64 * 256 + 128);
    EXPECT_EQ(owners, 1);
}

TEST(Watertight, FanOf1000TrianglesCentredOnAPixelCentreCoversEachSampleOnceAt16Samples) {
    const mr::Mesh fan = fan_mesh({64 * 256 + 128, 64 * 256 + 128}, 50.0, 1000);
    expect_watertight(fan, 128, 128, 16, mr::PatternKind::grid, Expect::grid4, false);
}

TEST(Watertight, FanCentredOnAGridSampleCoversEachSampleOnceAt16Samples) {
    // (64 + 32/256, 64 + 96/256) px is sample (a=0, b=1) of the 4×4 grid of pixel (64, 64).
    const mr::Mesh fan = fan_mesh({64 * 256 + 32, 64 * 256 + 96}, 50.0, 1000);
    expect_watertight(fan, 128, 128, 16, mr::PatternKind::grid, Expect::grid4, false);
}

// --- jittered grids past the viewport ----------------------------------------------------------

GridSpec overscan_grid(int W, int H, bool main_diagonal) {
    GridSpec g;
    g.nx = g.ny = 256;
    g.x0 = -0.1 * W * 256;
    g.y0 = -0.1 * H * 256;
    g.x1 = 1.1 * W * 256;
    g.y1 = 1.1 * H * 256;
    g.main_diagonal = main_diagonal;
    g.seed = main_diagonal ? 11 : 12;
    return g;
}

TEST(Watertight, GridOf256x256QuadsMainDiagonalCoversEverySampleOnceAt1Sample) {
    const mr::Mesh m = grid_mesh(overscan_grid(512, 256, true), oracle::center_pattern());
    assert_no_degenerate(m);
    expect_watertight(m, 512, 256, 1, mr::PatternKind::center, Expect::center, true);
}

TEST(Watertight, GridOf256x256QuadsMainDiagonalCoversEverySampleOnceAt16Samples) {
    const mr::Mesh m = grid_mesh(overscan_grid(512, 256, true), oracle::grid_pattern(4));
    assert_no_degenerate(m);
    expect_watertight(m, 512, 256, 16, mr::PatternKind::grid, Expect::grid4, true);
}

TEST(Watertight, GridOf256x256QuadsOtherDiagonalCoversEverySampleOnceAt1Sample) {
    const mr::Mesh m = grid_mesh(overscan_grid(512, 256, false), oracle::center_pattern());
    assert_no_degenerate(m);
    expect_watertight(m, 512, 256, 1, mr::PatternKind::center, Expect::center, true);
}

TEST(Watertight, GridOf256x256QuadsOtherDiagonalCoversEverySampleOnceAt16Samples) {
    const mr::Mesh m = grid_mesh(overscan_grid(512, 256, false), oracle::grid_pattern(4));
    assert_no_degenerate(m);
    expect_watertight(m, 512, 256, 16, mr::PatternKind::grid, Expect::grid4, true);
}

TEST(Watertight, GridCoversEverySampleOnceWithTheRotated4xPattern) {
    const mr::Mesh m = grid_mesh(overscan_grid(512, 256, true), oracle::rotated_pattern());
    assert_no_degenerate(m);
    expect_watertight(m, 512, 256, 4, mr::PatternKind::rotated, Expect::rotated, true);
}

TEST(Watertight, GridCoversEverySampleOnceWithAStratifiedPattern) {
    const mr::Mesh m = grid_mesh(overscan_grid(512, 256, false), oracle::grid_pattern(4));
    assert_no_degenerate(m);
    expect_watertight(m, 512, 256, 16, mr::PatternKind::stratified, Expect::stratified4x4, true, 0x5eed);
}

// --- random conforming mesh on the 1/256 grid --------------------------------------------------

GridSpec random_mesh_spec(std::uint64_t seed) {
    GridSpec g;
    g.nx = 75;
    g.ny = 70;  // 10,500 triangles
    g.x0 = 20.3 * 256;
    g.y0 = 17.7 * 256;
    g.x1 = 236.1 * 256;
    g.y1 = 240.4 * 256;
    g.random_diagonals = true;
    g.integer_positions = true;
    g.seed = seed;
    return g;
}

TEST(Watertight, RandomConformingMeshOf10500TrianglesCoversEachSampleOnceAt1Sample) {
    const mr::Mesh m = grid_mesh(random_mesh_spec(21), oracle::center_pattern());
    ASSERT_GE(m.triangles.size(), 10000u);
    assert_no_degenerate(m);
    expect_watertight(m, 256, 256, 1, mr::PatternKind::center, Expect::center, false);
}

TEST(Watertight, RandomConformingMeshOf10500TrianglesCoversEachSampleOnceAt16Samples) {
    const mr::Mesh m = grid_mesh(random_mesh_spec(22), oracle::grid_pattern(4));
    ASSERT_GE(m.triangles.size(), 10000u);
    assert_no_degenerate(m);
    expect_watertight(m, 256, 256, 16, mr::PatternKind::grid, Expect::grid4, false);
}

}  // namespace
