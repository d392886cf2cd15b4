// Stress case 12: the scenes of the other cases rendered with 1, 2 and 4 threads must give
// bit-identical samples (DESIGN.md 2.8), and the suite runner.
#include <cstring>

#include "mipraster/stress/stress_cases.hpp"
#include "stress_util.hpp"

namespace mipraster {

using namespace stress;

namespace {

// Values that differ bit for bit (NaNs with the same payload count as equal).
template <class Floats>
std::uint64_t differing(const Floats& a, const Floats& b) {
    if (a.size() != b.size()) return std::max(a.size(), b.size());
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(float)) != 0;
    return n;
}

template <class T>
std::uint64_t differing_ints(const std::vector<T>& a, const std::vector<T>& b) {
    if (a.size() != b.size()) return std::max(a.size(), b.size());
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
    return n;
}

}  // namespace

std::vector<StressRow> stress_determinism(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 12;
    row.name = "determinism";
    std::vector<StressScene> scenes;
    const int gw = full ? 1024 : 256;
    scenes.push_back(coverage_scene("watertight grid S=16",
                                    jittered_grid_mesh(gw / 4, gw / 8, -0.1 * gw, -0.1 * gw / 2, 1.1 * gw, 1.1 * gw / 2, false, 27),
                                    gw, gw / 2, 16));
    scenes.push_back(coverage_scene("slivers S=16", sliver_mesh(128, 128, 1e4, 1e-3, 90, 7), 128, 128, 16));
    scenes.push_back(coverage_scene("fan S=4", fan_mesh(64.5, 64.5, 50, 1000), 128, 128, 4, PatternKind::rotated));
    for (double angle : {89.0, 89.99}) {
        StressScene g = grazing_scene(angle, full ? 256 : 96, full ? 256 : 96, 4);
        g.settings.anti_aliasing = AntiAliasing::ssaa;
        scenes.push_back(g);
    }
    {
        StressScene d = depth_scene(false, 1e-3, 1e3, 1.0, 1e-7, true, 64);
        d.settings.keep_samples = true;
        scenes.push_back(d);
        StressScene e = depth_scene(true, 1e-3, kInfiniteFar, 1e5, 1e-7, false, 64);
        e.settings.keep_samples = true;
        scenes.push_back(e);
    }
    std::vector<ClipScene> clip_scenes = {near_plane_scene(full ? 256 : 64, 4), huge_scene(128, 1e9, 16, 5),
                                          huge_scene(128, 1e15, 16, 6)};
    std::uint64_t values = 0, differ = 0;
    for (const StressScene& sc : scenes) {
        std::vector<RenderResult> results;
        for (int threads : {1, 2, 4}) {
            StressScene t = sc;
            t.settings.threads = threads;
            t.settings.keep_samples = true;
            results.push_back(render_scene(t));
        }
        std::uint64_t here = 0;
        for (int k = 1; k < 3; ++k) {
            here += differing(results[0].framebuffer.color, results[k].framebuffer.color);
            here += differing(results[0].framebuffer.depth, results[k].framebuffer.depth);
            here += differing(results[0].color.pixels, results[k].color.pixels);
        }
        values += 2 * (results[0].framebuffer.color.size() + results[0].framebuffer.depth.size() + results[0].color.pixels.size());
        differ += here;
        row.details.push_back(sc.name + ": " + count(here) + " values differ");
    }
    for (const ClipScene& sc : clip_scenes) {
        std::vector<Visibility> results;
        for (int threads : {1, 2, 4}) {
            RasterizeSettings s = sc.settings;
            s.threads = threads;
            results.push_back(rasterize(sc.clip, sc.triangles, s));
        }
        std::uint64_t here = 0;
        for (int k = 1; k < 3; ++k) {
            here += differing_ints(results[0].triangle_id, results[k].triangle_id);
            here += differing(results[0].barycentrics, results[k].barycentrics);
            here += differing(results[0].depth, results[k].depth);
        }
        values += 2 * (results[0].triangle_id.size() + results[0].barycentrics.size() + results[0].depth.size());
        differ += here;
        row.details.push_back(sc.name + " (primitive layer): " + count(here) + " values differ");
    }
    row.tried = std::to_string(scenes.size() + clip_scenes.size()) +
                " scenes of cases 1-6 (grids, slivers, fan, grazing planes, depth, near plane, huge triangles) at 1, 2 and 4 threads";
    row.figure = count(differ) + " of " + count(values) + " sample values differ from the 1-thread render";
    row.bound = "0 (bit-identical)";
    row.pass = differ == 0 && values > 0;
    return {row};
}

std::vector<StressRow> run_stress_suite(StressSize size, const std::function<void(const StressRow&)>& on_row) {
    using Case = std::vector<StressRow> (*)(StressSize);
    const Case cases[] = {stress_watertight,      stress_slivers,         stress_huge_coordinates, stress_near_plane,
                          stress_depth,           stress_grazing_texture, stress_derivatives,      stress_degenerate,
                          stress_texture_sizes,   stress_subpixel_motion, stress_interpolation,    stress_determinism};
    std::vector<StressRow> rows;
    for (const Case c : cases)
        for (StressRow& r : c(size)) {
            if (on_row) on_row(r);
            rows.push_back(std::move(r));
        }
    return rows;
}

}  // namespace mipraster
