// mipraster_bench_texture — speed and accuracy of mipraster's texture filters, measured the way
// /work/shared/bench/anchor_oiio_texture.cpp measures OpenImageIO's TextureSystem, so the two
// can be put side by side (python -m mipraster.bench_texture does that).
//
//   mipraster_bench_texture OUT.json [--quick] [--n-timing N] [--n-acc M] [--reps R]
//                           [--filters a,b,...] [--footprints a,b,...] [--markdown PATH]
//
// Same as the anchor:
//  * textures: 1024² checker (10-texel squares) and zone plate 0.5 + 0.5·sin(π r²/1024), r in
//    texels from the centre, computed in double at texel centres and rounded to float; given to
//    mipraster as 1-channel float (expanded to RGBA = (v, v, v, 1)). Repeat wrap on both axes.
//  * footprints: derivative vectors in texels of level 0 (divided by 1024 for uv): mag_0.25px,
//    iso_8x8, aniso_8to1_45deg (16 × 2 texels rotated 45°), aniso_8to1_axis (16 × 2).
//  * accuracy: n_acc centres per texture from std::mt19937_64(1234 + texture index) with
//    uniform_real_distribution<double>(0.05, 0.95), s then t, rounded to float. Ground truth =
//    box average of the bilinear level-0 texture over the parallelogram c + u·dx + v·dy,
//    u, v ∈ [−½, ½], 64×64 midpoint samples, double. Metrics: MAE, RMSE, max, bias (channel R).
//  * timing: one thread, the zone plate, the coherent pattern (a 1024-wide raster of pixels over
//    a plane whose per-pixel derivatives are the footprint), n_timing lookups per pass, a warm-up
//    pass first (builds the mip levels / summed-area table), then R timed passes; lookups/s of the
//    best pass (the anchor's statistic, best of 2) and of the median pass. This program does not
//    pin itself: run it under `taskset -c 0` (the Python driver does).
//  * trilinear_batch and anisotropic_batch: the trilinear and anisotropic samplers through
//    BatchSampler (texture/sample_batch.hpp), kLookupBatch lookups per call, timed and measured
//    like the others (same points, same pattern, same lookup count).
//
// Usage errors exit with status 2, failures with 1.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iterator>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "mipraster/texture/sample.hpp"
#include "mipraster/texture/sample_batch.hpp"
#include "mipraster/texture/sampler.hpp"
#include "cli_options.hpp"
#include "mipraster/texture/texture.hpp"

namespace {

using namespace mipraster;

constexpr const char* kUsage =
    "usage: mipraster_bench_texture OUT.json [options]\n"
    "\n"
    "Measures mipraster's texture filters (nearest, bilinear, trilinear, anisotropic, ewa, sat) like\n"
    "/work/shared/bench/anchor_oiio_texture.cpp: error against the exact box-filtered footprint\n"
    "average on a 1024^2 checker and zone plate, and single-thread lookups/s on the zone plate.\n"
    "trilinear_batch and anisotropic_batch are trilinear and anisotropic through BatchSampler,\n"
    "8 lookups per call (the same points, pattern and lookup count).\n"
    "Prints Markdown tables to stdout, progress to stderr, and writes the results to OUT.json.\n"
    "Run it pinned to one CPU (taskset -c 0 ...) for stable timings.\n"
    "\n"
    "options:\n"
    "  --quick             short run: n-timing 65536, n-acc 1000, reps 3\n"
    "  --n-timing N        lookups per timed pass                        [1048576]\n"
    "  --n-acc M           accuracy footprints per texture and footprint [20000]\n"
    "  --reps R            timed passes after the warm-up pass, >= 1     [5]\n"
    "  --filters LIST      comma-separated subset of nearest,bilinear,trilinear,\n"
    "                      trilinear_batch,anisotropic,anisotropic_batch,ewa,sat [all]\n"
    "  --footprints LIST   comma-separated subset of mag_0.25px,iso_8x8,\n"
    "                      aniso_8to1_45deg,aniso_8to1_axis (e.g. for profiling) [all]\n"
    "  --markdown PATH     also write the Markdown tables to PATH\n"
    "  -h, --help          this message\n";

constexpr int kW = 1024;  // texture width and height
constexpr int kGtN = 64;  // ground-truth samples per axis

struct Footprint {
    const char* name;
    double xs, xt, ys, yt;  // derivative vectors in texels of level 0
};

constexpr double kR = 0.70710678118654752440;
const Footprint kFootprints[] = {
    {"mag_0.25px", 0.25, 0.0, 0.0, 0.25},
    {"iso_8x8", 8.0, 0.0, 0.0, 8.0},
    {"aniso_8to1_45deg", 16.0 * kR, 16.0 * kR, -2.0 * kR, 2.0 * kR},
    {"aniso_8to1_axis", 16.0, 0.0, 0.0, 2.0},
};

struct Filter {
    std::string name;
    Sampler sampler;
    bool batched = false;  // through BatchSampler, kLookupBatch lookups per call
};

// The filters that have a "<name>_batch" variant: the samplers BatchSampler's float path takes.
constexpr const char* kBatchSuffix = "_batch";
const char* const kBatchedFilters[] = {"trilinear", "anisotropic"};

Filter make_filter(const std::string& name) {
    std::string base = name;
    const std::size_t suffix = std::strlen(kBatchSuffix);
    const bool batched = name.size() > suffix && name.compare(name.size() - suffix, suffix, kBatchSuffix) == 0;
    if (batched) {
        base = name.substr(0, name.size() - suffix);
        if (std::find(std::begin(kBatchedFilters), std::end(kBatchedFilters), base) == std::end(kBatchedFilters))
            throw std::invalid_argument("filter: unknown name '" + name +
                                        "'; the batched filters are trilinear_batch and anisotropic_batch");
    }
    Filter f{name, Sampler(), batched};
    try {
        f.sampler = Sampler::from_filter_name(base);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string(e.what()) + " (or a batched one: trilinear_batch, anisotropic_batch)");
    }
    f.sampler.wrap_u = f.sampler.wrap_v = WrapMode::repeat;
    f.sampler.max_anisotropy = 16.0f;  // anisotropic: at most 16 probes; ewa: ratio cap 16
    f.sampler.validate();
    return f;
}

// ---- textures and ground truth (the anchor's Level0, same arithmetic) --------------------------

struct Level0 {
    int w = kW, h = kW;
    std::vector<float> px;
    float at(int x, int y) const {
        x %= w;
        if (x < 0) x += w;
        y %= h;
        if (y < 0) y += h;
        return px[size_t(y) * w + x];
    }
    double bilinear(double x, double y) const {
        x -= 0.5;
        y -= 0.5;
        double fx = std::floor(x), fy = std::floor(y);
        int ix = int(fx), iy = int(fy);
        double ax = x - fx, ay = y - fy;
        double a = at(ix, iy), b = at(ix + 1, iy);
        double c = at(ix, iy + 1), d = at(ix + 1, iy + 1);
        return (a * (1 - ax) + b * ax) * (1 - ay) + (c * (1 - ax) + d * ax) * ay;
    }
    double box(double cx, double cy, const Footprint& f, int n) const {
        double sum = 0;
        for (int j = 0; j < n; ++j) {
            double v = (j + 0.5) / n - 0.5;
            for (int i = 0; i < n; ++i) {
                double u = (i + 0.5) / n - 0.5;
                sum += bilinear(cx + u * f.xs + v * f.ys, cy + u * f.xt + v * f.yt);
            }
        }
        return sum / (double(n) * n);
    }
};

// anchor_oiio_texture.py make_images(): texel centres at i + 0.5, computed in double, stored as float.
Level0 make_checker() {
    Level0 L;
    L.px.resize(size_t(kW) * kW);
    for (int j = 0; j < kW; ++j)
        for (int i = 0; i < kW; ++i) {
            const double x = i + 0.5, y = j + 0.5;
            L.px[size_t(j) * kW + i] = float(std::fmod(std::floor(x / 10.0) + std::floor(y / 10.0), 2.0) * 1.0);
        }
    return L;
}

Level0 make_zoneplate() {
    Level0 L;
    L.px.resize(size_t(kW) * kW);
    const double pi = 3.14159265358979323846;
    for (int j = 0; j < kW; ++j)
        for (int i = 0; i < kW; ++i) {
            const double x = i + 0.5 - kW / 2.0, y = j + 0.5 - kW / 2.0;
            L.px[size_t(j) * kW + i] = float(0.5 + 0.5 * std::sin(pi * (x * x + y * y) / kW));
        }
    return L;
}

struct Points {
    std::vector<float> s, t;
};

Points random_pts(size_t n, double lo, double hi, unsigned seed) {
    Points P;
    P.s.resize(n);
    P.t.resize(n);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(lo, hi);
    for (size_t k = 0; k < n; ++k) {
        P.s[k] = float(U(rng));
        P.t[k] = float(U(rng));
    }
    return P;
}

// The anchor's coherent pattern.
Points coherent(const Footprint& f, size_t n) {
    Points P;
    P.s.resize(n);
    P.t.resize(n);
    const int RW = 1024;
    for (size_t k = 0; k < n; ++k) {
        double x = double(k % RW) - RW / 2, y = double(k / RW) - double(n / RW) / 2;
        double s = 0.5 + (x * f.xs + y * f.ys) / kW;
        double t = 0.5 + (x * f.xt + y * f.yt) / kW;
        P.s[k] = float(s - std::floor(s));
        P.t[k] = float(t - std::floor(t));
    }
    return P;
}

// Lookups k < n at (s[k], t[k]) with one footprint through `sampler`, kLookupBatch per call (the
// last call takes the rest); use(k, colour) for each.
template <typename Use>
inline void sample_batched(BatchSampler& sampler, const Points& P, glm::vec2 dx, glm::vec2 dy, Use&& use) {
    LookupBatch batch;
    glm::vec4 out[kLookupBatch];
    const size_t n = P.s.size();
    for (size_t k = 0; k < n; k += kLookupBatch) {
        batch.count = static_cast<int>(std::min<size_t>(kLookupBatch, n - k));
        for (int i = 0; i < batch.count; ++i) batch.set(i, glm::vec2(P.s[k + i], P.t[k + i]), dx, dy);
        sampler.sample(batch, out);
        for (int i = 0; i < batch.count; ++i) use(k + i, out[i]);
    }
}

glm::vec2 deriv_x(const Footprint& f) { return {float(f.xs / kW), float(f.xt / kW)}; }
glm::vec2 deriv_y(const Footprint& f) { return {float(f.ys / kW), float(f.yt / kW)}; }

// ---- results -------------------------------------------------------------------------------------

struct AccuracyRow {
    std::string texture, footprint, filter;
    double mae = 0, rmse = 0, maxe = 0, bias = 0;
};

struct TimingRow {
    std::string footprint, filter;
    double best = 0, median = 0;  // lookups per second
    std::vector<double> passes;   // lookups per second of each timed pass
};

using Clock = std::chrono::steady_clock;

std::string json_escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (c == '\n')
            out += "\\n";
        else
            out += c;
    }
    return out;
}

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

// Rows = filters, columns = footprints.
template <typename Get>
std::string table(const std::vector<std::string>& filters, const std::vector<std::string>& footprints, Get get) {
    std::string s = "| filter |";
    for (const std::string& f : footprints) s += " " + f + " |";
    s += "\n|---|";
    for (size_t i = 0; i < footprints.size(); ++i) s += "---|";
    s += "\n";
    for (const std::string& name : filters) {
        s += "| " + name + " |";
        for (const std::string& f : footprints) s += " " + get(name, f.c_str()) + " |";
        s += "\n";
    }
    return s;
}

// The non-empty items of a comma-separated list.
std::vector<std::string> split_list(const char* text) {
    std::vector<std::string> items;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ','))
        if (!item.empty()) items.push_back(item);
    return items;
}

int usage_error(const std::string& message) { return mipraster::apps::usage_error("mipraster_bench_texture", message, kUsage); }

using mipraster::apps::parse_count;

int run(int argc, char** argv) {
    std::string out_json, out_md;
    long long n_timing = 1 << 20, n_acc = 20000, reps = 5;
    bool quick = false, set_timing = false, set_acc = false, set_reps = false;
    std::vector<std::string> filter_names = {"nearest",           "bilinear", "trilinear", "trilinear_batch", "anisotropic",
                                             "anisotropic_batch", "ewa",      "sat"};
    std::vector<std::string> footprint_names;
    for (const Footprint& f : kFootprints) footprint_names.push_back(f.name);
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
        if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (a == "--quick") {
            quick = true;
        } else if (a == "--n-timing" || a == "--n-acc" || a == "--reps") {
            const char* v = value();
            if (!v) return usage_error(a + " needs a value");
            long long parsed = 0;
            if (!parse_count(v, 1, parsed)) return usage_error(a + ": '" + v + "' is not a positive integer");
            if (a == "--n-timing") n_timing = parsed, set_timing = true;
            if (a == "--n-acc") n_acc = parsed, set_acc = true;
            if (a == "--reps") reps = parsed, set_reps = true;
        } else if (a == "--filters") {
            const char* v = value();
            if (!v) return usage_error("--filters needs a value");
            filter_names = split_list(v);
            if (filter_names.empty()) return usage_error("--filters: empty list");
        } else if (a == "--footprints") {
            const char* v = value();
            if (!v) return usage_error("--footprints needs a value");
            footprint_names.clear();
            for (const std::string& item : split_list(v)) {
                bool known = false;
                for (const Footprint& f : kFootprints) known = known || item == f.name;
                if (!known)
                    return usage_error("--footprints: unknown footprint '" + item +
                                       "'; expected mag_0.25px, iso_8x8, aniso_8to1_45deg or aniso_8to1_axis");
                footprint_names.push_back(item);
            }
            if (footprint_names.empty()) return usage_error("--footprints: empty list");
        } else if (a == "--markdown") {
            const char* v = value();
            if (!v) return usage_error("--markdown needs a path");
            out_md = v;
        } else if (!a.empty() && a[0] == '-') {
            return usage_error("unknown option '" + a + "'");
        } else if (out_json.empty()) {
            out_json = a;
        } else {
            return usage_error("unexpected argument '" + a + "' (the JSON path is already '" + out_json + "')");
        }
    }
    if (out_json.empty()) return usage_error("missing the output JSON path");
    if (quick) {
        if (!set_timing) n_timing = 1 << 16;
        if (!set_acc) n_acc = 1000;
        if (!set_reps) reps = 3;
    }
    std::vector<Filter> filters;
    for (const std::string& name : filter_names) {
        try {
            filters.push_back(make_filter(name));
        } catch (const std::exception& e) {
            return usage_error(std::string("--filters: ") + e.what());
        }
    }
    // Fail on an unwritable output before spending minutes measuring.
    FILE* probe = std::fopen(out_json.c_str(), "w");
    if (!probe) {
        std::fprintf(stderr, "mipraster_bench_texture: cannot write '%s': %s\n", out_json.c_str(), std::strerror(errno));
        return 1;
    }
    std::fclose(probe);

    auto selected = [&](const Footprint& f) {
        return std::find(footprint_names.begin(), footprint_names.end(), f.name) != footprint_names.end();
    };
    const char* tex_labels[2] = {"checker", "zoneplate"};
    Level0 levels0[2] = {make_checker(), make_zoneplate()};
    Texture textures[2];
    double seconds_build_textures = 0;
    {
        const auto t0 = Clock::now();
        for (int ti = 0; ti < 2; ++ti)
            textures[ti] = Texture::from_float(levels0[ti].px.data(), kW, kW, 1, true, tex_labels[ti]);
        seconds_build_textures = std::chrono::duration<double>(Clock::now() - t0).count();
    }

    // ---------------- accuracy ----------------
    std::vector<AccuracyRow> accuracy;
    std::string gt_conv;
    std::string crosscheck;  // zone plate, aniso_8to1_45deg: first 16 centres and GT (as in the anchor)
    double seconds_ground_truth = 0, seconds_accuracy_lookups = 0;
    for (int ti = 0; ti < 2; ++ti) {
        const Level0& L0 = levels0[ti];
        TextureView view(textures[ti]);
        const Points P = random_pts(size_t(n_acc), 0.05, 0.95, 1234 + ti);
        for (const Footprint& f : kFootprints) {
            if (!selected(f)) continue;
            auto t0 = Clock::now();
            std::vector<double> gt(static_cast<size_t>(n_acc));
            for (size_t k = 0; k < gt.size(); ++k) gt[k] = L0.box(double(P.s[k]) * kW, double(P.t[k]) * kW, f, kGtN);
            double conv = 0;
            for (size_t k = 0; k < 100 && k < gt.size(); ++k)
                conv = std::max(conv, std::fabs(L0.box(double(P.s[k]) * kW, double(P.t[k]) * kW, f, 256) - gt[k]));
            seconds_ground_truth += std::chrono::duration<double>(Clock::now() - t0).count();
            gt_conv += (gt_conv.empty() ? "" : ", ") + std::string("\"") + tex_labels[ti] + "/" + f.name +
                       "\": " + fmt("%.3g", conv);
            if (ti == 1 && &f == &kFootprints[2]) {
                for (size_t k = 0; k < 16 && k < gt.size(); ++k) {
                    char buf[160];
                    std::snprintf(buf, sizeof buf, "%s[%.9g, %.9g, %.17g]", crosscheck.empty() ? "" : ", ",
                                  double(P.s[k]), double(P.t[k]), gt[k]);
                    crosscheck += buf;
                }
            }
            t0 = Clock::now();
            const glm::vec2 dx = deriv_x(f), dy = deriv_y(f);
            for (const Filter& filter : filters) {
                AccuracyRow row;
                row.texture = tex_labels[ti];
                row.footprint = f.name;
                row.filter = filter.name;
                const auto add = [&](size_t k, const glm::vec4& r) {
                    const double d = double(r.x) - gt[k];
                    row.mae += std::fabs(d);
                    row.rmse += d * d;
                    row.bias += d;
                    row.maxe = std::max(row.maxe, std::fabs(d));
                };
                if (filter.batched) {
                    BatchSampler batch(view, filter.sampler);
                    sample_batched(batch, P, dx, dy, add);
                } else {
                    for (size_t k = 0; k < gt.size(); ++k)
                        add(k, sample_texture(view, filter.sampler, glm::vec2(P.s[k], P.t[k]), dx, dy));
                }
                const double n = double(gt.size());
                row.mae /= n;
                row.rmse = std::sqrt(row.rmse / n);
                row.bias /= n;
                accuracy.push_back(row);
            }
            seconds_accuracy_lookups += std::chrono::duration<double>(Clock::now() - t0).count();
            std::fprintf(stderr, "accuracy %s %s done\n", tex_labels[ti], f.name);
        }
    }

    // ---------------- timing ----------------
    std::vector<TimingRow> timing;
    double checksum = 0;
    {
        TextureView view(textures[1]);
        for (const Footprint& f : kFootprints) {
            if (!selected(f)) continue;
            const Points C = coherent(f, size_t(n_timing));
            const glm::vec2 dx = deriv_x(f), dy = deriv_y(f);
            for (const Filter& filter : filters) {
                TimingRow row;
                row.footprint = f.name;
                row.filter = filter.name;
                BatchSampler batch(view, filter.sampler);  // one per draw, as a renderer would hold it
                for (long long r = 0; r <= reps; ++r) {  // r == 0 is the warm-up pass
                    double acc = 0;
                    const auto t0 = Clock::now();
                    if (filter.batched) {
                        sample_batched(batch, C, dx, dy, [&](size_t, const glm::vec4& r) { acc += r.x; });
                    } else {
                        for (size_t k = 0; k < C.s.size(); ++k)
                            acc += sample_texture(view, filter.sampler, glm::vec2(C.s[k], C.t[k]), dx, dy).x;
                    }
                    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
                    if (r > 0) row.passes.push_back(double(n_timing) / dt);
                    checksum += acc;
                }
                std::vector<double> sorted = row.passes;
                std::sort(sorted.begin(), sorted.end());
                row.best = sorted.back();
                const size_t m = sorted.size();
                row.median = m % 2 ? sorted[m / 2] : 0.5 * (sorted[m / 2 - 1] + sorted[m / 2]);
                std::fprintf(stderr, "timing %-18s %-12s best %8.3f  median %8.3f M lookups/s\n", f.name,
                             filter.name.c_str(), row.best / 1e6, row.median / 1e6);
                timing.push_back(row);
            }
        }
    }

    // ---------------- JSON ----------------
    FILE* out = std::fopen(out_json.c_str(), "w");
    if (!out) {
        std::fprintf(stderr, "mipraster_bench_texture: cannot write '%s': %s\n", out_json.c_str(), std::strerror(errno));
        return 1;
    }
    std::fprintf(out, "{\n \"bench\": \"mipraster_bench_texture\",\n");
    std::fprintf(out, " \"n_timing\": %lld, \"n_accuracy\": %lld, \"gt_n\": %d, \"reps\": %lld, \"quick\": %s,\n",
                 n_timing, n_acc, kGtN, reps, quick ? "true" : "false");
    std::fprintf(out, " \"texel_format\": \"rgba32f (1-channel float expanded to v,v,v,1)\",\n");
    std::fprintf(out, " \"timing_texture\": \"zoneplate\", \"timing_pattern\": \"coherent\",\n");
#ifdef NDEBUG
    std::fprintf(out, " \"bench_ndebug\": true,\n");
#else
    std::fprintf(out, " \"bench_ndebug\": false,\n");
#endif
    std::fprintf(out, " \"samplers\": {");
    for (size_t i = 0; i < filters.size(); ++i)
        std::fprintf(out, "%s\"%s\": \"%s%s\"", i ? ", " : "", filters[i].name.c_str(),
                     json_escape(filters[i].sampler.to_string()).c_str(),
                     filters[i].batched ? (" through BatchSampler, " + std::to_string(kLookupBatch) + " lookups per call").c_str() : "");
    std::fprintf(out, "},\n \"accuracy\": [\n");
    for (size_t i = 0; i < accuracy.size(); ++i) {
        const AccuracyRow& a = accuracy[i];
        std::fprintf(out,
                     "%s  {\"texture\": \"%s\", \"footprint\": \"%s\", \"filter\": \"%s\", \"mae\": %.6g, "
                     "\"rmse\": %.6g, \"max\": %.6g, \"bias\": %.6g}",
                     i ? ",\n" : "", a.texture.c_str(), a.footprint.c_str(), a.filter.c_str(), a.mae, a.rmse, a.maxe,
                     a.bias);
    }
    std::fprintf(out, "\n ],\n \"timing\": [\n");
    for (size_t i = 0; i < timing.size(); ++i) {
        const TimingRow& t = timing[i];
        std::fprintf(out,
                     "%s  {\"texture\": \"zoneplate\", \"footprint\": \"%s\", \"pattern\": \"coherent\", \"filter\": "
                     "\"%s\", \"lookups_per_s\": %.6g, \"lookups_per_s_median\": %.6g, \"passes\": [",
                     i ? ",\n" : "", t.footprint.c_str(), t.filter.c_str(), t.best, t.median);
        for (size_t p = 0; p < t.passes.size(); ++p) std::fprintf(out, "%s%.6g", p ? ", " : "", t.passes[p]);
        std::fprintf(out, "]}");
    }
    std::fprintf(out, "\n ],\n \"gt_convergence_max_abs_64_vs_256\": {%s},\n", gt_conv.c_str());
    std::fprintf(out, " \"crosscheck_zoneplate_aniso_8to1_45deg_s_t_gt\": [%s],\n", crosscheck.c_str());
    std::fprintf(out,
                 " \"seconds\": {\"texture_from_float\": %.4g, \"ground_truth\": %.4g, \"accuracy_lookups\": %.4g},\n",
                 seconds_build_textures, seconds_ground_truth, seconds_accuracy_lookups);
    std::fprintf(out, " \"checksum\": %.9g\n}\n", checksum);
    if (std::fclose(out) != 0) {
        std::fprintf(stderr, "mipraster_bench_texture: writing '%s' failed\n", out_json.c_str());
        return 1;
    }

    // ---------------- Markdown ----------------
    std::vector<std::string> names;
    for (const Filter& f : filters) names.push_back(f.name);
    auto acc_get = [&](const char* tex, const char* metric) {
        return [&, tex, metric](const std::string& filter, const char* fp) {
            for (const AccuracyRow& a : accuracy)
                if (a.texture == tex && a.footprint == fp && a.filter == filter)
                    return fmt("%.4f", std::strcmp(metric, "mae") == 0 ? a.mae : a.rmse);
            return std::string();
        };
    };
    auto time_get = [&](bool median) {
        return [&, median](const std::string& filter, const char* fp) {
            for (const TimingRow& t : timing)
                if (t.footprint == fp && t.filter == filter) return fmt("%.3f", (median ? t.median : t.best) / 1e6);
            return std::string();
        };
    };
    std::string md;
    md += "mipraster texture filters: " + std::to_string(n_timing) + " timing lookups (best and median of " +
          std::to_string(reps) + " passes after a warm-up pass, one thread), " + std::to_string(n_acc) +
          " accuracy footprints per texture, ground truth " + std::to_string(kGtN) + "x" + std::to_string(kGtN) +
          (quick ? " (--quick)" : "") + "\n";
    for (const char* tex : tex_labels)
        for (const char* metric : {"mae", "rmse"}) {
            md += std::string("\n### ") + tex + " " + (std::strcmp(metric, "mae") == 0 ? "MAE" : "RMSE") +
                  " (vs box-filtered bilinear level 0)\n\n";
            md += table(names, footprint_names, acc_get(tex, metric));
        }
    md += "\n### M lookups/s, best pass (zone plate, RGBA float, coherent raster order)\n\n";
    md += table(names, footprint_names, time_get(false));
    md += "\n### M lookups/s, median pass\n\n";
    md += table(names, footprint_names, time_get(true));
    md += "\nGT convergence, max |GT64-GT256|: {" + gt_conv + "}\n";
    std::fputs(md.c_str(), stdout);
    if (!out_md.empty()) {
        FILE* m = std::fopen(out_md.c_str(), "w");
        if (!m || std::fputs(md.c_str(), m) < 0 || std::fclose(m) != 0) {
            std::fprintf(stderr, "mipraster_bench_texture: cannot write '%s'\n", out_md.c_str());
            return 1;
        }
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mipraster_bench_texture: %s\n", e.what());
        return 1;
    }
}
