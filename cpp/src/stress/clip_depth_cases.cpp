// Stress cases on clipping, depth and interpolation, against the double-precision clip-space ray
// cast: 4 near plane, 5 depth ordering, 11 interpolation far from the camera.
#include <algorithm>
#include <cmath>
#include <map>

#include <glm/gtc/matrix_transform.hpp>

#include "mipraster/stress/clip_ray_cast.hpp"
#include "mipraster/stress/stress_cases.hpp"
#include "pipeline_probe.hpp"
#include "stress_util.hpp"

namespace mipraster {

using namespace stress;

namespace {

bool finite2(const glm::dvec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

// Whether the ray-cast coverage at (sx, sy) px flips within `band` px in any of 8 directions.
bool flips_near(const std::array<glm::dvec4, 3>& p, double sx, double sy, double band, int W, int H, bool reverse_z,
                bool at_centre) {
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            if (ray_cast_clip(p, screen_to_ndc_x(sx + dx * band, W), screen_to_ndc_y(sy + dy * band, H), reverse_z).hit != at_centre)
                return true;
    return false;
}

}  // namespace

// ---- 4. Near plane -------------------------------------------------------------------------------

std::vector<StressRow> stress_near_plane(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 4;
    row.name = "near plane";
    const int W = full ? 256 : 64, S = 4;
    const double band = 2.0 / 256.0;  // px: snapping of the clipped vertices plus the clip's rounding
    const ClipScene sc = near_plane_scene(W, S);
    std::uint64_t differences = 0, unexplained = 0, covered = 0, nonfinite = 0, samples = 0, values = 0;
    for (std::size_t t = 0; t < sc.triangles.size(); ++t) {
        const glm::uvec3 tri = sc.triangles[t];
        const std::array<glm::dvec4, 3> p = {sc.clip[tri[0]], sc.clip[tri[1]], sc.clip[tri[2]]};
        const Visibility vis = rasterize({p[0], p[1], p[2]}, {glm::uvec3(0, 1, 2)}, sc.settings);
        std::uint64_t here_diff = 0, here_covered = 0;
        for (int y = 0; y < W; ++y)
            for (int x = 0; x < W; ++x)
                for (int s = 0; s < vis.samples; ++s) {
                    const std::size_t i = (static_cast<std::size_t>(y) * W + x) * vis.samples + s;
                    const double sx = x + vis.pattern.x[s] / 256.0, sy = y + vis.pattern.y[s] / 256.0;
                    const bool want = ray_cast_clip(p, screen_to_ndc_x(sx, W), screen_to_ndc_y(sy, W), false).hit;
                    const bool got = vis.triangle_id[i] == 0;
                    ++samples;
                    here_covered += want;
                    if (got) {
                        values += 3;
                        nonfinite += !std::isfinite(vis.depth[i]) + !std::isfinite(vis.barycentrics[2 * i]) +
                                     !std::isfinite(vis.barycentrics[2 * i + 1]);
                    }
                    if (got != want) {
                        ++here_diff;
                        unexplained += !flips_near(p, sx, sy, band, W, W, false, want);
                    }
                }
        differences += here_diff;
        covered += here_covered;
        row.details.push_back("triangle " + std::to_string(t) + ": " + count(here_covered) + " samples visible, " +
                              count(here_diff) + " differ from the ray cast");
    }
    // Attributes and analytic derivatives through the pipeline's own stages: uv = the vertex's
    // position in a 2×2 pattern, interpolated perspective-correct.
    std::vector<glm::vec2> uvs;
    for (std::size_t i = 0; i < sc.clip.size(); ++i) uvs.push_back(glm::vec2(float(i % 3 == 1), float(i % 3 == 2)));
    std::uint64_t probed = 0;
    probe_samples(sc.clip, sc.triangles, uvs, W, W, make_sample_pattern(PatternKind::rotated, 4),
                                        DepthConvention::opengl, Interpolation::perspective, [&](const ProbeSample& q) {
                                            ++probed;
                                            values += 10;
                                            nonfinite += !std::isfinite(q.depth) + !std::isfinite(q.weights.x) +
                                                         !std::isfinite(q.weights.y) + !std::isfinite(q.weights.z) +
                                                         2 * !finite2(q.uv.uv) + 2 * !finite2(q.uv.dx) + 2 * !finite2(q.uv.dy);
                                        });
    row.tried = std::to_string(sc.triangles.size()) + " triangles in OpenGL clip space: w = 1e-12, 0, < 0 (one and two "
                "vertices), all behind, grazing the near plane, w = 1e-300, edge-on, a vertex 1e20 behind, w ~ 1e46; " +
                std::to_string(W) + "^2, S=4";
    row.figure = count(differences - unexplained) + " of " + count(samples) + " samples differ from the ray cast within " +
                 "2/256 px of its edge, " + count(unexplained) + " beyond; " + count(nonfinite) + " non-finite of " +
                 count(values) + " depth, weight, uv and derivative values (" + count(probed) + " samples probed)";
    row.bound = "0 differences beyond 2/256 px, 0 non-finite values";
    row.pass = unexplained == 0 && nonfinite == 0 && covered > 0 && probed > 0;
    return {row};
}

// ---- 5. Depth ------------------------------------------------------------------------------------

std::vector<StressRow> stress_depth(StressSize size) {
    const bool full = size == StressSize::full;
    const int N = full ? 64 : 32;
    const double near = 1e-3;
    const std::vector<double> seps = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
    const std::vector<double> dists = full ? std::vector<double>{1e-2, 1e-1, 1, 10, 1e2, 1e3, 1e4, 1e5}
                                           : std::vector<double>{1e-2, 1, 1e2, 1e5};
    const std::vector<double> fars = {1e3 * near, 1e6 * near, 1e8 * near, kInfiniteFar};
    // fraction[convention][far][sep][dist]: share of covered samples showing the nearer quad,
    // over both drawing orders.
    std::map<std::tuple<int, double, double, double>, double> fraction;
    for (int conv = 0; conv < 2; ++conv)
        for (double far : fars)
            for (double sep : seps)
                for (double d : dists) {
                    if (d * 1.3 >= far) continue;  // the tilted quads reach 1.3·d
                    std::uint64_t nearer = 0, total = 0;
                    for (bool near_first : {true, false}) {
                        const RenderResult r = render_scene(depth_scene(conv == 0, near, far, d, sep, near_first, N));
                        for (std::size_t i = 0; i < r.color.pixels.size(); i += 4) {
                            nearer += r.color.pixels[i + 1] == 1.0f;
                            total += r.color.pixels[i + 3] == 1.0f;
                        }
                    }
                    // −1: nothing drew (the depth rounded to the clear value and failed the test).
                    fraction[{conv, far, sep, d}] = total ? double(nearer) / double(total) : -1.0;
                }
    std::vector<StressRow> rows;
    double rz_min_contract = 1.0, gl_min_contract = 1.0;
    bool rz_never_worse = true;
    for (int conv = 0; conv < 2; ++conv) {
        StressRow row;
        row.number = 5;
        row.name = conv == 0 ? "depth, reverse-Z (library cameras)" : "depth, OpenGL matrices";
        for (double far : fars) {
            std::string line = "far = " + (std::isinf(far) ? std::string("inf") : fmt(far / near) + " x near") + ":";
            for (double sep : seps) {
                line += "  sep " + fmt(sep) + " [";
                for (double d : dists) {
                    auto it = fraction.find({conv, far, sep, d});
                    if (it == fraction.end()) continue;
                    line += (line.back() == '[' ? "" : " ") + (it->second < 0 ? std::string("none") : fmt(it->second, 3));
                    if (sep >= 1e-6 && std::isinf(far)) (conv == 0 ? rz_min_contract : gl_min_contract) =
                        std::min(conv == 0 ? rz_min_contract : gl_min_contract, std::max(0.0, it->second));
                    if (conv == 1 && it->second > fraction[{0, far, sep, d}] + 1e-12) rz_never_worse = false;
                    if (conv == 0 && it->second < 0) rz_never_worse = false;  // reverse-Z always draws
                }
                line += "]";
            }
            row.details.push_back(line);
        }
        row.details.insert(row.details.begin(), "fraction correctly ordered per far plane, separation [distances " +
                                                    fmt(dists.front()) + " .. " + fmt(dists.back()) + "], near = 1e-3");
        auto at = [&](double far, double sep, double d) {
            const double f = fraction[{conv, far, sep, d}];
            return f < 0 ? std::string("none drawn") : fmt(f, 3);
        };
        row.tried = "two 30-degree-tilted quads at relative separations 1e-3..1e-7, distances 1e-2..1e5, near 1e-3, far " +
                    std::string("1e3 x near .. infinite, both drawing orders, ") + std::to_string(N) + "^2";
        if (conv == 0) {
            row.figure = "min fraction ordered at separations >= 1e-6, infinite far: " + fmt(rz_min_contract, 4) +
                         "; at 1e-7, d = 1: " + at(kInfiniteFar, 1e-7, 1.0) + ", d = 1e5: " + at(kInfiniteFar, 1e-7, 1e5);
            row.bound = "1.0 at separations >= 1e-6 for distances 1e-2..1e5 (DESIGN.md 2.3)";
            row.pass = rz_min_contract == 1.0;
        } else {
            row.figure = "infinite far, separation 1e-6, d = 1e-2 / 1 / 1e2 / 1e5: " + at(kInfiniteFar, 1e-6, 1e-2) + " / " +
                         at(kInfiniteFar, 1e-6, 1.0) + " / " + at(kInfiniteFar, 1e-6, 1e2) + " / " +
                         at(kInfiniteFar, 1e-6, 1e5) + "; far 1e6 x near, separation 1e-4, d = 1e2: " +
                         at(1e6 * near, 1e-4, 1e2) + " (0.5 = equal depths, first drawn wins)";
            row.bound = "never better than reverse-Z at the same far, separation and distance (why reverse-Z is the default)";
            row.pass = rz_never_worse;
        }
        rows.push_back(row);
    }
    return rows;
}

// ---- 11. Interpolation ---------------------------------------------------------------------------

std::vector<StressRow> stress_interpolation(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 11;
    row.name = "interpolation vs ray cast";
    const int W = full ? 256 : 96;
    const double near = 1e-2;
    // One px of snapping-induced change: the bound per sample is the change of the exact weights
    // over 2/256 px (vertices move ≤ √2/512 px each when snapped), plus float rounding.
    const double band = 2.0 / 256.0;
    const glm::dmat4 proj = perspective(0.8, 1.0, near);
    double max_weight_error = 0.0, max_depth_rel = 0.0, max_ratio = 0.0;
    std::uint64_t samples = 0, over = 0, nonfinite = 0;
    for (const double k : {10.0, 1e2, 1e3, 1e4, 1e5, 1e6}) {
        const double d = k * near;
        double here_weight = 0.0, here_depth = 0.0;
        for (const double tilt : {30.0, 60.0, 85.0}) {
            // A square of side d·0.6 at distance d, tilted about x, centred on the view axis.
            glm::dmat4 model = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -d));
            model = glm::rotate(model, tilt * 3.14159265358979323846 / 180.0, glm::dvec3(1.0, 0.0, 0.0));
            model = glm::scale(model, glm::dvec3(0.3 * d));
            const glm::dmat4 mvp = proj * model;
            const glm::dvec4 c[4] = {mvp * glm::dvec4(-1, -1, 0, 1), mvp * glm::dvec4(1, -1, 0, 1),
                                     mvp * glm::dvec4(1, 1, 0, 1), mvp * glm::dvec4(-1, 1, 0, 1)};
            const std::vector<glm::dvec4> clip = {c[0], c[1], c[2], c[3]};
            const std::vector<glm::uvec3> tris = {{0, 1, 2}, {0, 2, 3}};
            RasterizeSettings rs;
            rs.width = rs.height = W;
            rs.samples = 1;
            rs.threads = 2;
            rs.depth_convention = DepthConvention::reverse_z;
            const Visibility vis = rasterize(clip, tris, rs);
            for (int y = 0; y < W; ++y)
                for (int x = 0; x < W; ++x) {
                    const std::size_t i = static_cast<std::size_t>(y) * W + x;
                    const int t = vis.triangle_id[i];
                    if (t < 0) continue;
                    const std::array<glm::dvec4, 3> p = {clip[tris[t][0]], clip[tris[t][1]], clip[tris[t][2]]};
                    const double sx = x + 0.5, sy = y + 0.5;
                    auto at = [&](double ox, double oy) {
                        // The weights on the triangle's plane, even just outside it (no hit test needed).
                        return ray_cast_clip(p, screen_to_ndc_x(sx + ox, W), screen_to_ndc_y(sy + oy, W), true);
                    };
                    const ClipHit h = at(0, 0);
                    if (!(h.w > 0.0)) continue;
                    const glm::dvec3 got(1.0 - vis.barycentrics[2 * i] - vis.barycentrics[2 * i + 1], vis.barycentrics[2 * i],
                                         vis.barycentrics[2 * i + 1]);
                    if (!std::isfinite(got.y) || !std::isfinite(got.z) || !std::isfinite(vis.depth[i])) {
                        ++nonfinite;
                        continue;
                    }
                    double allowed_w = 0.0, allowed_z = 0.0;
                    for (const glm::dvec2 o : {glm::dvec2(band, 0), glm::dvec2(-band, 0), glm::dvec2(0, band), glm::dvec2(0, -band)}) {
                        const ClipHit q = at(o.x, o.y);
                        for (int j = 0; j < 3; ++j) allowed_w = std::max(allowed_w, std::fabs(q.weights[j] - h.weights[j]));
                        allowed_z = std::max(allowed_z, std::fabs(q.window_depth - h.window_depth));
                    }
                    // Float storage of the weights and depth: a few ulps.
                    allowed_w += 4e-7;
                    allowed_z += 4e-7 * h.window_depth;
                    double err_w = 0.0;
                    for (int j = 1; j < 3; ++j) err_w = std::max(err_w, std::fabs(got[j] - h.weights[j]));
                    const double err_z = std::fabs(double(vis.depth[i]) - h.window_depth);
                    here_weight = std::max(here_weight, err_w);
                    here_depth = std::max(here_depth, err_z / h.window_depth);
                    max_ratio = std::max({max_ratio, err_w / allowed_w, err_z / allowed_z});
                    over += err_w > allowed_w || err_z > allowed_z;
                    ++samples;
                }
        }
        max_weight_error = std::max(max_weight_error, here_weight);
        max_depth_rel = std::max(max_depth_rel, here_depth);
        row.details.push_back("distance " + fmt(k) + " x near: max weight error " + fmt(here_weight) +
                              ", max depth relative error " + fmt(here_depth));
    }
    row.tried = "squares tilted 30, 60, 85 degrees at 10 .. 10^6 x near (reverse-Z, infinite far), " + std::to_string(W) +
                "^2; perspective-correct weights and depth vs the double ray cast at each pixel centre";
    row.figure = "max weight error " + fmt(max_weight_error) + " (relative to the attribute range), max depth relative error " +
                 fmt(max_depth_rel) + "; worst error / bound " + fmt(max_ratio) + " over " + count(samples) + " samples";
    row.bound = "per sample: the exact values' change over 2/256 px (vertex snapping) + float rounding; 0 non-finite";
    row.pass = over == 0 && nonfinite == 0 && samples > 0;
    return {row};
}

}  // namespace mipraster
