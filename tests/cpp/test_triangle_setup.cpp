// Triangle setup (DESIGN.md §2.1): snapping to 1/256 px with round-half-even, the top-left fill
// rule on exact integer edge functions, whole-pixel shift invariance up to the largest viewport,
// degenerate triangles and face culling. Expected coverage comes from oracle.hpp and from the
// rule's statement written out per case.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "helpers.hpp"
#include "mipraster/pipeline/interpolate.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;
using oracle::Fixed2;

mr::Mesh mesh_of(const std::vector<glm::vec3>& positions) {
    mr::Mesh m;
    m.positions = positions;
    for (std::uint32_t i = 0; i + 2 < positions.size(); i += 3) add_triangle(m, i, i + 1, i + 2);
    return m;
}

glm::vec3 fx(double x, double y) { return glm::vec3(static_cast<float>(x), static_cast<float>(y), 0.0f); }

/// Oracle coverage counts of all triangles of a mesh given in 1/256 px units.
std::vector<int> oracle_counts(const mr::Mesh& m, int W, int H, const oracle::Pattern& p) {
    std::vector<int> counts(static_cast<std::size_t>(W) * H * p.count(), 0);
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        oracle::accumulate_coverage(snapped_triangle(m, t), W, H, p, counts);
    return counts;
}

mr::RenderResult render_fixed(const mr::Mesh& m, int W, int H, int S, mr::PatternKind kind,
                              mr::CullMode cull = mr::CullMode::none) {
    mr::DrawState st = no_depth(mr::BlendMode::add);
    st.cull = cull;
    return mr::render({make_draw(m, fixed_to_ndc(W, H), st)}, identity_camera(), settings(W, H, S, kind));
}

// ---------------------------------------------------------------------------------------------
// The top-left rule, edge by edge
// ---------------------------------------------------------------------------------------------

struct EdgeCase {
    int dx, dy;  ///< direction of the edge (screen, y down)
    int nx, ny;  ///< normal pointing into the triangle
    bool owns_samples_on_it;  ///< the rule's statement for this edge
    const char* name;
};

// Top edge: horizontal with the interior below (larger y). Left edge: interior on its +x side.
const EdgeCase kEdgeCases[8] = {
    {1, 0, 0, 1, true, "horizontal, interior below: top edge"},
    {1, 0, 0, -1, false, "horizontal, interior above: bottom edge"},
    {0, 1, 1, 0, true, "vertical, interior right: left edge"},
    {0, 1, -1, 0, false, "vertical, interior left: right edge"},
    {1, 1, 1, -1, true, "diagonal down-right, interior up-right: left edge"},
    {1, 1, -1, 1, false, "diagonal down-right, interior down-left: right edge"},
    {1, -1, 1, 1, true, "diagonal up-right, interior down-right: left edge"},
    {1, -1, -1, -1, false, "diagonal up-right, interior up-left: right edge"},
};

TEST(TriangleSetup, TopLeftRuleForAllEightEdgeDirectionsOnInsideAndOutsideTheEdgeBothWindings) {
    const int W = 16, H = 16;
    const Fixed2 P{8 * 256 + 128, 8 * 256 + 128};  // the centre sample of pixel (8, 8)
    int checked = 0;
    for (const EdgeCase& ec : kEdgeCases) {
        for (int winding = 0; winding < 2; ++winding) {
            for (int sy = -1; sy <= 1; ++sy) {
                for (int sx = -1; sx <= 1; ++sx) {
                    // The edge A–B passes through P; C lies on the interior side. The whole triangle
                    // moves by (sx, sy) units, so P sits at −(sx, sy) relative to the edge.
                    const double ax = P.x - 768.0 * ec.dx + sx, ay = P.y - 768.0 * ec.dy + sy;
                    const double bx = P.x + 768.0 * ec.dx + sx, by = P.y + 768.0 * ec.dy + sy;
                    const double cx = P.x + 1024.0 * ec.nx + sx, cy = P.y + 1024.0 * ec.ny + sy;
                    const mr::Mesh m = winding == 0 ? mesh_of({fx(ax, ay), fx(bx, by), fx(cx, cy)})
                                                    : mesh_of({fx(bx, by), fx(ax, ay), fx(cx, cy)});
                    SCOPED_TRACE(std::string(ec.name) + ", winding " + std::to_string(winding) + ", shift (" +
                                 std::to_string(sx) + ", " + std::to_string(sy) + ")");
                    const int side = -(ec.nx * sx + ec.ny * sy);  // > 0: P is inside by that much
                    const bool expected = side > 0 || (side == 0 && ec.owns_samples_on_it);

                    EXPECT_EQ(oracle::covers(snapped_triangle(m, 0), P.x, P.y), expected) << "oracle disagrees with the rule";
                    const mr::RenderResult r = render_fixed(m, W, H, 1, mr::PatternKind::center);
                    EXPECT_EQ(sample_channel(r.framebuffer, 8, 8, 0, 0), expected ? 1.0f : 0.0f);
                    const std::vector<int> counts = oracle_counts(m, W, H, oracle::center_pattern());
                    EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0,
                                              "coverage"));
                    ++checked;
                }
            }
        }
    }
    EXPECT_EQ(checked, 8 * 2 * 9);
}

/// Whether a sample is strictly inside (no tie-breaking needed).
bool strictly_inside(const std::array<Fixed2, 3>& v, std::int64_t x, std::int64_t y) {
    const oracle::i128 area = oracle::cross(v[0], v[1], v[2].x, v[2].y);
    if (area == 0) return false;
    for (int i = 0; i < 3; ++i) {
        oracle::i128 e = oracle::cross(v[i], v[(i + 1) % 3], x, y);
        if (area < 0) e = -e;
        if (e <= 0) return false;
    }
    return true;
}

TEST(TriangleSetup, RandomLatticeTrianglesWithEdgesThroughSamplesMatchTheOracleAt64Samples) {
    // Vertices on the lattice 16 + 32k units, the same lattice as the 8×8 grid pattern's samples:
    // edges pass exactly through many samples and vertices sit on samples, so the fill rule
    // decides a large number of samples.
    const int W = 32, H = 32, S = 64;
    std::mt19937_64 rng(1234);
    std::uniform_int_distribution<int> k(-8, W * 8 + 8);
    std::size_t ties = 0;
    for (int batch = 0; batch < 12; ++batch) {
        std::vector<glm::vec3> pos;
        for (int t = 0; t < 3 * 25; ++t) pos.push_back(fx(16 + 32.0 * k(rng), 16 + 32.0 * k(rng)));
        const mr::Mesh m = mesh_of(pos);
        const mr::RenderResult r = render_fixed(m, W, H, S, mr::PatternKind::grid);
        const oracle::Pattern p = to_oracle(r.pattern);
        ASSERT_TRUE(same_offsets(p, oracle::grid_pattern(8)));
        const std::vector<int> counts = oracle_counts(m, W, H, p);
        EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0, "coverage"))
            << "batch " << batch;
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            const auto v = snapped_triangle(m, t);
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x)
                    for (int s = 0; s < S; ++s) {
                        const Fixed2 q = oracle::sample_position(x, y, p, s);
                        ties += oracle::covers(v, q.x, q.y) && !strictly_inside(v, q.x, q.y);
                    }
        }
    }
    EXPECT_GT(ties, 1000u) << "too few samples on edges for the test to exercise the fill rule";
}

TEST(TriangleSetup, CoverageDoesNotDependOnVertexOrder) {
    const int W = 32, H = 32;
    std::mt19937_64 rng(77);
    std::uniform_int_distribution<int> k(-4, W * 8 + 4);
    const int orders[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    for (int t = 0; t < 20; ++t) {
        glm::vec3 v[3];
        for (auto& p : v) p = fx(16 + 32.0 * k(rng), 16 + 32.0 * k(rng));
        std::vector<float> first;
        for (const auto& o : orders) {
            const mr::Mesh m = mesh_of({v[o[0]], v[o[1]], v[o[2]]});
            const mr::RenderResult r = render_fixed(m, W, H, 64, mr::PatternKind::grid);
            if (first.empty()) {
                first = r.framebuffer.color;
                const std::vector<int> counts = oracle_counts(m, W, H, to_oracle(r.pattern));
                EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0, "coverage"));
            } else {
                EXPECT_TRUE(r.framebuffer.color == first) << "triangle " << t << " order " << o[0] << o[1] << o[2];
            }
        }
    }
}

TEST(TriangleSetup, RandomNdcTrianglesOnAnOddSizedViewportMatchTheOracleIncludingSnapping) {
    // Float NDC vertices (not on any grid) through the identity camera: the oracle snaps
    // (x+1)·W/2·256 and (1−y)·H/2·256 itself.
    const int W = 97, H = 61, S = 16;
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<float> u(-1.3f, 1.3f);
    for (int batch = 0; batch < 8; ++batch) {
        mr::Mesh m;
        for (int i = 0; i < 3 * 30; ++i) m.positions.push_back(glm::vec3(u(rng), u(rng), 0.0f));
        for (std::uint32_t i = 0; i < m.positions.size(); i += 3) add_triangle(m, i, i + 1, i + 2);
        const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), no_depth(mr::BlendMode::add))},
                                              identity_camera(), settings(W, H, S, mr::PatternKind::grid));
        const oracle::Pattern p = to_oracle(r.pattern);
        ASSERT_TRUE(same_offsets(p, oracle::grid_pattern(4)));
        std::vector<int> counts(static_cast<std::size_t>(W) * H * S, 0);
        for (const auto& tri : m.triangles) {
            std::array<Fixed2, 3> v;
            for (int i = 0; i < 3; ++i)
                v[i] = oracle::snap_ndc(m.positions[tri[i]].x, m.positions[tri[i]].y, W, H);
            oracle::accumulate_coverage(v, W, H, p, counts);
        }
        EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0, "coverage"))
            << "batch " << batch;
    }
}

// ---------------------------------------------------------------------------------------------
// Snapping rounds half to even
// ---------------------------------------------------------------------------------------------

TEST(TriangleSetup, SnappingRoundsHalfToEvenOnVerticalAndHorizontalEdges) {
    // The 3×3 grid puts samples at offsets 43, 128 and 213 (DESIGN.md: (a+½)/3 rounded to 1/256).
    const int W = 8, H = 8;
    auto pattern_has = [](const oracle::Pattern& p, int x) {
        for (int s = 0; s < p.count(); ++s)
            if (p.x[s] == x) return true;
        return false;
    };
    struct Case {
        double edge;   ///< units; the snapped edge is the nearest even integer
        int offset;    ///< sample offset inside pixel 2 that decides the case
        bool covered;  ///< with round-half-even
    };
    // Left (and top) edges own samples exactly on them.
    //   555.5 → 556: the sample at 512+43 = 555 is left of the edge → not covered (half-down: 555 → covered).
    //   640.5 → 640: the sample at 512+128 = 640 is on the edge → covered (half-up: 641 → not covered).
    const Case cases[] = {{555.5, 43, false}, {640.5, 128, true}};
    for (const Case& c : cases) {
        for (int axis = 0; axis < 2; ++axis) {
            SCOPED_TRACE("edge at " + std::to_string(c.edge) + (axis ? " (horizontal, top)" : " (vertical, left)"));
            // Vertical left edge at x = edge (interior right), or horizontal top edge at y = edge.
            const glm::vec3 a = axis ? fx(-512, c.edge) : fx(c.edge, -512);
            const glm::vec3 b = axis ? fx(8 * 256 + 512, c.edge) : fx(c.edge, 8 * 256 + 512);
            const glm::vec3 d = axis ? fx(1024, c.edge + 6 * 256) : fx(c.edge + 6 * 256, 1024);
            const mr::Mesh m = mesh_of({a, b, d});
            const mr::RenderResult r = render_fixed(m, W, H, 9, mr::PatternKind::grid);
            const oracle::Pattern p = to_oracle(r.pattern);
            ASSERT_TRUE(pattern_has(p, c.offset));
            int decided = 0;
            for (int s = 0; s < 9; ++s) {
                if ((axis ? p.y[s] : p.x[s]) != c.offset) continue;
                for (int i = 0; i < 8; ++i) {
                    const int x = axis ? i : 2, y = axis ? 2 : i;
                    EXPECT_EQ(sample_channel(r.framebuffer, x, y, s, 0), c.covered ? 1.0f : 0.0f)
                        << "pixel (" << x << ", " << y << ") sample " << s;
                    const Fixed2 q = oracle::sample_position(x, y, p, s);
                    EXPECT_EQ(oracle::covers(snapped_triangle(m, 0), q.x, q.y), c.covered);
                    ++decided;
                }
            }
            EXPECT_EQ(decided, 3 * 8);
        }
    }
}

TEST(TriangleSetup, HalfUnitVerticesIncludingNegativeOnesMatchTheOracle) {
    const int W = 16, H = 16, S = 16;
    std::mt19937_64 rng(4242);
    std::uniform_int_distribution<int> k(-3000, 7000);
    std::size_t rounding_matters = 0;
    for (int batch = 0; batch < 10; ++batch) {
        std::vector<glm::vec3> pos;
        for (int i = 0; i < 3 * 10; ++i) pos.push_back(fx(k(rng) + 0.5, k(rng) + 0.5));
        const mr::Mesh m = mesh_of(pos);
        const mr::RenderResult r = render_fixed(m, W, H, S, mr::PatternKind::grid);
        const oracle::Pattern p = to_oracle(r.pattern);
        const std::vector<int> counts = oracle_counts(m, W, H, p);
        EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0, "coverage"))
            << "batch " << batch;
        // Teeth: rounding half up instead would change some samples.
        std::vector<int> up(counts.size(), 0);
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            std::array<Fixed2, 3> v;
            for (int i = 0; i < 3; ++i) {
                const glm::vec3 q = m.positions[m.triangles[t][i]];
                v[i] = {static_cast<std::int64_t>(std::floor(q.x + 0.5)), static_cast<std::int64_t>(std::floor(q.y + 0.5))};
            }
            oracle::accumulate_coverage(v, W, H, p, up);
        }
        for (std::size_t i = 0; i < up.size(); ++i) rounding_matters += up[i] != counts[i];
    }
    EXPECT_GT(rounding_matters, 0u) << "the test cannot tell half-even from half-up rounding";
}

// ---------------------------------------------------------------------------------------------
// Whole-pixel shifts, up to the largest viewport
// ---------------------------------------------------------------------------------------------

TEST(TriangleSetup, ShiftingSmallTrianglesAcrossA32768PixelViewportShiftsCoverageExactly) {
    const int W = 32768, H = 8, S = 16;
    std::mt19937_64 rng(31337);
    std::uniform_int_distribution<int> ux(0, 24 * 256), uy(-128, 8 * 256 + 128);
    const int copies[3] = {3, 15991, 32300};  // pixel offsets of the three copies
    const int n = 10;
    std::vector<glm::vec3> pos;
    for (int t = 0; t < n; ++t) {
        int v[3][2];
        for (auto& p : v) {
            p[0] = ux(rng);
            p[1] = uy(rng);
        }
        for (int c : copies)
            for (auto& p : v) pos.push_back(fx((c + 40.0 * t) * 256 + p[0], p[1]));
    }
    const mr::Mesh m = mesh_of(pos);
    const mr::RenderResult r = render_fixed(m, W, H, S, mr::PatternKind::grid);
    const oracle::Pattern p = to_oracle(r.pattern);
    ASSERT_TRUE(same_offsets(p, oracle::grid_pattern(4)));
    const std::vector<int> counts = oracle_counts(m, W, H, p);
    EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0, "coverage"));

    std::size_t covered = 0, differ = 0;
    for (int t = 0; t < n; ++t)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < 40; ++x)
                for (int s = 0; s < S; ++s) {
                    const float a = sample_channel(r.framebuffer, copies[0] + 40 * t + x, y, s, 0);
                    covered += a != 0.0f;
                    for (int c = 1; c < 3; ++c)
                        differ += sample_channel(r.framebuffer, copies[c] + 40 * t + x, y, s, 0) != a;
                }
    EXPECT_EQ(differ, 0u);
    EXPECT_GT(covered, 100u);
}

TEST(TriangleSetup, ShiftingALongSliverFromMinus30000To62000PixelsShiftsCoverageExactly) {
    const int W = 32768, H = 8, S = 4;
    // A sliver spanning the whole viewport with vertices far outside it (inside the guard band).
    const double ax = -30000.0 * 256 + 77, ay = 77, bx = 62000.0 * 256 + 131, by = 1946,
                 cx = -29000.0 * 256 + 5, cy = 2022;
    std::vector<std::vector<float>> red;
    const int shifts[4][2] = {{0, 0}, {1, 0}, {1234, 0}, {5, 1}};
    for (const auto& sh : shifts) {
        const double dx = sh[0] * 256.0, dy = sh[1] * 256.0;
        const mr::Mesh m = mesh_of({fx(ax + dx, ay + dy), fx(bx + dx, by + dy), fx(cx + dx, cy + dy)});
        const mr::RenderResult r = render_fixed(m, W, H, S, mr::PatternKind::rotated);
        const std::vector<int> counts = oracle_counts(m, W, H, to_oracle(r.pattern));
        EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0, "coverage"))
            << "shift (" << sh[0] << ", " << sh[1] << ")";
        std::vector<float> v(static_cast<std::size_t>(W) * H * S);
        for (std::size_t i = 0; i < v.size(); ++i) v[i] = r.framebuffer.color[4 * i];
        red.push_back(std::move(v));
    }
    auto at = [&](int k, int x, int y, int s) { return red[k][(static_cast<std::size_t>(y) * W + x) * S + s]; };
    std::size_t covered = 0;
    for (int k = 1; k < 4; ++k) {
        const int dx = shifts[k][0], dy = shifts[k][1];
        std::size_t differ = 0;
        for (int y = dy; y < H; ++y)
            for (int x = dx; x < W; ++x)
                for (int s = 0; s < S; ++s) {
                    differ += at(k, x, y, s) != at(0, x - dx, y - dy, s);
                    covered += at(0, x - dx, y - dy, s) != 0.0f;
                }
        EXPECT_EQ(differ, 0u) << "shift (" << dx << ", " << dy << ")";
    }
    EXPECT_GT(covered, 10000u);
}

// ---------------------------------------------------------------------------------------------
// Degenerate triangles and culling
// ---------------------------------------------------------------------------------------------

TEST(TriangleSetup, ZeroAreaAfterSnappingCoversNothingAndIsCountedDegenerate) {
    const int W = 16, H = 16;
    const std::vector<glm::vec3> pos = {
        // collinear only after snapping: (500,500), (1500,1500), (2500,2500)
        fx(500.3, 500.2), fx(1500.4, 1499.8), fx(2500.2, 2500.3),
        // three distinct points that snap to one
        fx(1000.1, 1000.2), fx(1000.3, 999.9), fx(999.8, 1000.4),
        // a repeated vertex
        fx(300, 300), fx(300, 300), fx(3000, 3500),
        // collinear through three pixel centres (samples exactly on the line)
        fx(128, 128), fx(128 + 512, 128 + 512), fx(128 + 1024, 128 + 1024),
        // control: a thin triangle that is not degenerate
        fx(500, 500), fx(3500, 3501), fx(2000, 2000),
    };
    const mr::Mesh m = mesh_of(pos);
    // Before snapping, the first two have non-zero area (the collapse is snapping's doing).
    for (int t = 0; t < 2; ++t) {
        const glm::dvec3 a(pos[3 * t]), b(pos[3 * t + 1]), c(pos[3 * t + 2]);
        EXPECT_NE((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x), 0.0);
    }
    for (int t = 0; t < 4; ++t) EXPECT_TRUE(oracle::is_degenerate(snapped_triangle(m, t))) << "triangle " << t;
    EXPECT_FALSE(oracle::is_degenerate(snapped_triangle(m, 4)));

    const mr::RenderResult r = render_fixed(m, W, H, 16, mr::PatternKind::grid);
    EXPECT_EQ(r.stats.triangles_degenerate, 4u);
    EXPECT_EQ(r.stats.triangles_rasterized, 1u);
    std::vector<int> counts(static_cast<std::size_t>(W) * H * 16, 0);
    oracle::accumulate_coverage(snapped_triangle(m, 4), W, H, to_oracle(r.pattern), counts);
    EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0, "coverage"));

    // Alone, the degenerate ones draw nothing at all, at 1 sample too (samples on the line).
    mr::Mesh only_degenerate = mesh_of(std::vector<glm::vec3>(pos.begin(), pos.begin() + 12));
    const mr::RenderResult r1 = render_fixed(only_degenerate, W, H, 1, mr::PatternKind::center);
    EXPECT_EQ(r1.stats.triangles_degenerate, 4u);
    EXPECT_EQ(r1.stats.samples_covered, 0u);
    EXPECT_TRUE(samples_equal(r1.framebuffer, std::vector<float>(W * H, 0.0f), 0, "coverage"));
}

TEST(TriangleSetup, BackFaceCullingRemovesExactlyTheExpectedWinding) {
    const int W = 32, H = 32;
    // One triangle on the left, one on the right; NDC, y up.
    const std::vector<glm::vec3> pos = {
        {-0.9f, -0.5f, 0.0f}, {-0.1f, -0.5f, 0.0f}, {-0.5f, 0.5f, 0.0f},  // left
        {0.1f, -0.5f, 0.0f},  {0.5f, 0.5f, 0.0f},   {0.9f, -0.5f, 0.0f},  // right
    };
    auto ccw_in_ndc = [&](int t) {
        const glm::dvec3 a(pos[3 * t]), b(pos[3 * t + 1]), c(pos[3 * t + 2]);
        return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) > 0.0;  // y up: > 0 is CCW
    };
    ASSERT_TRUE(ccw_in_ndc(0));
    ASSERT_FALSE(ccw_in_ndc(1));
    const mr::Mesh m = mesh_of(pos);

    auto triangle_counts = [&](int t, const oracle::Pattern& p) {
        std::array<Fixed2, 3> v;
        for (int i = 0; i < 3; ++i) v[i] = oracle::snap_ndc(pos[3 * t + i].x, pos[3 * t + i].y, W, H);
        std::vector<int> counts(static_cast<std::size_t>(W) * H * p.count(), 0);
        oracle::accumulate_coverage(v, W, H, p, counts);
        return counts;
    };
    for (mr::CullMode cull : {mr::CullMode::none, mr::CullMode::back, mr::CullMode::front}) {
        SCOPED_TRACE(mr::to_string(cull));
        mr::DrawState st = no_depth(mr::BlendMode::add);
        st.cull = cull;
        const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), st)}, identity_camera(),
                                              settings(W, H, 4, mr::PatternKind::rotated));
        const oracle::Pattern p = to_oracle(r.pattern);
        // Front faces are counter-clockwise in NDC: back culling keeps triangle 0, front keeps 1.
        const bool keep0 = cull != mr::CullMode::front, keep1 = cull != mr::CullMode::back;
        std::vector<float> expected(static_cast<std::size_t>(W) * H * 4, 0.0f);
        const auto c0 = triangle_counts(0, p), c1 = triangle_counts(1, p);
        for (std::size_t i = 0; i < expected.size(); ++i) expected[i] = float((keep0 ? c0[i] : 0) + (keep1 ? c1[i] : 0));
        EXPECT_TRUE(samples_equal(r.framebuffer, expected, 0, "coverage"));
        EXPECT_EQ(r.stats.triangles_backface, std::uint64_t(cull == mr::CullMode::none ? 0 : 1));
        EXPECT_EQ(r.stats.triangles_rasterized, std::uint64_t(cull == mr::CullMode::none ? 2 : 1));
    }
}

TEST(TriangleSetup, BackFaceCullingThroughAPerspectiveCameraKeepsTheFacesTowardTheViewer) {
    // A closed cube viewed from outside, each face with its own vertices and colour, wound
    // counter-clockwise seen from outside. Culling back faces must show, at every sample, the face
    // the ray caster hits first; culling front faces the face it hits last.
    mr::Mesh cube;
    const glm::vec3 corner[8] = {{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1},
                                 {-1, -1, 1},  {1, -1, 1},  {-1, 1, 1},  {1, 1, 1}};
    // Faces as quads (a, b, c, d), counter-clockwise seen from outside.
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; ++f) {
        const std::uint32_t base = static_cast<std::uint32_t>(cube.positions.size());
        for (int i = 0; i < 4; ++i) {
            cube.positions.push_back(corner[quads[f][i]]);
            cube.colors.push_back(glm::vec4(static_cast<float>(f + 1) / 8.0f, 0.0f, 0.0f, 1.0f));
        }
        add_triangle(cube, base, base + 1, base + 2);
        add_triangle(cube, base, base + 2, base + 3);
    }
    // Check of the test mesh: every normal (b−a)×(c−a) points away from the centre.
    for (const auto& t : cube.triangles) {
        const glm::dvec3 a(cube.positions[t[0]]), b(cube.positions[t[1]]), c(cube.positions[t[2]]);
        ASSERT_GT(oracle::RayCaster::dot3(oracle::RayCaster::cross3(b - a, c - a), (a + b + c) / 3.0), 0.0);
    }
    const mr::Camera cam = mr::Camera::look_at_perspective({3.0, 2.5, 4.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0.9, 1.0, 0.1);
    const int W = 64, H = 64;
    auto draw_with = [&](mr::CullMode cull) {
        mr::DrawState st = no_depth(mr::BlendMode::add);
        st.cull = cull;
        st.interpolation = mr::Interpolation::flat;
        return mr::render({make_draw(cube, glm::dmat4(1.0), st)}, cam, settings(W, H, 1));
    };
    const mr::RenderResult back = draw_with(mr::CullMode::back), front = draw_with(mr::CullMode::front);
    const oracle::RayCaster rc(cam.view, cam.projection, true, W, H);
    std::size_t inside = 0, checked = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const oracle::Ray ray = rc.ray(x + 0.5, y + 0.5);
            double nearest = 1e300, farthest = -1e300, min_edge = 1e300;
            float nearest_color = 0.0f, farthest_color = 0.0f;
            for (const auto& t : cube.triangles) {
                const glm::dvec3 a(cube.positions[t[0]]), b(cube.positions[t[1]]), c(cube.positions[t[2]]);
                const oracle::Hit h = rc.intersect(ray, a, b, c);
                if (h.hit && h.view_distance < nearest) {
                    nearest = h.view_distance;
                    nearest_color = cube.colors[t[0]].r;
                }
                if (h.hit && h.view_distance > farthest) {
                    farthest = h.view_distance;
                    farthest_color = cube.colors[t[0]].r;
                }
                const glm::dvec3 pa = rc.project(a), pb = rc.project(b), pc = rc.project(c);
                for (auto [p, q] : {std::pair{pa, pb}, std::pair{pb, pc}, std::pair{pc, pa}})
                    min_edge = std::min(min_edge, oracle::distance_to_segment({x + 0.5, y + 0.5}, {p.x, p.y}, {q.x, q.y}));
            }
            if (min_edge < 0.01) continue;  // on a projected edge: skip
            ++checked;
            inside += nearest < 1e300;
            EXPECT_EQ(sample_channel(back.framebuffer, x, y, 0, 0), nearest_color) << "back culling, pixel " << x << "," << y;
            EXPECT_EQ(sample_channel(front.framebuffer, x, y, 0, 0), farthest_color) << "front culling, pixel " << x << "," << y;
        }
    EXPECT_GT(inside, 500u);
    EXPECT_GT(checked, 3000u);
    // Three faces (six triangles) face the camera at (3, 2.5, 4), three face away.
    EXPECT_EQ(back.stats.triangles_backface, 6u);
    EXPECT_EQ(front.stats.triangles_backface, 6u);
}

}  // namespace

namespace {

// The depth plane is kept in double and rounded to float once per sample, so the stored depth is
// the correctly rounded value of the unsnapped triangle's depth plane (screen-affine in z/w) at
// the sample's position in the snapped triangle. A plane stored as three floats rounds three times
// and can invert surfaces ~1e-7 apart (relative): found by the stress suite, case 5 (reverse-Z,
// distance 100, separation 1e-7: 80 % inverted). The vertices' own depths interpolated over the
// snapped triangle are off by the plane's change across the snapping: surfaces 1e-6 apart whose
// vertices snapped differently swapped.
TEST(TriangleSetup, DepthAtASampleIsTheCorrectlyRoundedPlaneValue) {
    std::mt19937_64 rng(61);
    std::uniform_real_distribution<double> xy(-0.9, 0.9), w(0.5, 3.0), z(0.0, 1.0), bary(0.0, 1.0);
    mr::Viewport vp;
    vp.width = vp.height = 256;
    vp.depth_convention = mr::DepthConvention::reverse_z;
    std::size_t checked = 0, wrong = 0;
    for (int k = 0; k < 2000; ++k) {
        std::array<glm::dvec4, 3> p;
        std::array<double, 3> zw;
        for (int i = 0; i < 3; ++i) {
            const double wi = w(rng);
            zw[i] = z(rng);
            p[i] = glm::dvec4(xy(rng) * wi, xy(rng) * wi, zw[i] * wi, wi);
            zw[i] = p[i].z / p[i].w;  // the window depth the setup sees
        }
        mr::SetupTriangle t;
        mr::SetupCounters counters;
        if (!mr::setup_triangle(p, vp, mr::CullMode::none, t, counters)) continue;
        // Unsnapped (exact) and snapped positions in 1/256 px, and the exact plane's gradient.
        long double ux[3], uy[3], sx[3], sy[3];
        for (int i = 0; i < 3; ++i) {
            ux[i] = (static_cast<long double>(p[i].x) / p[i].w + 1) * 128 * 256;
            uy[i] = (1 - static_cast<long double>(p[i].y) / p[i].w) * 128 * 256;
            const mr::ScreenVertex s = mr::project_vertex(p[i], vp);
            sx[i] = s.x, sy[i] = s.y;
        }
        const long double ex1 = ux[1] - ux[0], ey1 = uy[1] - uy[0], ex2 = ux[2] - ux[0], ey2 = uy[2] - uy[0];
        const long double det = ex1 * ey2 - ey1 * ex2, dz1 = zw[1] - zw[0], dz2 = zw[2] - zw[0];
        const long double gx = (dz1 * ey2 - dz2 * ey1) / det, gy = (dz2 * ex1 - dz1 * ex2) / det;
        for (int j = 0; j < 8; ++j) {
            double l1 = bary(rng), l2 = bary(rng);
            if (l1 + l2 > 1.0) {
                l1 = 1.0 - l1;
                l2 = 1.0 - l2;
            }
            const glm::dvec3 l(1.0 - l1 - l2, l1, l2);
            const long double x = l.x * sx[0] + l.y * sx[1] + l.z * sx[2], y = l.x * sy[0] + l.y * sy[1] + l.z * sy[2];
            const double exact = static_cast<double>(zw[0] + gx * (x - ux[0]) + gy * (y - uy[0]));
            const float got = mr::sample_depth(t, l);
            // Skip values within 1e-9 of a rounding boundary (the snap offsets are kept as floats,
            // 2^-25 of 1/256 px; with double's own error that could flip them).
            const float lo = static_cast<float>(exact * (1 - 1e-9)), hi = static_cast<float>(exact * (1 + 1e-9));
            if (lo != hi) continue;
            ++checked;
            wrong += got != static_cast<float>(exact);
        }
    }
    EXPECT_GT(checked, 10000u);
    EXPECT_EQ(wrong, 0u) << wrong << " of " << checked << " depths are not the correctly rounded plane value";
}

// A triangle's bounds are the pixels with a sample position inside its box (Viewport's sample
// extent): every sample the oracle finds covered lies in them, and they are exactly the pixels
// whose span of sample offsets meets the box (found here by scanning, not by the setup's
// ⌈·⌉/⌊·⌋); a triangle whose box holds no sample position is not set up: counted as outside where
// the box meets no pixel of the viewport, else as between the samples.
// Small random triangles (many between samples) for the documented patterns' extents and the
// whole-pixel default.
TEST(TriangleSetup, BoundsAreThePixelsWithASamplePositionInTheTrianglesBox) {
    constexpr int W = 40, H = 30;
    const std::vector<oracle::Pattern> patterns = {oracle::center_pattern(), oracle::rotated_pattern(),
                                                   oracle::grid_pattern(4), oracle::Pattern{{5, 250}, {77, 200}}};
    std::mt19937_64 rng(20261130);
    std::uniform_int_distribution<int> corner(-3 * 256, (W + 3) * 256), spread(0, 3 * 256);
    std::size_t set_up = 0, between_samples = 0, covered_samples = 0;
    for (std::size_t k = 0; k <= patterns.size(); ++k) {
        const bool whole_pixel = k == patterns.size();  // the defaults: any offset in the pixel
        const oracle::Pattern pattern = whole_pixel ? oracle::center_pattern() : patterns[k];
        mr::Viewport vp{W, H, mr::DepthConvention::reverse_z};
        if (!whole_pixel) {
            vp.sample_x0 = *std::min_element(pattern.x.begin(), pattern.x.end());
            vp.sample_x1 = *std::max_element(pattern.x.begin(), pattern.x.end());
            vp.sample_y0 = *std::min_element(pattern.y.begin(), pattern.y.end());
            vp.sample_y1 = *std::max_element(pattern.y.begin(), pattern.y.end());
        }
        // The pixels along one axis whose samples' span [p·256 + lo, p·256 + hi] meets [a, b].
        const auto scan = [](std::int64_t a, std::int64_t b, int lo, int hi, int n, int& first, int& last) {
            first = n, last = -1;
            for (int p = 0; p < n; ++p) {
                const std::int64_t corner = std::int64_t{p} * 256;
                if (corner + hi >= a && corner + lo <= b) first = std::min(first, p), last = p;
            }
        };
        for (int t = 0; t < 3000; ++t) {
            const int x0 = corner(rng), y0 = corner(rng) * H / W;
            const int size = t % 3 == 0 ? 64 : spread(rng);  // a third of them within a quarter pixel
            std::array<mr::ScreenVertex, 3> v{};
            std::array<oracle::Fixed2, 3> f;
            std::uniform_int_distribution<int> offset(0, size);
            for (int i = 0; i < 3; ++i) {
                v[i].x = x0 + offset(rng), v[i].y = y0 + offset(rng), v[i].inv_w = 1.0, v[i].depth = 0.5;
                f[i] = {v[i].x, v[i].y};
            }
            mr::SetupTriangle st;
            mr::SetupCounters counters;
            const bool ok = mr::setup_triangle(v, vp, mr::CullMode::none, st, counters);
            if (oracle::is_degenerate(f)) {
                EXPECT_FALSE(ok);
                continue;
            }
            const std::int64_t lo_x = std::min({f[0].x, f[1].x, f[2].x}), hi_x = std::max({f[0].x, f[1].x, f[2].x});
            const std::int64_t lo_y = std::min({f[0].y, f[1].y, f[2].y}), hi_y = std::max({f[0].y, f[1].y, f[2].y});
            int first_x, last_x, first_y, last_y, any_x0, any_x1, any_y0, any_y1;
            scan(lo_x, hi_x, vp.sample_x0, vp.sample_x1, W, first_x, last_x);
            scan(lo_y, hi_y, vp.sample_y0, vp.sample_y1, H, first_y, last_y);
            scan(lo_x, hi_x, 0, 255, W, any_x0, any_x1);  // the pixels the box meets at all
            scan(lo_y, hi_y, 0, 255, H, any_y0, any_y1);
            const bool some_pixel = first_x <= last_x && first_y <= last_y;
            const bool meets_view = any_x0 <= any_x1 && any_y0 <= any_y1;
            ASSERT_EQ(ok, some_pixel) << "pattern " << k << ", triangle " << t;
            if (!ok) {
                EXPECT_EQ(counters.culled_outside, meets_view ? 0u : 1u);
                EXPECT_EQ(counters.culled_between_samples, meets_view ? 1u : 0u);
                between_samples += meets_view;
                continue;
            }
            ++set_up;
            EXPECT_EQ(st.min_x, first_x);
            EXPECT_EQ(st.max_x, last_x);
            EXPECT_EQ(st.min_y, first_y);
            EXPECT_EQ(st.max_y, last_y);
            for (int py = 0; py < H; ++py)
                for (int px = 0; px < W; ++px)
                    for (int s = 0; s < pattern.count(); ++s) {
                        const oracle::Fixed2 p = oracle::sample_position(px, py, pattern, s);
                        if (!oracle::covers(f, p.x, p.y)) continue;
                        ++covered_samples;
                        ASSERT_TRUE(px >= st.min_x && px <= st.max_x && py >= st.min_y && py <= st.max_y)
                            << "pattern " << k << ": covered sample " << s << " of pixel " << px << "," << py
                            << " outside the bounds";
                    }
        }
    }
    EXPECT_GT(set_up, 5000u);
    EXPECT_GT(covered_samples, 5000u);
    EXPECT_GT(between_samples, 100u);  // triangles inside the viewport between its samples
}

}  // namespace
