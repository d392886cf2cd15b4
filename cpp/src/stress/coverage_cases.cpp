// Stress cases on coverage, each compared sample for sample with the exact oracle:
// 1 watertightness, 2 slivers, 3 huge coordinates, 8 degenerate triangles, 10 sub-pixel motion.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "mipraster/stress/exact_coverage.hpp"
#include "mipraster/stress/stress_cases.hpp"
#include "pipeline_probe.hpp"
#include "stress_util.hpp"

namespace mipraster {

using namespace stress;

namespace {

std::string comparison_text(const CoverageComparison& c) {
    return "cracks " + count(c.cracks) + ", double hits " + count(c.double_hits) + ", mismatches " +
           count(c.mismatches) + " of " + count(c.samples) + " samples (" + count(c.oracle_covered) + " covered)";
}

std::array<FixedPoint, 3> snapped(const Mesh& m, const glm::uvec3& t) {
    std::array<FixedPoint, 3> v;
    for (int i = 0; i < 3; ++i) v[i] = {exact_snap(double(m.positions[t[i]].x)), exact_snap(double(m.positions[t[i]].y))};
    return v;
}

}  // namespace

// ---- 1. Watertightness ---------------------------------------------------------------------------

std::vector<StressRow> stress_watertight(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 1;
    row.name = "watertight";
    struct Setup {
        std::string what;
        StressScene scene;
        bool fills_viewport;
    };
    std::vector<Setup> setups;
    const int gw = full ? 2048 : 1024, gh = full ? 1024 : 512, cells = full ? 512 : 256;
    for (int S : {1, 16}) {
        // A jittered grid past every side of the viewport: every sample must be covered exactly once.
        auto grid = jittered_grid_mesh(cells, cells / 2, -0.1 * gw, -0.1 * gh, 1.1 * gw, 1.1 * gh, false, 11 + S);
        setups.push_back({"grid " + std::to_string(cells) + "x" + std::to_string(cells / 2) + " quads, " +
                              std::to_string(gw) + "x" + std::to_string(gh) + " S=" + std::to_string(S),
                          coverage_scene("watertight grid S=" + std::to_string(S), grid, gw, gh, S), true});
    }
    const int fw = full ? 512 : 128, fan_n = full ? 4000 : 1000;
    for (int S : {1, 16}) {
        // Fan centred exactly on a sample: all triangles meet there, one must own it.
        auto fan = fan_mesh(fw / 2 + 0.5, fw / 2 + 0.5, 0.4 * fw, fan_n);
        setups.push_back({"fan of " + std::to_string(fan_n) + " at a sample, S=" + std::to_string(S),
                          coverage_scene("watertight fan", fan, fw, fw, S, S == 1 ? PatternKind::center : PatternKind::grid),
                          false});
    }
    const int rw = full ? 1024 : 256, rc = full ? 300 : 75;
    auto random_mesh = jittered_grid_mesh(rc, rc, 0.08 * rw, 0.07 * rw, 0.92 * rw, 0.94 * rw, true, 21);
    setups.push_back({"random conforming mesh of " + count(random_mesh->triangles.size()) + " on the 1/256 grid, S=16",
                      coverage_scene("watertight random mesh", random_mesh, rw, rw, 16), false});

    std::uint64_t samples = 0, cracks = 0, doubles = 0, mismatches = 0, oracle_twice = 0, uncovered_full = 0;
    bool patterns = true, finite = true;
    for (const Setup& s : setups) {
        const RenderResult r = render_scene(s.scene);
        const CoverageComparison c = compare_coverage(s.scene, r);
        samples += c.samples;
        cracks += c.cracks;
        doubles += c.double_hits;
        mismatches += c.mismatches;
        oracle_twice += c.oracle_twice;
        if (s.fills_viewport) uncovered_full += c.samples - c.oracle_covered;
        patterns = patterns && c.pattern_ok;
        finite = finite && c.finite;
        row.details.push_back(s.what + ": " + comparison_text(c));
    }
    row.tried = std::to_string(setups.size()) + " meshes (jittered grids past the viewport, fans, a random conforming mesh) at S = 1 and 16, " +
                count(samples) + " samples";
    row.figure = "cracks " + count(cracks) + ", double hits " + count(doubles) + ", samples differing from the exact reference " +
                 count(mismatches);
    row.bound = "0 cracks, 0 double hits, 0 differences (the reference itself covers no sample twice" +
                std::string(full ? ", >= 10^7 samples" : "") + ")";
    row.pass = cracks == 0 && doubles == 0 && mismatches == 0 && oracle_twice == 0 && uncovered_full == 0 && patterns &&
               finite && (!full || samples >= 10000000);
    if (oracle_twice || uncovered_full) row.details.push_back("test meshes are not conforming: the reference counts " +
                                                              count(oracle_twice) + " samples twice, " +
                                                              count(uncovered_full) + " uncovered in a full grid");
    if (!patterns) row.details.push_back("the renderer's sample pattern differs from the documented one");
    return {row};
}

// ---- 2. Slivers ----------------------------------------------------------------------------------

std::vector<StressRow> stress_slivers(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 2;
    row.name = "slivers";
    const int W = full ? 256 : 128, angles = full ? 180 : 90;
    std::uint64_t samples = 0, mismatches = 0, covered = 0;
    bool finite = true;
    for (const double width : {1e-3, 1e-2, 1.0 / 256.0}) {
        for (const int S : {1, 16}) {
            const StressScene sc = coverage_scene("slivers", sliver_mesh(W, W, 1e4, width, angles, 7), W, W, S,
                                                  S == 1 ? PatternKind::center : PatternKind::grid);
            const CoverageComparison c = compare_coverage(sc, render_scene(sc));
            samples += c.samples;
            mismatches += c.mismatches;
            covered += c.oracle_covered;
            finite = finite && c.finite && c.pattern_ok;
            row.details.push_back("width " + fmt(width) + " px, S=" + std::to_string(S) + ": " + comparison_text(c));
        }
    }
    row.tried = std::to_string(angles) + " slivers 10^4 px long at angles k*180/" + std::to_string(angles) +
                " deg, widths 10^-3, 10^-2, 1/256 px, S = 1 and 16, " + std::to_string(W) + "^2 viewport";
    row.figure = count(mismatches) + " of " + count(samples) + " samples differ from the exact reference (" +
                 count(covered) + " covered)";
    row.bound = "0 differences";
    row.pass = mismatches == 0 && finite && covered > 0;
    return {row};
}

// ---- 3. Huge coordinates -------------------------------------------------------------------------

std::vector<StressRow> stress_huge_coordinates(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 3;
    row.name = "huge coordinates";
    const int W = 256, n = full ? 64 : 16;
    // A difference is explained when the reference itself flips within this many 1/256 px of the
    // sample: past the guard band the pipeline clips before snapping, so its edges may move by
    // the snapping of the clipped vertices (≤ √2/2 unit) plus the clip's rounding.
    const std::int64_t band = 2;
    std::uint64_t unexplained = 0, explained = 0, guard_band_differences = 0, samples = 0, covered = 0;
    int edge_bits = 0, coef_bits = 0;
    bool finite = true;
    for (const double radius : {1e6, 1e9, 1e12, 1e15}) {
        std::vector<std::array<glm::dvec2, 3>> units;
        const ClipScene sc = huge_scene(W, radius, n, 5, &units);
        // Inside the guard band (2^20 px from the centre) nothing is clipped: coverage must be exact.
        const bool in_guard_band = radius + W < 1048576.0;
        std::uint64_t differences = 0, here_unexplained = 0, here_covered = 0;
        int S = 0;
        for (std::size_t t = 0; t < sc.triangles.size(); ++t) {
            // One triangle per call: the primitive layer's depth test would hide overlaps.
            const glm::uvec3 tri = sc.triangles[t];
            const Visibility vis = rasterize({sc.clip[tri[0]], sc.clip[tri[1]], sc.clip[tri[2]]}, {glm::uvec3(0, 1, 2)},
                                             sc.settings);
            finite = finite && pattern_is_documented(vis.pattern);
            S = vis.samples;
            std::array<FixedPoint, 3> v;
            for (int i = 0; i < 3; ++i) v[i] = {exact_snap(units[t][i].x), exact_snap(units[t][i].y)};
            for (int y = 0; y < W; ++y)
                for (int x = 0; x < W; ++x)
                    for (int s = 0; s < S; ++s) {
                        const std::size_t i = (static_cast<std::size_t>(y) * W + x) * S + s;
                        const std::int64_t X = x * 256 + vis.pattern.x[s], Y = y * 256 + vis.pattern.y[s];
                        const bool want = exact_covers(v, X, Y), got = vis.triangle_id[i] == 0;
                        ++samples;
                        here_covered += want;
                        if (got) finite = finite && std::isfinite(vis.depth[i]) && std::isfinite(vis.barycentrics[2 * i]) &&
                                          std::isfinite(vis.barycentrics[2 * i + 1]);
                        if (got == want) continue;
                        ++differences;
                        bool flips = false;
                        for (int dy = -1; dy <= 1 && !flips; ++dy)
                            for (int dx = -1; dx <= 1 && !flips; ++dx)
                                flips = exact_covers(v, X + dx * band, Y + dy * band) != want;
                        if (!flips) ++here_unexplained;
                    }
        }
        covered += here_covered;
        if (in_guard_band) guard_band_differences += differences;
        unexplained += here_unexplained;
        explained += differences - here_unexplained;
        // The bit budget of the edge functions with these inputs, through the pipeline's own setup.
        const ProbeStats ps = probe_samples(sc.clip, sc.triangles, {}, W, W, make_sample_pattern(PatternKind::rotated, 4),
                                            DepthConvention::opengl, Interpolation::screen, [](const ProbeSample&) {});
        edge_bits = std::max(edge_bits, ps.max_edge_bits);
        coef_bits = std::max(coef_bits, ps.max_coefficient_bits);
        row.details.push_back("radius " + fmt(radius) + " px" + (in_guard_band ? " (inside the guard band)" : " (clipped)") +
                              ": " + count(differences) + " differences, " + count(differences - here_unexplained) +
                              " within 2/256 px of the exact edge, " + count(here_unexplained) + " beyond; " +
                              count(here_covered) + " covered; edge values need " + std::to_string(ps.max_edge_bits) +
                              " bits, coefficients " + std::to_string(ps.max_coefficient_bits));
    }
    row.tried = std::to_string(n) + " triangles per radius with vertices 10^6, 10^9, 10^12, 10^15 px away and an edge "
                "through a 256^2 viewport, rotated 4x, clip space in double";
    row.figure = count(guard_band_differences) + " differences inside the guard band; past it " + count(explained) +
                 " within 2/256 px of the exact edge and " + count(unexplained) + " beyond; edge values " +
                 std::to_string(edge_bits) + " bits, coefficients " + std::to_string(coef_bits) + " bits";
    row.bound = "exact inside the guard band, 0 beyond 2/256 px past it; edge values <= 63 bits, coefficients <= 31";
    row.pass = guard_band_differences == 0 && unexplained == 0 && edge_bits <= 63 && coef_bits <= 31 && finite && covered > 0;
    return {row};
}

// ---- 8. Degenerate triangles ---------------------------------------------------------------------

std::vector<StressRow> stress_degenerate(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 8;
    row.name = "degenerate triangles";
    const int W = 128;
    auto m = std::make_shared<Mesh>();
    auto add = [&](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {  // 1/256 px units
        const std::uint32_t first = static_cast<std::uint32_t>(m->positions.size());
        for (const glm::dvec2& p : {a, b, c}) m->positions.push_back(glm::vec3(float(p.x), float(p.y), 0.0f));
        m->triangles.push_back(glm::uvec3(first, first + 1, first + 2));
    };
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0.0, W * 256.0), dir(-1.0, 1.0);
    const int n = full ? 20000 : 2000;
    for (int k = 0; k < n; ++k) {
        const glm::dvec2 a(std::round(u(rng)), std::round(u(rng)));
        const glm::dvec2 d(std::round(dir(rng) * 4096), std::round(dir(rng) * 4096));
        switch (k % 5) {
            case 0: add(a, a + d, a + 3.0 * d); break;                      // collinear, exact on the grid
            case 1: add(a, a, a + d); break;                                // repeated vertex
            case 2: add(a, a, a); break;                                    // a point
            case 3: add(a, a + d + glm::dvec2(0.3, -0.2), a + 2.0 * d + glm::dvec2(-0.4, 0.1)); break;  // zero area after snapping
            case 4: {  // collinear, vertices 2^20 steps out (clipped); exact in float on a 4096-unit grid
                const glm::dvec2 c = glm::round(a / 4096.0) * 4096.0;
                add(c - 1048576.0 * d, c, c + 1048576.0 * d);
                break;
            }
        }
    }
    // Each triangle must be degenerate for the reference too, else the test mesh is wrong.
    std::uint64_t not_degenerate = 0;
    for (const auto& t : m->triangles)
        not_degenerate += !exact_degenerate(snapped(*m, t));
    std::uint64_t covered = 0, nonfinite = 0;
    for (const int S : {1, 16}) {
        StressScene sc = coverage_scene("degenerate", m, W, W, S);
        sc.draws[0].state.interpolation = Interpolation::perspective;
        const RenderResult r = render_scene(sc);
        covered += r.stats.samples_covered;
        for (float v : r.framebuffer.color) nonfinite += !std::isfinite(v) || v != 0.0f;
    }
    // Through the pipeline's own stages: no piece is set up, no sample is visited.
    std::vector<glm::dvec4> clip;
    for (const glm::vec3& p : m->positions) clip.push_back(fixed_to_ndc(W, W) * glm::dvec4(glm::dvec3(p), 1.0));
    std::uint64_t probed = 0;
    const ProbeStats ps = probe_samples(clip, m->triangles, {}, W, W, make_sample_pattern(PatternKind::grid, 16),
                                        DepthConvention::opengl, Interpolation::perspective,
                                        [&](const ProbeSample&) { ++probed; });
    row.tried = count(m->triangles.size()) + " collinear, repeated-vertex, point, snapped-to-zero and far collinear "
                "triangles, S = 1 and 16";
    row.figure = count(covered) + " samples covered, " + count(nonfinite) + " framebuffer values non-zero or non-finite, " +
                 count(ps.pieces) + " pieces set up";
    row.bound = "0 covered, 0 non-zero, 0 set up";
    row.pass = covered == 0 && nonfinite == 0 && ps.pieces == 0 && probed == 0 && not_degenerate == 0;
    if (not_degenerate) row.details.push_back(count(not_degenerate) + " test triangles are not degenerate for the reference");
    return {row};
}

// ---- 10. Sub-pixel motion ------------------------------------------------------------------------

std::vector<StressRow> stress_subpixel_motion(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 10;
    row.name = "sub-pixel motion";
    const int W = 16, S = 16, steps = full ? 1024 : 256;
    const glm::dvec2 base[3] = {{1000.3, 900.0}, {2900.0, 1500.7}, {1300.0, 3100.2}};  // 1/256 px units
    std::uint64_t mismatches = 0, samples = 0, non_monotonic = 0, changes = 0;
    for (const glm::dvec2 step : {glm::dvec2(1, 0), glm::dvec2(0, 1), glm::dvec2(1, 1)}) {
        std::vector<std::vector<std::uint8_t>> seq;  // per step, per sample
        for (int k = 0; k < steps; ++k) {
            auto m = std::make_shared<Mesh>();
            for (const glm::dvec2& p : base) {
                const glm::dvec2 q = p + double(k) * step;
                m->positions.push_back(glm::vec3(float(q.x), float(q.y), 0.0f));
            }
            m->triangles = {{0, 1, 2}};
            const StressScene sc = coverage_scene("motion", m, W, W, S, PatternKind::grid);
            const RenderResult r = render_scene(sc);
            const CoverageComparison c = compare_coverage(sc, r);
            mismatches += c.mismatches;
            samples += c.samples;
            std::vector<std::uint8_t> cov(r.framebuffer.color.size() / 4);
            for (std::size_t i = 0; i < cov.size(); ++i) cov[i] = r.framebuffer.color[4 * i] != 0.0f;
            seq.push_back(std::move(cov));
        }
        // A sample enters through the leading edges and leaves through the trailing one at most once.
        for (std::size_t i = 0; i < seq[0].size(); ++i) {
            int entries = 0, exits = 0;
            for (int k = 1; k < steps; ++k) {
                entries += !seq[k - 1][i] && seq[k][i];
                exits += seq[k - 1][i] && !seq[k][i];
            }
            changes += entries + exits;
            non_monotonic += entries > 1 || exits > 1 || (entries == 1 && exits == 1 && seq[0][i]);  // in, out, in again
        }
    }
    row.tried = "a 7x9 px triangle moved " + std::to_string(steps) + " steps of 1/256 px along x, y and the diagonal, 16x16 px, S=16";
    row.figure = count(mismatches) + " of " + count(samples) + " samples differ from the exact reference; " +
                 count(non_monotonic) + " samples change more than once each way (" + count(changes) + " changes in all)";
    row.bound = "0 differences, 0 non-monotonic samples";
    row.pass = mismatches == 0 && non_monotonic == 0 && changes > 0;
    return {row};
}

}  // namespace mipraster
