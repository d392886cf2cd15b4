// mipraster_bench_roofline — the two machine limits the frame-time roofline divides by:
//
//  * framebuffer-write bandwidth: streaming stores of an RGBA float colour buffer and a float depth
//    buffer the size of a 1920×1080 frame (20 bytes a pixel, ~41 MB: larger than the caches), by 1
//    and by 2 threads (each thread writes its own half of the rows);
//  * trilinear throughput: mipraster's own lookups as renders make them (BatchSampler, sixteen at a
//    time; trilinear, repeat) on a 1024² RGBA
//    texture at a coherent pattern (a 1024-wide raster of pixels over a plane whose per-pixel uv
//    derivatives are an isotropic footprint of d texels), lookups/s by 1 and 2 threads, for a few d
//    (d ≤ 1 magnifies: one bilinear lookup; d > 1 blends two levels).
//
//   mipraster_bench_roofline OUT.json [--quick] [--reps R] [--lookups N]
//
// Each figure is measured in R timed passes after one warm-up pass (which also builds the mip
// levels); the JSON holds every pass, the best and the median. Threads are started for each pass
// (about 0.1 ms, under 3% of a pass). Run it pinned (taskset -c 0,1): the Python driver
// (python -m mipraster.bench --roofline) does. Usage errors exit with status 2.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "mipraster/texture/sample_batch.hpp"
#include "mipraster/texture/sampler.hpp"
#include "cli_options.hpp"
#include "mipraster/texture/texture.hpp"

namespace {

using namespace mipraster;
using Clock = std::chrono::steady_clock;

constexpr const char* kUsage =
    "usage: mipraster_bench_roofline OUT.json [--quick] [--reps R] [--lookups N]\n"
    "\n"
    "Measures the framebuffer-write bandwidth (RGBA float + depth float over a 1920x1080 frame) and\n"
    "mipraster's trilinear lookup throughput (BatchSampler; 1024^2 RGBA texture, coherent pattern), each\n"
    "with 1 and 2 threads. Prints a summary to stdout and writes every pass to OUT.json.\n"
    "\n"
    "options:\n"
    "  --quick       reps 3, lookups 262144\n"
    "  --reps R      timed passes after the warm-up pass, >= 1   [7]\n"
    "  --lookups N   texture lookups per timed pass, >= 1024      [1048576]\n"
    "  -h, --help    this message\n";

constexpr int kFrameW = 1920, kFrameH = 1080;
constexpr int kTexSize = 1024;
constexpr int kPatternWidth = 1024;  // pixels per row of the coherent lookup pattern
constexpr int kMaxThreads = 2;
/// Isotropic footprints in texels per pixel: magnification, then 1.5, 3 and 6 texels (λ ≈ 0.58,
/// 1.58, 2.58: always two levels blended).
constexpr double kFootprints[] = {0.5, 1.5, 3.0, 6.0};

struct Passes {
    std::vector<double> rates;  // per timed pass, in the unit of the figure
    double best() const { return *std::max_element(rates.begin(), rates.end()); }
    double median() const {
        std::vector<double> s = rates;
        std::sort(s.begin(), s.end());
        const std::size_t n = s.size();
        return n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
    }
};

// Runs work(t, threads) on `threads` threads (t = 0 on this one) and returns the wall seconds.
double run_threads(int threads, const std::function<void(int, int)>& work) {
    const auto t0 = Clock::now();
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work, t, threads);
    work(0, threads);
    for (std::thread& th : pool) th.join();
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// ---- framebuffer-write bandwidth ---------------------------------------------------------------

// Rows [lo, hi) of the frame get colour (v, v, v, 1) and depth v: the stores a clear or a
// full-screen opaque draw makes.
void write_rows(float* color, float* depth, int lo, int hi, float v) {
    float* c = color + std::size_t(lo) * kFrameW * 4;
    float* d = depth + std::size_t(lo) * kFrameW;
    const std::size_t n = std::size_t(hi - lo) * kFrameW;
    for (std::size_t i = 0; i < n; ++i) {
        c[4 * i + 0] = v;
        c[4 * i + 1] = v;
        c[4 * i + 2] = v;
        c[4 * i + 3] = 1.0f;
        d[i] = v;
    }
}

constexpr double kFrameBytes = double(kFrameW) * kFrameH * (4 + 1) * sizeof(float);

Passes framebuffer_bandwidth(int threads, int reps, double& checksum) {
    std::vector<float> color(std::size_t(kFrameW) * kFrameH * 4), depth(std::size_t(kFrameW) * kFrameH);
    Passes p;
    for (int r = 0; r <= reps; ++r) {  // pass 0 is the warm-up (page faults)
        const float v = 0.25f + 0.01f * float(r);
        const double s = run_threads(threads, [&](int t, int n) {
            write_rows(color.data(), depth.data(), kFrameH * t / n, kFrameH * (t + 1) / n, v);
        });
        if (r > 0) p.rates.push_back(kFrameBytes / s / 1e9);
        checksum += color[std::size_t(r) * 4097 % color.size()] + depth[std::size_t(r) * 131 % depth.size()];
    }
    return p;
}

// ---- trilinear throughput ----------------------------------------------------------------------

Texture make_texture() {
    // An 8-colour checker of 32-texel squares (the filter's arithmetic does not depend on the
    // content; the uint8 texels are decoded to RGBA float as the benchmark scenes' are).
    std::vector<std::uint8_t> px(std::size_t(kTexSize) * kTexSize * 4);
    for (int y = 0; y < kTexSize; ++y)
        for (int x = 0; x < kTexSize; ++x) {
            const int k = (x / 32 + 3 * (y / 32)) % 8;
            std::uint8_t* p = &px[(std::size_t(y) * kTexSize + x) * 4];
            p[0] = std::uint8_t(30 * k), p[1] = std::uint8_t(255 - 25 * k), p[2] = std::uint8_t(90 + 20 * k), p[3] = 255;
        }
    return Texture::from_8bit(px.data(), kTexSize, kTexSize, 4, false, "roofline checker");
}

// Lookups [lo, hi) of the coherent pattern: pixel k at (k mod 1024, k / 1024), uv advancing
// d/1024 per pixel along x and y.
// Through BatchSampler, sixteen at a time, as renders look textures up.
glm::vec4 lookups(const TextureView& view, const Sampler& sampler, double d, std::size_t lo, std::size_t hi) {
    const float step = float(d / kTexSize);
    const glm::vec2 dx(step, 0.0f), dy(0.0f, step);
    BatchSampler batch_sampler(view, sampler);
    LookupBatch batch;
    glm::vec4 out[kLookupBatch];
    glm::vec4 sum(0.0f);
    for (std::size_t k = lo; k < hi; k += kLookupBatch) {
        batch.count = static_cast<int>(std::min<std::size_t>(kLookupBatch, hi - k));
        for (int l = 0; l < batch.count; ++l) {
            const double u = 0.5 + double((k + l) % kPatternWidth) * d / kTexSize;
            const double v = 0.5 + double((k + l) / kPatternWidth) * d / kTexSize;
            batch.set(l, glm::vec2(float(u - std::floor(u)), float(v - std::floor(v))), dx, dy);
        }
        batch_sampler.sample(batch, out);
        for (int l = 0; l < batch.count; ++l) sum += out[l];
    }
    return sum;
}

Passes trilinear_throughput(const TextureView& view, double d, int threads, long long n, int reps,
                            double& checksum) {
    Sampler sampler = Sampler::from_filter_name("trilinear");
    sampler.wrap_u = sampler.wrap_v = WrapMode::repeat;
    sampler.validate();
    Passes p;
    for (int r = 0; r <= reps; ++r) {  // pass 0 is the warm-up (builds the levels it needs)
        std::vector<glm::vec4> sums(static_cast<std::size_t>(threads));
        const double s = run_threads(threads, [&](int t, int m) {
            sums[t] = lookups(view, sampler, d, std::size_t(n * t / m), std::size_t(n * (t + 1) / m));
        });
        if (r > 0) p.rates.push_back(double(n) / s);
        for (const glm::vec4& v : sums) checksum += v.x + v.y + v.z + v.w;
    }
    return p;
}

// ---- output --------------------------------------------------------------------------------------

std::string json_passes(const Passes& p) {
    std::string s = "{\"best\": " + std::to_string(p.best()) + ", \"median\": " + std::to_string(p.median()) +
                    ", \"passes\": [";
    for (std::size_t i = 0; i < p.rates.size(); ++i) s += (i ? ", " : "") + std::to_string(p.rates[i]);
    return s + "]}";
}

int usage_error(const std::string& message) { return mipraster::apps::usage_error("mipraster_bench_roofline", message, kUsage); }

using mipraster::apps::parse_count;

int run(int argc, char** argv) {
    std::string out_json;
    long long reps = 7, n = 1 << 20;
    bool quick = false, set_reps = false, set_n = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (a == "--quick") {
            quick = true;
        } else if (a == "--reps" || a == "--lookups") {
            if (i + 1 >= argc) return usage_error(a + " needs a value");
            const char* v = argv[++i];
            long long parsed = 0;
            if (!parse_count(v, a == "--reps" ? 1 : 1024, parsed))
                return usage_error(a + ": '" + v + "' is not an integer >= " + (a == "--reps" ? "1" : "1024"));
            (a == "--reps" ? reps : n) = parsed;
            (a == "--reps" ? set_reps : set_n) = true;
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
        if (!set_reps) reps = 3;
        if (!set_n) n = 1 << 18;
    }
    FILE* out = std::fopen(out_json.c_str(), "w");
    if (!out) {
        std::fprintf(stderr, "mipraster_bench_roofline: cannot write '%s': %s\n", out_json.c_str(), std::strerror(errno));
        return 1;
    }

    double checksum = 0;  // printed, so no measured store or lookup can be optimized away
    std::string json = "{\n \"framebuffer_write\": {\"width\": " + std::to_string(kFrameW) +
                       ", \"height\": " + std::to_string(kFrameH) +
                       ", \"bytes_per_pixel\": 20, \"unit\": \"GB/s\", \"threads\": {";
    std::printf("framebuffer writes, %dx%d RGBA float + depth float (%.1f MB a pass):\n", kFrameW, kFrameH,
                kFrameBytes / 1e6);
    for (int t = 1; t <= kMaxThreads; ++t) {
        const Passes p = framebuffer_bandwidth(t, int(reps), checksum);
        std::printf("  %d thread%s: %.2f GB/s best, %.2f median\n", t, t > 1 ? "s" : "", p.best(), p.median());
        json += (t > 1 ? ", " : "") + std::string("\"") + std::to_string(t) + "\": " + json_passes(p);
    }
    json += "}},\n \"trilinear\": {\"texture\": \"1024x1024 RGBA float, repeat\", \"lookups_per_pass\": " +
            std::to_string(n) + ", \"unit\": \"lookups/s\", \"footprints\": [";
    const Texture texture = make_texture();
    const TextureView view(texture);
    std::printf("trilinear lookups (BatchSampler), 1024^2 RGBA, coherent pattern, %lld lookups a pass:\n", n);
    bool first = true;
    for (double d : kFootprints) {
        json += std::string(first ? "" : ",") + "\n  {\"texels_per_pixel\": " + std::to_string(d) + ", \"threads\": {";
        first = false;
        for (int t = 1; t <= kMaxThreads; ++t) {
            const Passes p = trilinear_throughput(view, d, t, n, int(reps), checksum);
            std::printf("  %.1f texels/pixel, %d thread%s: %.2f M lookups/s best, %.2f median\n", d, t,
                        t > 1 ? "s" : "", p.best() / 1e6, p.median() / 1e6);
            json += (t > 1 ? ", " : "") + std::string("\"") + std::to_string(t) + "\": " + json_passes(p);
        }
        json += "}}";
    }
    json += "]},\n \"reps\": " + std::to_string(reps) + ", \"checksum\": " + std::to_string(checksum) + "\n}\n";
    std::fputs(json.c_str(), out);
    std::fclose(out);
    std::printf("(checksum %.6g)\n", checksum);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mipraster_bench_roofline: %s\n", e.what());
        return 1;
    }
}
