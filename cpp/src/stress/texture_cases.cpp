// Stress cases on texturing: 6 grazing planes, 7 extreme derivatives and uv magnitudes,
// 9 texture sizes and wrap modes at the borders.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "mipraster/stress/stress_cases.hpp"
#include "mipraster/stress/clip_ray_cast.hpp"
#include "mipraster/stress/texture_reference.hpp"
#include "mipraster/texture/sample.hpp"
#include "pipeline_probe.hpp"
#include "stress_util.hpp"

namespace mipraster {

using namespace stress;

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

bool finite4(const glm::vec4& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w); }

// Spacing of floats at |x| (one ulp).
double float_spacing(double x) {
    const float f = static_cast<float>(std::fabs(x));
    return double(std::nextafter(f, std::numeric_limits<float>::infinity())) - double(f);
}

}  // namespace

// ---- 6. Grazing textures -------------------------------------------------------------------------

std::vector<StressRow> stress_grazing_texture(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 6;
    row.name = "grazing textures";
    const int W = full ? 256 : 64, sub = full ? 16 : 8;
    std::uint64_t nonfinite = 0, non_monotonic = 0, unclamped = 0, lookups = 0, monotonic_steps = 0;
    double worst_mean_aniso = 0.0;
    bool aniso_not_worse = true;
    for (const double angle : {80.0, 89.0, 89.9, 89.99}) {
        const StressScene sc = grazing_scene(angle, W, W, 1);
        const Draw& draw = sc.draws[0];
        const Mesh& mesh = *sc.meshes[0];
        const glm::dmat4 mvp = sc.camera.projection * sc.camera.view * draw.model;
        std::vector<glm::dvec4> clip;
        for (const glm::vec3& p : mesh.positions) clip.push_back(mvp * glm::dvec4(glm::dvec3(p), 1.0));
        TextureView view(draw.texture);
        const TextureLevel& level0 = view.level(0);
        const Sampler aniso = draw.sampler, iso = Sampler::from_filter_name("trilinear");
        Sampler ref_sampler = aniso;  // wrap modes of the draw
        std::vector<double> lod(static_cast<std::size_t>(W) * W, kNan);
        // The footprint reference: the bilinear level-0 texture averaged over the pixel's square,
        // sub×sub points each ray-cast onto the plane y = 0 in double.
        const glm::dmat4 inv_view = glm::inverse(sc.camera.view);
        const glm::dvec3 eye(inv_view[3]);
        const double tan_half = std::tan(0.5 * 60.0 * 3.14159265358979323846 / 180.0);
        double err_aniso = 0.0, err_iso = 0.0;
        std::uint64_t n_ref = 0;
        probe_samples(clip, mesh.triangles, mesh.uvs, W, W, make_sample_pattern(PatternKind::center, 1),
                      DepthConvention::reverse_z, Interpolation::perspective, [&](const ProbeSample& q) {
                          const glm::vec2 uv(q.uv.uv), dx(q.uv.dx), dy(q.uv.dy);
                          const double li = texture_lod(view, iso, dx, dy), la = texture_lod(view, aniso, dx, dy);
                          const glm::vec4 ca = sample_texture(view, aniso, uv, dx, dy), ci = sample_texture(view, iso, uv, dx, dy);
                          ++lookups;
                          nonfinite += !std::isfinite(li) + !std::isfinite(la) + !finite4(ca) + !finite4(ci) +
                                       !std::isfinite(q.uv.dx.x + q.uv.dx.y + q.uv.dy.x + q.uv.dy.y);
                          lod[static_cast<std::size_t>(q.y) * W + q.x] = li;
                          // Anisotropy is clamped: λ is at least log2(Pmax / max_anisotropy).
                          const double pmax = std::max(glm::length(glm::dvec2(dx) * glm::dvec2(view.width(), view.height())),
                                                       glm::length(glm::dvec2(dy) * glm::dvec2(view.width(), view.height())));
                          const double floor_lod = std::clamp(std::log2(pmax / aniso.max_anisotropy), 0.0, double(view.level_count() - 1));
                          unclamped += la < floor_lod - 1e-5 || la > li + 1e-9;
                          // Footprint reference.
                          double ref = 0.0;
                          for (int b = 0; b < sub; ++b)
                              for (int a = 0; a < sub; ++a) {
                                  const double xn = screen_to_ndc_x(q.x + (a + 0.5) / sub, W), yn = screen_to_ndc_y(q.y + (b + 0.5) / sub, W);
                                  const glm::dvec3 d = glm::dmat3(inv_view) * glm::dvec3(xn * tan_half, yn * tan_half, -1.0);
                                  if (!(d.y < 0.0)) return;  // sub-point above the horizon
                                  const glm::dvec3 p = eye + (-eye.y / d.y) * d;
                                  if (std::fabs(p.x) > 1e6 || p.z < -1e6 || p.z > 0.0) return;  // past the plane's edge
                                  ref += reference_lookup(level0, p.x / 4.0, -p.z / 4.0, TexelFilter::linear, ref_sampler).r;
                              }
                          ref /= sub * sub;
                          err_aniso += std::fabs(ca.r - ref);
                          err_iso += std::fabs(ci.r - ref);
                          ++n_ref;
                      });
        // λ along the centre column, from the bottom row up to the horizon, never decreases.
        const int x = W / 2;
        for (int y = W - 1; y > 0; --y) {
            const double below = lod[static_cast<std::size_t>(y) * W + x], above = lod[static_cast<std::size_t>(y - 1) * W + x];
            if (std::isnan(below) || std::isnan(above)) continue;
            ++monotonic_steps;
            non_monotonic += above < below - 1e-9;
        }
        const double mean_a = n_ref ? err_aniso / n_ref : 0.0, mean_i = n_ref ? err_iso / n_ref : 0.0;
        worst_mean_aniso = std::max(worst_mean_aniso, mean_a);
        aniso_not_worse = aniso_not_worse && mean_a <= mean_i + 1e-9;
        row.details.push_back(fmt(angle, 6) + " deg: mean |error| vs the box footprint: anisotropic " + fmt(mean_a) +
                              ", trilinear " + fmt(mean_i) + " over " + count(n_ref) + " pixels; largest lambda " + fmt(*std::max_element(lod.begin(), lod.end(), [](double a, double b) {
                                  return std::isnan(a) || (!std::isnan(b) && a < b);
                              })));
    }
    row.tried = "a checker plane (64^2 texels, repeat) at 80, 89, 89.9, 89.99 deg to the view, " + std::to_string(W) +
                "^2, anisotropic 16x and trilinear through the pipeline's uv and analytic derivatives";
    row.figure = count(nonfinite) + " non-finite of " + count(lookups) + " lookups; " + count(non_monotonic) + " of " +
                 count(monotonic_steps) + " steps towards the horizon lower lambda; " + count(unclamped) +
                 " anisotropic lambdas outside [log2(Pmax/16), isotropic]; mean |error| vs box footprint " + fmt(worst_mean_aniso) +
                 " at worst";
    row.bound = "0 non-finite, 0 decreasing, 0 unclamped; anisotropic error <= trilinear's at every angle";
    row.pass = nonfinite == 0 && non_monotonic == 0 && unclamped == 0 && aniso_not_worse && lookups > 0 && monotonic_steps > 0;
    return {row};
}

// ---- 7. Derivatives and uv magnitude -------------------------------------------------------------

std::vector<StressRow> stress_derivatives(StressSize size) {
    const bool full = size == StressSize::full;
    std::vector<StressRow> rows;
    {
        // 7a: a constant texture must come back unchanged for every footprint (DESIGN.md 2.6).
        StressRow row;
        row.number = 7;
        row.name = "extreme derivatives";
        const int w = 37, h = 23;
        const glm::vec4 value(0.25f, 0.5f, 0.75f, 1.0f);
        TextureLevel level(w, h);
        for (glm::vec4& t : level.texels) t = value;
        const Texture tex(std::move(level), "constant 37x23");
        TextureView view(tex);
        const double inf = std::numeric_limits<double>::infinity(), big = 1e30, tiny = 1e-40;
        const std::vector<std::pair<glm::dvec2, glm::dvec2>> derivs = {
            {{0, 0}, {0, 0}},       {{inf, 0}, {0, inf}},  {{kNan, kNan}, {kNan, kNan}}, {{inf, 0}, {0, kNan}},
            {{big, 0}, {0, tiny}},  {{tiny, 0}, {0, 0}},   {{-inf, inf}, {inf, -inf}},   {{1, 0}, {0, 0}},
            {{big, big}, {big, big}}, {{0, kNan}, {0, 0}}, {{1e-3, 0}, {0, 1e3}},        {{-1, 2}, {kNan, inf}}};
        const std::vector<glm::dvec2> uvs = {{0.3, 0.7}, {0, 0}, {1, 1}, {-1e8, 1e8}, {1e30, -1e30}, {-0.5, 2.5}};
        const char* filters[] = {"nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"};
        std::uint64_t lookups = 0, wrong = 0, bad_lod = 0;
        for (const char* f : filters)
            for (const WrapMode wrap : {WrapMode::repeat, WrapMode::clamp, WrapMode::mirror}) {
                Sampler s = Sampler::from_filter_name(f);
                s.wrap_u = s.wrap_v = wrap;
                for (const auto& [dx, dy] : derivs) {
                    const double lambda = texture_lod(view, s, glm::vec2(dx), glm::vec2(dy));
                    bad_lod += !std::isfinite(lambda) || lambda < 0.0 || lambda > view.level_count() - 1;
                    for (const glm::dvec2& uv : uvs) {
                        const glm::vec4 c = sample_texture(view, s, glm::vec2(uv), glm::vec2(dx), glm::vec2(dy));
                        ++lookups;
                        wrong += c != value;
                    }
                }
            }
        // A non-finite uv returns the border colour.
        std::uint64_t border_wrong = 0;
        Sampler b = Sampler::from_filter_name("anisotropic");
        b.border_color = glm::vec4(0.1f, 0.2f, 0.3f, 0.4f);
        for (const glm::dvec2& uv : {glm::dvec2(kNan, 0.5), glm::dvec2(0.5, inf), glm::dvec2(-inf, kNan)})
            for (const auto& [dx, dy] : derivs) {
                ++lookups;
                border_wrong += sample_texture(view, b, glm::vec2(uv), glm::vec2(dx), glm::vec2(dy)) != b.border_color;
            }
        row.tried = std::to_string(derivs.size()) + " derivative pairs (zero, +-inf, NaN, mixed, 1e30, 1e-40) x 6 uvs "
                    "(up to 1e30) x 6 filters x 3 wraps on a constant 37x23 texture; non-finite uvs";
        row.figure = count(wrong + border_wrong) + " of " + count(lookups) + " lookups not the constant (or border); " +
                     count(bad_lod) + " lambdas non-finite or outside [0, levels-1]";
        row.bound = "0 and 0";
        row.pass = wrong == 0 && border_wrong == 0 && bad_lod == 0;
        rows.push_back(row);
    }
    {
        // 7b: uv far from 0 with repeat wrap. Mesh uvs are float: their spacing at |u| is lost
        // before any interpolation — the inherent limit, measured here through the renderer.
        StressRow row;
        row.number = 7;
        row.name = "uv precision at large |uv| (repeat)";
        const int W = 64, H = 4, n = 64;
        std::vector<float> ramp(n);
        for (int i = 0; i < n; ++i) ramp[i] = float(i) / n;
        const Texture tex = Texture::from_float(ramp.data(), n, 1, 1, true, "ramp 64x1");
        bool within = true;
        std::string figure;
        const std::vector<double> mags = full ? std::vector<double>{0, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, -1e8, 1e9}
                                              : std::vector<double>{0, 1e4, 1e6, 1e7, 1e8, -1e8};
        for (const double M : mags) {
            auto m = std::make_shared<Mesh>();
            m->positions = {{0.0f, 0.0f, 0.0f}, {W * 256.0f, 0.0f, 0.0f}, {W * 256.0f, H * 256.0f, 0.0f}, {0.0f, H * 256.0f, 0.0f}};
            const float u0 = float(M), u1 = float(M + 1.0);
            m->uvs = {{u0, 0.0f}, {u1, 0.0f}, {u1, 1.0f}, {u0, 1.0f}};
            m->triangles = {{0, 1, 2}, {0, 2, 3}};
            StressScene sc = coverage_scene("uv " + fmt(M), m, W, H, 1);
            sc.draws[0].state.blend = BlendMode::replace;
            sc.draws[0].texture = tex;
            sc.draws[0].sampler = Sampler::from_filter_name("nearest");
            const RenderResult r = render_scene(sc);
            // Texel index error (circular) at each pixel of the first row: intended texel is x.
            int worst = 0;
            for (int x = 0; x < W; ++x) {
                const double v = r.color.at(x, 0, 0);
                const int i = std::isfinite(v) ? static_cast<int>(std::lround(v * n)) : -1000;
                const int d = std::abs(i - x) % n;
                worst = std::max(worst, i < 0 ? n : std::min(d, n - d));
            }
            // Inherent: the vertex uvs and the sampler's float uv each round by ≤ ½ spacing.
            const double allowed = std::min(double(n / 2), std::floor(n * float_spacing(M + 1.0) + 0.5));
            within = within && worst <= allowed;
            row.details.push_back("|u| = " + fmt(M) + ": float spacing " + fmt(float_spacing(M + 1.0)) + " periods, worst texel error " +
                                  std::to_string(worst) + " of 64 (allowed " + fmt(allowed) + ")");
            figure += (figure.empty() ? "" : ", ") + fmt(M) + ": " + std::to_string(worst);
        }
        row.tried = "a 64 px quad spanning one period of a 64-texel ramp (nearest, repeat) with uv offset by 0 .. +-1e8";
        row.figure = "worst texel error by offset: " + figure + " (of 64; 32 = content lost)";
        row.bound = "<= 64 x the float spacing of the uvs (the float input's own rounding; 0 up to 1e4)";
        row.pass = within;
        rows.push_back(row);
    }
    return rows;
}

// ---- 9. Texture sizes and wrap modes -------------------------------------------------------------

std::vector<StressRow> stress_texture_sizes(StressSize size) {
    const bool full = size == StressSize::full;
    StressRow row;
    row.number = 9;
    row.name = "texture sizes and borders";
    std::vector<std::pair<int, int>> sizes = {{1, 1}, {1, 7}, {7, 1}, {3, 5}, {37, 23}, {256, 256}};
    sizes.push_back(full ? std::make_pair(16384, 16384) : std::make_pair(2048, 2048));
    double worst = 0.0, worst_mean = 0.0;
    std::uint64_t lookups = 0, bad_sizes = 0, nonfinite = 0;
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (const auto& [w, h] : sizes) {
        TextureLevel level(w, h);
        const bool big = std::size_t(w) * h > 1000000;
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i)
                level.at(i, j) = big ? glm::vec4(float(((i >> 7) + (j >> 7)) & 1), float(i & 255) / 255.0f, float(j & 255) / 255.0f, 1.0f)
                                     : glm::vec4(unit(rng), unit(rng), unit(rng), unit(rng));
        const Texture tex(std::move(level), "stress " + std::to_string(w) + "x" + std::to_string(h));
        TextureView view(tex);
        const TextureLevel& l0 = view.level(0);
        // Lookups at and around the borders, exact texel edges and centres, far outside.
        const std::vector<double> us = {0.0, 1.0, -1e-7, 1.0 + 1e-7, 0.5 / w, -0.5 / w, 1.0 - 0.5 / w, 1.0 + 0.5 / w,
                                        1.0 / w, -3.25, 7.9, 0.999999, 1e-3, -1.0 / w};
        const std::vector<double> vs = {0.0, 1.0, -1e-7, 1.0 + 1e-7, 0.5 / h, -0.5 / h, 1.0 - 0.5 / h, 1.0 + 0.5 / h,
                                        1.0 / h, -2.75, 5.1, 0.999999, 1e-3, -1.0 / h};
        double here = 0.0;
        for (const WrapMode wu : {WrapMode::repeat, WrapMode::clamp, WrapMode::mirror, WrapMode::border})
            for (const WrapMode wv : {WrapMode::repeat, WrapMode::clamp, WrapMode::mirror, WrapMode::border})
                for (const TexelFilter f : {TexelFilter::nearest, TexelFilter::linear}) {
                    Sampler s;
                    s.mag_filter = s.min_filter = f;
                    s.mip_filter = MipFilter::none;
                    s.wrap_u = wu;
                    s.wrap_v = wv;
                    s.border_color = glm::vec4(0.2f, 0.4f, 0.6f, 0.8f);
                    for (const double u : us)
                        for (const double v : vs) {
                            const glm::vec2 uv(static_cast<float>(u), static_cast<float>(v));
                            const glm::vec4 got = sample_texture(view, s, uv, glm::vec2(0.0f), glm::vec2(0.0f));
                            const glm::dvec4 want = reference_lookup(l0, double(uv.x), double(uv.y), f, s);
                            ++lookups;
                            nonfinite += !finite4(got);
                            for (int c = 0; c < 4; ++c) here = std::max(here, std::fabs(double(got[c]) - want[c]));
                        }
                }
        // Mip levels: sizes by definition and the mean kept at every level.
        double mean0[4] = {0, 0, 0, 0}, mean_err = 0.0;
        int levels = view.level_count();
        const int expected_levels = [&] {
            int n = 1, a = w, b = h;
            while (a > 1 || b > 1) {
                a = std::max(1, a / 2);
                b = std::max(1, b / 2);
                ++n;
            }
            return n;
        }();
        bad_sizes += levels != expected_levels;
        for (int k = 0; k < levels; ++k) {
            const TextureLevel& lk = view.level(k);
            bad_sizes += lk.width != std::max(1, w >> k) || lk.height != std::max(1, h >> k);
            double sum[4] = {0, 0, 0, 0};
            for (const glm::vec4& t : lk.texels)
                for (int c = 0; c < 4; ++c) sum[c] += t[c];
            for (int c = 0; c < 4; ++c) {
                const double mean = sum[c] / double(lk.texels.size());
                if (k == 0) mean0[c] = mean;
                mean_err = std::max(mean_err, std::fabs(mean - mean0[c]));
            }
        }
        worst = std::max(worst, here);
        worst_mean = std::max(worst_mean, mean_err);
        row.details.push_back(std::to_string(w) + "x" + std::to_string(h) + ": " + std::to_string(levels) +
                              " levels, max lookup error " + fmt(here) + ", max level-mean drift " + fmt(mean_err));
    }
    row.tried = "textures 1x1, 1x7, 7x1, 3x5, 37x23, 256^2, " + std::string(full ? "16384^2" : "2048^2") +
                ": nearest and bilinear at 14x14 border uvs in all 16 wrap-mode pairs; every mip level";
    row.figure = "max |lookup - reference| " + fmt(worst) + " over " + count(lookups) + " lookups; " + count(bad_sizes) +
                 " wrong level sizes; max drift of a level's mean " + fmt(worst_mean);
    row.bound = "lookups <= 1e-6, 0 wrong sizes, mean drift <= 1e-5";
    row.pass = worst <= 1e-6 && bad_sizes == 0 && worst_mean <= 1e-5 && nonfinite == 0;
    return {row};
}

}  // namespace mipraster
