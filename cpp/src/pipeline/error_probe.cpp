#include "mipraster/pipeline/error_probe.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "mipraster/core/constants.hpp"
#include "mipraster/core/memory_limit.hpp"
#include "mipraster/core/splitmix.hpp"

namespace mipraster {

namespace {

// Distinct from any pattern seed a user is likely to pick, so the reference's samples are not the
// render's own (the estimate needs their errors independent).
constexpr std::uint64_t kReferenceSeed = 0x9E3779B97F4A7C15ull;

void require_size(const Image& map, const Image& color, const char* name) {
    if (map.width != color.width || map.height != color.height || map.channels != 1)
        throw std::invalid_argument(std::string(name) + ": expected a " + std::to_string(color.width) + "x" +
                                    std::to_string(color.height) + "x1 map (the colour's size), got " + map.to_string());
}

// A uniform double in [0, 1) from the generator.
double uniform01(std::uint64_t& state) { return static_cast<double>(splitmix64(state) >> 11) * 0x1p-53; }

// Step 1: `pixels` draws, i.i.d. from p_i = ½/N + ½·g_i/Σg over the guide g, with no reference
// passes yet.
ProbeReference draw_probe_pixels(const Image& g, int pixels, std::uint64_t seed) {
    const std::size_t n_all = static_cast<std::size_t>(g.width) * g.height;
    ProbeReference r;
    r.width = g.width;
    r.height = g.height;
    r.seed = seed;
    double total = 0.0;
    for (const float v : g.pixels) total += v;
    std::vector<double> cdf(n_all);
    double running = 0.0;
    for (std::size_t i = 0; i < n_all; ++i) {
        running += total > 0.0 ? 0.5 / double(n_all) + 0.5 * g.pixels[i] / total : 1.0 / double(n_all);
        cdf[i] = running;
    }
    std::uint64_t state = seed;
    state = splitmix64(state) ^ ((std::uint64_t(std::uint32_t(g.width)) << 32) | std::uint32_t(g.height));
    state = splitmix64(state) ^ std::uint64_t(std::uint32_t(pixels));
    r.chosen.resize(static_cast<std::size_t>(pixels));
    for (std::uint32_t& c : r.chosen) {
        const std::size_t i = static_cast<std::size_t>(
            std::upper_bound(cdf.begin(), cdf.end(), uniform01(state) * running) - cdf.begin());
        c = static_cast<std::uint32_t>(std::min(i, n_all - 1));
    }
    r.distinct = r.chosen;
    std::sort(r.distinct.begin(), r.distinct.end());
    r.distinct.erase(std::unique(r.distinct.begin(), r.distinct.end()), r.distinct.end());
    // The probability of each draw, and where its pixel's reference is kept.
    r.probability.resize(r.chosen.size());
    r.slot.resize(r.chosen.size());
    for (std::size_t k = 0; k < r.chosen.size(); ++k) {
        const std::size_t i = r.chosen[k];
        r.probability[k] = (cdf[i] - (i ? cdf[i - 1] : 0.0)) / running;
        r.slot[k] = static_cast<std::size_t>(std::lower_bound(r.distinct.begin(), r.distinct.end(), r.chosen[k]) -
                                             r.distinct.begin());
    }
    r.mean.assign(r.distinct.size() * 3, 0.0);
    r.m2.assign(r.distinct.size() * 3, 0.0);
    return r;
}

// The estimate from what the passes gave so far.
struct Estimate {
    double mse = 0, mse_se = 0;  // the image's MSE and its standard error
    double reference_mse = 0;    // the reference's own MSE, weighted alike
};

}  // namespace

std::string ProbeReference::to_string() const {
    char out[160];
    std::snprintf(out, sizeof out, "ProbeReference(%zu draws, %zu pixels, %d passes of %d samples, %dx%d)", chosen.size(),
                  distinct.size(), passes, kProbeReferenceSpp, width, height);
    return out;
}

std::string ErrorProbe::to_string() const {
    char head[160], halves[48] = "";
    std::snprintf(head, sizeof head, "ErrorProbe(rmse%s%.4g \u00b1 %.2g, pixels=%d (%d distinct) at %d spp",
                  upper_bound ? "<=" : "=", rmse, standard_error, pixels, distinct_pixels, reference_spp);
    if (halves_rmse >= 0.0) std::snprintf(halves, sizeof halves, ", halves_rmse=%.4g", halves_rmse);
    char tail[128];
    std::snprintf(tail, sizeof tail, ", reference_rmse=%.3g, rendered_passes=%d, ms=%.2f)", reference_rmse,
                  rendered_passes, ms);
    return std::string(head) + halves + tail;
}

int probe_reference_passes(int spp) { return std::max(kProbeMinPasses, 2 * spp / 32); }

int default_probe_pixels(int width, int height, int spp) {
    const double budget = double(width) * height * spp / (4.0 * kProbeReferenceSpp * probe_reference_passes(spp));
    return static_cast<int>(std::min<double>(kProbeMaxPixels, std::max<double>(kProbeMinPixels, std::round(budget))));
}

Image error_guide(const Image& color, const Image* halves_map) {
    if (color.channels < 3) throw std::invalid_argument("color: expected 3 or 4 channels, got " + color.to_string());
    const int w = color.width, h = color.height;
    Image g(w, h, 1);
    // The largest mean over R, G, B of (half the step)² to a neighbour. In double, kept at most
    // the largest float: in float, colours of 10²⁰ squared to infinity, and the probe's draw
    // probabilities (guide / total) became NaN.
    const auto saturated = [](double v) {
        return static_cast<float>(std::min<double>(v, std::numeric_limits<float>::max()));
    };
    auto step = [&](int x0, int y0, int x1, int y1) {
        double s = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double d = double(color.at(x1, y1, c)) - color.at(x0, y0, c);
            s += d * d / 12.0;
        }
        g.at(x0, y0, 0) = std::max(g.at(x0, y0, 0), saturated(s));
        g.at(x1, y1, 0) = std::max(g.at(x1, y1, 0), saturated(s));
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (x + 1 < w) step(x, y, x + 1, y);
            if (y + 1 < h) step(x, y, x, y + 1);
        }
    if (halves_map) {
        require_size(*halves_map, color, "halves_map");
        // The squared map averaged over each 3×3 neighbourhood (zero outside the image).
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0.0;
                for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
                    for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u) {
                        const double m = halves_map->at(u, v, 0);
                        sum += m * m;
                    }
                g.at(x, y, 0) = saturated(g.at(x, y, 0) + sum / 9.0);
            }
    }
    return g;
}

std::vector<Draw> reference_draws(const std::vector<Draw>& draws) {
    std::vector<Draw> out = draws;
    const Sampler bilinear = Sampler::from_filter_name("bilinear");
    for (Draw& d : out) {
        if (!d.texture) continue;
        d.sampler.mag_filter = bilinear.mag_filter;
        d.sampler.min_filter = bilinear.min_filter;
        d.sampler.mip_filter = bilinear.mip_filter;
        d.sampler.footprint = bilinear.footprint;
    }
    return out;
}

ErrorProbe measure_error(const std::vector<Draw>& draws, const Camera& camera, const RenderSettings& settings,
                         const Image& color, const Image* halves_map, int pixels, std::uint64_t seed,
                         const Image* guide, ProbeReference* reuse) {
    const auto start = std::chrono::steady_clock::now();
    if (pixels < 1) throw std::invalid_argument("probe_pixels: expected a number of pixels >= 1, got " + std::to_string(pixels));
    if (color.channels < 3) throw std::invalid_argument("color: expected 3 or 4 channels, got " + color.to_string());
    if (color.width != settings.width || color.height != settings.height)
        throw std::invalid_argument("color: expected the render's " + std::to_string(settings.width) + "x" +
                                    std::to_string(settings.height) + " pixels, got " + color.to_string());
    if (halves_map) require_size(*halves_map, color, "halves_map");
    if (guide) require_size(*guide, color, "guide");
    const int w = color.width;
    const std::size_t n_all = static_cast<std::size_t>(w) * color.height;

    ErrorProbe probe;
    if (halves_map) {
        double sum = 0.0;
        for (const float m : halves_map->pixels) sum += double(m) * m;
        probe.halves_rmse = std::sqrt(sum / double(n_all));
    }

    if (reuse && !reuse->empty() && (reuse->width != w || reuse->height != color.height))
        throw std::invalid_argument("reuse: the probe's draws were made for a " + std::to_string(reuse->width) + "x" +
                                    std::to_string(reuse->height) + " image, got " + color.to_string());
    ProbeReference fresh;
    ProbeReference& r = reuse ? *reuse : fresh;
    if (r.empty()) {
        // Per draw: its pixel twice (chosen, distinct), its probability and slot, a pixel's running
        // mean and m2 (three channels each); per image pixel, the guide's cumulative sum.
        check_memory(static_cast<std::uint64_t>(pixels) * (2 * sizeof(std::uint32_t) + sizeof(double) +
                                                             sizeof(std::size_t) + 6 * sizeof(double)) +
                         n_all * sizeof(double),
                     "the error probe's " + std::to_string(pixels) + " probe_pixels");
        r = draw_probe_pixels(guide ? *guide : error_guide(color, halves_map), pixels, seed);
    }
    const std::vector<std::uint32_t>& chosen = r.chosen;
    const std::vector<std::uint32_t>& distinct = r.distinct;
    const std::vector<double>& p = r.probability;
    const std::vector<std::size_t>& slot = r.slot;
    std::vector<double>& mean = r.mean;
    std::vector<double>& m2 = r.m2;
    int& done = r.passes;
    const int reused_passes = done;

    // Step 2: reference passes of the listed pixels, folded into per-pixel running means and
    // sums of squared deviations (Welford) per channel.
    RenderSettings ref;
    ref.width = settings.width;
    ref.height = settings.height;
    ref.samples = kProbeReferenceSpp;
    ref.pattern = PatternKind::stratified;
    ref.anti_aliasing = AntiAliasing::ssaa;
    ref.threads = settings.threads;
    ref.clear_color = settings.clear_color;
    ref.derivatives = settings.derivatives;
    ref.debug_view = settings.debug_view;
    ref.pixels = distinct;
    std::vector<Draw> ref_draws;  // made only when a pass is to be rendered
    auto add_passes = [&](int passes) {
        if (done < passes && ref_draws.empty()) ref_draws = reference_draws(draws);
        for (; done < passes; ++done) {
            ref.pattern_seed = (kReferenceSeed + std::uint64_t(done)) ^ r.seed;
            const Image pass = render(ref_draws, camera, ref).color;
            for (std::size_t j = 0; j < distinct.size(); ++j)
                for (int c = 0; c < 3; ++c) {
                    const double x = pass.pixels[std::size_t(distinct[j]) * pass.channels + c];
                    double& m = mean[j * 3 + c];
                    const double delta = x - m;
                    m += delta / (done + 1);
                    m2[j * 3 + c] += delta * (x - m);
                }
        }
    };

    // Step 3: the unbiased MSE from the passes so far.
    auto estimate = [&]() {
        Estimate e;
        const double k_passes = done;
        double sum = 0.0, sum_sq = 0.0;
        for (std::size_t k = 0; k < chosen.size(); ++k) {
            const std::size_t i = chosen[k], j = slot[k];
            double diff2 = 0.0, own = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double d = double(color.pixels[i * color.channels + c]) - mean[j * 3 + c];
                diff2 += d * d / 3.0;
                own += m2[j * 3 + c] / (k_passes * (k_passes - 1.0)) / 3.0;  // the sample variance of the mean
            }
            const double weight = 1.0 / (double(n_all) * p[k]);
            const double term = (diff2 - own) * weight;
            sum += term;
            sum_sq += term * term;
            e.reference_mse += own * weight;
        }
        const double n = double(chosen.size());
        e.mse = sum / n;
        e.reference_mse /= n;
        e.mse_se = n > 1 ? std::sqrt(std::max(0.0, (sum_sq - n * e.mse * e.mse) / (n - 1.0)) / n)
                         : std::numeric_limits<double>::infinity();
        return e;
    };

    // Step 4: more passes while the error is unresolved and the reference's own error is what
    // hides it (not the few pixels drawn: more passes would not help that). A reused reference
    // starts with the passes it has.
    int passes = std::max(done, probe_reference_passes(settings.samples));
    add_passes(passes);
    Estimate e = estimate();
    auto hidden = [](const Estimate& x) {
        return !(x.mse > kProbeResolvedStandardErrors * x.mse_se) && x.reference_mse > std::max(x.mse, kProbeNegligibleMse);
    };
    while (hidden(e) && passes < kProbeMaxPasses) {
        passes = std::min(kProbeMaxPasses, 2 * passes);
        add_passes(passes);
        e = estimate();
    }

    probe.pixels = static_cast<int>(chosen.size());
    probe.distinct_pixels = static_cast<int>(distinct.size());
    probe.reference_spp = kProbeReferenceSpp * passes;
    probe.rendered_passes = passes - reused_passes;
    probe.reference_rmse = std::sqrt(std::max(0.0, e.reference_mse));
    if (hidden(e)) {
        probe.upper_bound = true;
        probe.rmse = std::sqrt(std::max(e.mse, 0.0) + kProbeResolvedStandardErrors * e.mse_se);
        probe.standard_error = std::sqrt(e.mse_se);
    } else {
        probe.rmse = std::sqrt(std::max(e.mse, 0.0));
        // The delta method where the RMSE is well above its noise; √(SE of the MSE) near 0.
        probe.standard_error = probe.rmse > 0.0 && e.mse_se < e.mse ? e.mse_se / (2.0 * probe.rmse) : std::sqrt(e.mse_se);
    }
    probe.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return probe;
}

void calibrate_error_map(Image& error_map, const ErrorProbe& probe) {
    if (!(probe.halves_rmse > 0.0)) return;
    const float scale = static_cast<float>(probe.rmse / probe.halves_rmse);
    for (float& v : error_map.pixels) v *= scale;
}

}  // namespace mipraster
