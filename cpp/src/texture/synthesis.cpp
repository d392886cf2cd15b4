#include "mipraster/texture/synthesis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "mipraster/core/constants.hpp"
#include "mipraster/core/splitmix.hpp"
#include "mipraster/core/thread_pool.hpp"

namespace mipraster {

namespace {

// The least work (candidate × known-pixel terms) worth handing to another thread: waking a
// worker costs microseconds, about as long as this many terms take.
constexpr std::size_t kSynthesisPairsPerTask = 32768;
static_assert(kSynthesisPairsPerTask > 0, "a task has work");

// Seeded draws from splitmix64, the same on every platform.
struct Random {
    std::uint64_t state;
    std::uint64_t next() { return splitmix64(state); }
    /// Uniform in [0, n) (multiply-shift; the bias is below 2^-32 for any n we use).
    std::size_t below(std::size_t n) {
        return static_cast<std::size_t>((static_cast<unsigned __int128>(next()) * n) >> 64);
    }
};

// The sample as one plane per channel, padded by window − 1 with wrapped pixels when it is
// periodic, so that every candidate window is a rectangle of consecutive rows: candidate
// (cy, cx) has its top-left corner at plane row cy, column cx, and the search runs over cx in
// contiguous memory (vectorizable).
struct SamplePlanes {
    int channels = 0, pitch = 0, rows = 0;
    int candidates_x = 0, candidates_y = 0;
    std::vector<float> values;  // channel c at [c·rows·pitch + row·pitch + column]

    const float* plane(int c) const { return &values[static_cast<std::size_t>(c) * rows * pitch]; }
};

SamplePlanes make_planes(const Image& sample, int n, bool periodic) {
    SamplePlanes p;
    p.channels = sample.channels;
    p.pitch = periodic ? sample.width + n - 1 : sample.width;
    p.rows = periodic ? sample.height + n - 1 : sample.height;
    p.candidates_x = periodic ? sample.width : sample.width - n + 1;
    p.candidates_y = periodic ? sample.height : sample.height - n + 1;
    p.values.resize(static_cast<std::size_t>(p.channels) * p.rows * p.pitch);
    for (int c = 0; c < p.channels; ++c)
        for (int y = 0; y < p.rows; ++y)
            for (int x = 0; x < p.pitch; ++x)
                p.values[(static_cast<std::size_t>(c) * p.rows + y) * p.pitch + x] =
                    sample.at(x % sample.width, y % sample.height, c);
    return p;
}

// One known pixel of the neighbourhood being matched: where it sits in a candidate window (as an
// offset into the planes from the window's top-left corner), its Gaussian weight and its value.
struct KnownPixel {
    std::size_t offset;
    float weight;
    float value[4];
};

// One known pixel as the sweep reads it: its weight and value in locals (registers), and the
// start of its row in each channel plane.
template <int C>
struct Term {
    const float* __restrict row[C];
    float value[C];
    float weight;

    Term(const SamplePlanes& p, const KnownPixel& k, std::size_t row_start) : weight(k.weight) {
        for (int c = 0; c < C; ++c) {
            row[c] = p.plane(c) + row_start + k.offset;
            value[c] = k.value[c];
        }
    }
    /// The weighted squared colour difference at candidate column x.
    [[gnu::always_inline]] float at(int x) const {
        float sum = 0.0f;
        for (int c = 0; c < C; ++c) {
            const float d = row[c][x] - value[c];
            sum += d * d;
        }
        return weight * sum;
    }
};

// SSDs of the candidate rows [cy0, cy1) against the known pixels, into ssd[cy·candidates_x + cx].
// Every candidate's sum runs over the known pixels in the same order whatever the rows, threads
// or vector width (no fused multiply-add: -ffp-contract=off, and the AVX2 build below enables no
// FMA), so the sums are bit-identical on every path. Four known pixels per sweep keep the
// accumulator in registers longer without changing that order.
template <int C>
[[gnu::always_inline]] inline void candidate_ssd_kernel(const SamplePlanes& p, const std::vector<KnownPixel>& known,
                                                        int cy0, int cy1, float* ssd) {
    const int nx = p.candidates_x;
    for (int cy = cy0; cy < cy1; ++cy) {
        float* __restrict acc = ssd + static_cast<std::size_t>(cy) * nx;
        for (int x = 0; x < nx; ++x) acc[x] = 0.0f;
        const std::size_t row = static_cast<std::size_t>(cy) * p.pitch;
        std::size_t k = 0;
        for (; k + 4 <= known.size(); k += 4) {
            const Term<C> t0(p, known[k], row), t1(p, known[k + 1], row), t2(p, known[k + 2], row),
                t3(p, known[k + 3], row);
            // ivdep: acc and the sample planes never overlap; without it GCC gives up on
            // vectorizing (too many pointers to check for aliasing at run time).
#pragma GCC ivdep
            for (int x = 0; x < nx; ++x) acc[x] = (((acc[x] + t0.at(x)) + t1.at(x)) + t2.at(x)) + t3.at(x);
        }
        for (; k < known.size(); ++k) {
            const Term<C> t(p, known[k], row);
#pragma GCC ivdep
            for (int x = 0; x < nx; ++x) acc[x] += t.at(x);
        }
    }
}

// The same kernel compiled for the x86-64 baseline (SSE2) and for AVX2 (twice the lanes); the
// AVX2 one runs where the CPU has it.
#define MIPRASTER_SSD_DISPATCH                                                \
    switch (p.channels) {                                                     \
        case 1: return candidate_ssd_kernel<1>(p, known, cy0, cy1, ssd);      \
        case 2: return candidate_ssd_kernel<2>(p, known, cy0, cy1, ssd);      \
        case 3: return candidate_ssd_kernel<3>(p, known, cy0, cy1, ssd);      \
        default: return candidate_ssd_kernel<4>(p, known, cy0, cy1, ssd);     \
    }

void candidate_ssd_baseline(const SamplePlanes& p, const std::vector<KnownPixel>& known, int cy0, int cy1, float* ssd) {
    MIPRASTER_SSD_DISPATCH
}

#if defined(__x86_64__) && defined(__GNUC__)
[[gnu::target("avx2")]] void candidate_ssd_avx2(const SamplePlanes& p, const std::vector<KnownPixel>& known, int cy0,
                                                int cy1, float* ssd) {
    MIPRASTER_SSD_DISPATCH
}
const bool kHasAvx2 = __builtin_cpu_supports("avx2");
#endif
#undef MIPRASTER_SSD_DISPATCH

void candidate_ssd(const SamplePlanes& p, const std::vector<KnownPixel>& known, int cy0, int cy1, float* ssd) {
#if defined(__x86_64__) && defined(__GNUC__)
    if (kHasAvx2) return candidate_ssd_avx2(p, known, cy0, cy1, ssd);
#endif
    candidate_ssd_baseline(p, known, cy0, cy1, ssd);
}

void validate(const Image& sample, const SynthesisSettings& s) {
    if (sample.width < 1 || sample.height < 1 || sample.channels < 1)
        throw std::invalid_argument("sample: empty (" + sample.to_string() + "); expected at least 1x1 with a channel");
    if (sample.channels > 4)
        throw std::invalid_argument("sample: " + std::to_string(sample.channels) + " channels; expected 1 to 4");
    if (sample.pixels.size() != static_cast<std::size_t>(sample.width) * sample.height * sample.channels)
        throw std::invalid_argument("sample: " + std::to_string(sample.pixels.size()) + " values for " + sample.to_string());
    for (std::size_t i = 0; i < sample.pixels.size(); ++i)
        if (!std::isfinite(sample.pixels[i])) {
            const std::size_t pixel = i / static_cast<std::size_t>(sample.channels);
            throw std::invalid_argument("sample[" + std::to_string(pixel / static_cast<std::size_t>(sample.width)) + ", " +
                                        std::to_string(pixel % static_cast<std::size_t>(sample.width)) + ", " +
                                        std::to_string(i % static_cast<std::size_t>(sample.channels)) + "] is " +
                                        std::to_string(sample.pixels[i]) + "; expected a finite number");
        }
    for (const auto& [size, name] : {std::pair<int, const char*>{s.width, "width"}, {s.height, "height"}})
        if (size < 1 || size > kMaxSynthesisDimension)
            throw std::invalid_argument(std::string(name) + ": " + std::to_string(size) + " is out of range; expected 1 to " +
                                        std::to_string(kMaxSynthesisDimension));
    if (s.window < 1 || s.window % 2 == 0)
        throw std::invalid_argument("window: " + std::to_string(s.window) + "; expected an odd size >= 1 (1, 3, 5, ...)");
    if (s.window > std::min(sample.width, sample.height))
        throw std::invalid_argument("window: " + std::to_string(s.window) + " is larger than the sample (" +
                                    std::to_string(sample.width) + "x" + std::to_string(sample.height) + ")");
    if (s.tileable && s.window > std::min(s.width, s.height))
        throw std::invalid_argument("window: " + std::to_string(s.window) + " is larger than the tileable output (" +
                                    std::to_string(s.width) + "x" + std::to_string(s.height) + ")");
    if (!std::isfinite(s.epsilon) || s.epsilon < 0.0)
        throw std::invalid_argument("epsilon: " + std::to_string(s.epsilon) + "; expected a finite number >= 0");
    resolve_thread_count(s.threads);  // throws naming threads
}

}  // namespace

std::string SynthesisSettings::to_string() const {
    return "SynthesisSettings(" + std::to_string(width) + "x" + std::to_string(height) + ", window=" +
           std::to_string(window) + ", seed=" + std::to_string(seed) + ", epsilon=" + std::to_string(epsilon) +
           ", periodic_sample=" + (periodic_sample ? "true" : "false") + ", tileable=" + (tileable ? "true" : "false") +
           ", threads=" + std::to_string(threads) + ")";
}

std::string SynthesisResult::to_string() const {
    return "SynthesisResult(" + image.to_string() + ", candidates=" + std::to_string(candidates) + ", " +
           std::to_string(milliseconds) + " ms)";
}

SynthesisResult synthesize_texture(const Image& sample, const SynthesisSettings& settings) {
    const auto start = std::chrono::steady_clock::now();
    validate(sample, settings);
    const int W = settings.width, H = settings.height, C = sample.channels, n = settings.window, r = n / 2;
    const SamplePlanes planes = make_planes(sample, n, settings.periodic_sample);
    const int ncx = planes.candidates_x, ncy = planes.candidates_y;
    const std::size_t candidates = static_cast<std::size_t>(ncx) * ncy;

    // Gaussian weights of the window, row-major.
    const double sigma = n / kSynthesisSigmaDivisor;
    std::vector<float> gauss(static_cast<std::size_t>(n) * n);
    for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx)
            gauss[static_cast<std::size_t>(dy + r) * n + dx + r] =
                static_cast<float>(std::exp(-(dx * dx + dy * dy) / (2.0 * sigma * sigma)));

    SynthesisResult result;
    result.image = Image(W, H, C);
    result.source.assign(static_cast<std::size_t>(W) * H, -1);
    result.candidates = candidates;
    std::vector<std::uint8_t> known(static_cast<std::size_t>(W) * H, 0);
    Random random{settings.seed};
    auto fill = [&](int x, int y, int sx, int sy) {
        const std::size_t o = static_cast<std::size_t>(y) * W + x;
        known[o] = 1;
        result.source[o] = sy * sample.width + sx;
        for (int c = 0; c < C; ++c) result.image.pixels[o * C + c] = sample.at(sx, sy, c);
    };
    // Output coordinates of a neighbour: wrapped when the output tiles, else −1 outside it.
    auto neighbour = [&](int x, int y, int dx, int dy) -> long {
        int qx = x + dx, qy = y + dy;
        if (settings.tileable) {
            qx = (qx % W + W) % W;
            qy = (qy % H + H) % H;
        } else if (qx < 0 || qy < 0 || qx >= W || qy >= H) {
            return -1;
        }
        return static_cast<long>(qy) * W + qx;
    };

    // Step 1: the seed patch, a random kSynthesisSeedSize² piece of the sample in the middle.
    const int seed_w = std::min({kSynthesisSeedSize, W, sample.width}), seed_h = std::min({kSynthesisSeedSize, H, sample.height});
    const int span_x = settings.periodic_sample ? sample.width : sample.width - seed_w + 1;
    const int span_y = settings.periodic_sample ? sample.height : sample.height - seed_h + 1;
    const int seed_sx = static_cast<int>(random.below(static_cast<std::size_t>(span_x)));
    const int seed_sy = static_cast<int>(random.below(static_cast<std::size_t>(span_y)));
    const int seed_x = (W - seed_w) / 2, seed_y = (H - seed_h) / 2;
    for (int y = 0; y < seed_h; ++y)
        for (int x = 0; x < seed_w; ++x)
            fill(seed_x + x, seed_y + y, (seed_sx + x) % sample.width, (seed_sy + y) % sample.height);
    std::size_t filled = static_cast<std::size_t>(seed_w) * seed_h;

    // Step 2: onion-skin layers. Each layer is every unknown pixel next to a known one, shuffled,
    // then stably sorted by how many known pixels its window holds (most first); its pixels are
    // synthesized in that order, each seeing the ones before it.
    ThreadPool pool(std::min(resolve_thread_count(settings.threads), ncy));
    // A batch has at most one pixel per thread, and only when a pixel's search is worth a thread.
    const bool worth_batching = pool.size() > 1 && candidates * static_cast<std::size_t>(n) * n / 2 >= kSynthesisPairsPerTask;
    const std::size_t max_batch = worth_batching ? static_cast<std::size_t>(pool.size()) : 1;
    std::vector<std::vector<float>> ssds(max_batch, std::vector<float>(candidates));
    std::vector<std::vector<KnownPixel>> neighbourhoods(max_batch);
    std::vector<std::size_t> batch;
    std::vector<std::uint32_t> matches;
    // The known pixels of pixel p's window.
    auto gather_neighbourhood = [&](std::size_t p, std::vector<KnownPixel>& out) {
        const int x = static_cast<int>(p % static_cast<std::size_t>(W)), y = static_cast<int>(p / static_cast<std::size_t>(W));
        out.clear();
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
                const long q = neighbour(x, y, dx, dy);
                if (q < 0 || !known[static_cast<std::size_t>(q)]) continue;
                KnownPixel k{static_cast<std::size_t>(dy + r) * planes.pitch + static_cast<std::size_t>(dx + r),
                             gauss[static_cast<std::size_t>(dy + r) * n + dx + r], {0, 0, 0, 0}};
                for (int c = 0; c < C; ++c) k.value[c] = result.image.pixels[static_cast<std::size_t>(q) * C + c];
                out.push_back(k);
            }
    };
    // Whether pixels p and q are outside each other's windows (more than r apart along x or y,
    // around the edges when the output tiles).
    auto apart = [&](std::size_t p, std::size_t q) {
        int dx = std::abs(static_cast<int>(p % static_cast<std::size_t>(W)) - static_cast<int>(q % static_cast<std::size_t>(W)));
        int dy = std::abs(static_cast<int>(p / static_cast<std::size_t>(W)) - static_cast<int>(q / static_cast<std::size_t>(W)));
        if (settings.tileable) {
            dx = std::min(dx, W - dx);
            dy = std::min(dy, H - dy);
        }
        return dx > r || dy > r;
    };
    std::vector<std::pair<int, std::size_t>> layer;  // (known count, pixel)
    while (filled < known.size()) {
        layer.clear();
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                if (known[static_cast<std::size_t>(y) * W + x]) continue;
                bool touches = false;
                for (int dy = -1; dy <= 1 && !touches; ++dy)
                    for (int dx = -1; dx <= 1 && !touches; ++dx) {
                        const long q = neighbour(x, y, dx, dy);
                        touches = q >= 0 && known[static_cast<std::size_t>(q)];
                    }
                if (!touches) continue;
                int count = 0;
                for (int dy = -r; dy <= r; ++dy)
                    for (int dx = -r; dx <= r; ++dx) {
                        const long q = neighbour(x, y, dx, dy);
                        count += q >= 0 && known[static_cast<std::size_t>(q)];
                    }
                layer.emplace_back(count, static_cast<std::size_t>(y) * W + x);
            }
        for (std::size_t i = layer.size(); i > 1; --i) std::swap(layer[i - 1], layer[random.below(i)]);
        std::stable_sort(layer.begin(), layer.end(), [](const auto& a, const auto& b) { return a.first > b.first; });

        // Pixels are searched in batches of consecutive layer pixels that are more than the
        // window's radius apart: no member lies in a later member's window, so each one's known
        // neighbourhood is what it would be one pixel at a time. Their searches run in parallel
        // (one pixel per thread), then they are filled in layer order with the same random draws,
        // so the output is the sequential one. A lone pixel splits its candidate rows instead.
        std::size_t next = 0;
        while (next < layer.size()) {
            batch.assign(1, next);
            std::size_t end = next + 1;
            for (; end < layer.size() && batch.size() < max_batch; ++end) {
                if (!std::all_of(batch.begin(), batch.end(), [&](std::size_t b) {
                        return apart(layer[b].second, layer[end].second);
                    }))
                    break;
                batch.push_back(end);
            }
            for (std::size_t b = 0; b < batch.size(); ++b) gather_neighbourhood(layer[batch[b]].second, neighbourhoods[b]);
            if (batch.size() > 1) {
                pool.parallel_for(batch.size(), [&](std::size_t b) {
                    candidate_ssd(planes, neighbourhoods[b], 0, ncy, ssds[b].data());
                });
            } else {
                const std::size_t tasks = std::min<std::size_t>(
                    static_cast<std::size_t>(pool.size()), candidates * neighbourhoods[0].size() / kSynthesisPairsPerTask);
                if (tasks <= 1) {
                    candidate_ssd(planes, neighbourhoods[0], 0, ncy, ssds[0].data());
                } else {
                    pool.parallel_for(tasks, [&](std::size_t t) {
                        candidate_ssd(planes, neighbourhoods[0], static_cast<int>(t * ncy / tasks),
                                      static_cast<int>((t + 1) * ncy / tasks), ssds[0].data());
                    });
                }
            }
            // In layer order: the candidates within (1 + ε) of the best; one of them at random.
            for (std::size_t b = 0; b < batch.size(); ++b) {
                const std::vector<float>& ssd = ssds[b];
                const float best = *std::min_element(ssd.begin(), ssd.end());
                const float limit = static_cast<float>(best * (1.0 + settings.epsilon));
                matches.clear();
                for (std::size_t i = 0; i < candidates; ++i)
                    if (ssd[i] <= limit) matches.push_back(static_cast<std::uint32_t>(i));
                const std::uint32_t pick = matches[random.below(matches.size())];
                const int cx = static_cast<int>(pick % static_cast<std::uint32_t>(ncx));
                const int cy = static_cast<int>(pick / static_cast<std::uint32_t>(ncx));
                const std::size_t pixel = layer[batch[b]].second;
                fill(static_cast<int>(pixel % static_cast<std::size_t>(W)), static_cast<int>(pixel / static_cast<std::size_t>(W)),
                     (cx + r) % sample.width, (cy + r) % sample.height);
                ++filled;
            }
            next = end;
        }
    }
    result.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace mipraster
