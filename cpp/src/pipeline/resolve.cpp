#include "mipraster/pipeline/resolve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "mipraster/core/constants.hpp"

namespace mipraster {

ResolveFilter parse_resolve_filter(const std::string& name) {
    try {
        return parse_reconstruction_filter(name);
    } catch (const std::invalid_argument&) {
        throw std::invalid_argument("resolve filter: unknown name '" + name + "'; expected one of " +
                                    reconstruction_filter_names());
    }
}

namespace {

typedef float Rgba __attribute__((vector_size(16)));  // one pixel (SSE's __m128 is this type)
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double RgbaDouble __attribute__((vector_size(32)));  // one AVX register, or two SSE2 ones

// Writes the RGBA pixels of a row of the output image past the cache where the CPU can (SSE's
// streaming stores, for 16-byte aligned pixels). A frame's image is larger than the cache and
// nothing reads it while the frame renders: ordinary stores first fetch each of its lines from
// memory, which was most of the cost of writing the image.
template <typename Pixel>
inline void write_row(float* dst, int n, Pixel&& pixel) {
#if defined(__SSE2__)
    if ((reinterpret_cast<std::uintptr_t>(dst) & 15) == 0) {
        for (int i = 0; i < n; ++i) _mm_stream_ps(dst + 4 * i, pixel(i));
        return;
    }
#endif
    for (int i = 0; i < n; ++i) {
        const auto v = pixel(i);
        std::memcpy(dst + 4 * i, &v, sizeof v);
    }
}

// A pixel's sample at p in double (exact).
inline RgbaDouble widen(const float* p) {
#if defined(__AVX__)
    return reinterpret_cast<RgbaDouble>(_mm256_cvtps_pd(_mm_loadu_ps(p)));  // (GCC split the generic one in four)
#else
    Rgba sample;
    std::memcpy(&sample, p, sizeof sample);
    return __builtin_convertvector(sample, RgbaDouble);
#endif
}

// The mean of the S samples at p (kSamples: S known when compiling, the loop unrolled; else 0).
// The sum in double: a float sum of samples near the float maximum would overflow to infinity,
// though their mean is finite (all four channels in one vector: per channel the same additions,
// from +0, in order). A power-of-two count divides by multiplying with its exact reciprocal
// (kPowerOfTwo; the same bits): four double divisions a pixel were most of the resolve.
// `sample(p, s)`: where sample s's RGBA is (p + 4s, or another colour in its place).
template <int kSamples, bool kPowerOfTwo, typename Sample>
inline Rgba sample_mean(const float* p, int S, double inverse, Sample&& sample) {
    const int count = kSamples ? kSamples : S;
    RgbaDouble sum{0, 0, 0, 0};
    for (int s = 0; s < count; ++s) sum += widen(sample(p, s));
    return __builtin_convertvector(kPowerOfTwo ? sum * inverse : sum / double(count), Rgba);
}
template <int kSamples, bool kPowerOfTwo>
inline Rgba sample_mean(const float* p, int S, double inverse) {
    return sample_mean<kSamples, kPowerOfTwo>(p, S, inverse, [](const float* q, int s) { return q + 4 * s; });
}

// Orders the streaming stores before whatever the thread stores next (the pool's hand-off).
inline void finish_rows() {
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

}  // namespace

void resolve_tile(const SampleWindow& samples, int x0, int y0, int x1, int y1, ResolveFilter filter, Image& out) {
    if (filter != ResolveFilter::box)
        throw std::invalid_argument("resolve_tile: the " + to_string(filter) +
                                    " filter reads neighbouring pixels; use resolve_framebuffer");
    const int S = samples.samples;
    // Every row of the rectangle through write_row, pixel(p) making a pixel of its S samples at p.
    const auto each_row = [&](auto&& pixel) {
        for (int y = y0; y < y1; ++y) {
            const float* src = samples.at(x0, y, 0);
            write_row(&out.at(x0, y, 0), x1 - x0, [&](int i) { return pixel(src + 4 * S * i); });
        }
    };
    const double inverse = 1.0 / S;
    if (S == 1) {
        each_row([](const float* p) {
            Rgba v;
            std::memcpy(&v, p, sizeof v);
            return v;
        });
    } else if (S == 4) {  // (MSAA and SSAA 4x: the sum unrolled)
        each_row([inverse](const float* p) { return sample_mean<4, true>(p, 4, inverse); });
    } else if ((S & (S - 1)) == 0) {
        each_row([S, inverse](const float* p) { return sample_mean<0, true>(p, S, inverse); });
    } else {
        each_row([S, inverse](const float* p) { return sample_mean<0, false>(p, S, inverse); });
    }
    finish_rows();
}

namespace {

// resolve_undrawn for a count of S samples (kSamples: S known when compiling, else 0).
template <int kSamples, bool kPowerOfTwo>
void resolve_undrawn_rows(const SampleWindow& samples, const SampleWindow& depth, int x0, int y0, int x1, int y1,
                          float clear_depth, const float* clear, Image& out) {
    const int S = kSamples ? kSamples : samples.samples;
    const double inverse = 1.0 / S;
    // A pixel none of whose samples was drawn: what resolve_tile makes of S clear samples.
    const Rgba clear_pixel = sample_mean<kSamples, kPowerOfTwo>(nullptr, S, inverse,
                                                                [clear](const float*, int) { return clear; });
    for (int y = y0; y < y1; ++y) {
        const float* const colour = samples.at(x0, y, 0);
        const float* const z = depth.at(x0, y, 0);
        write_row(&out.at(x0, y, 0), x1 - x0, [&](int i) {
            const float* const pixel_z = z + std::ptrdiff_t{S} * i;
            int undrawn = 0, all = S;  // (a count, or with SSE2 at four samples a mask)
#if defined(__SSE2__)
            if constexpr (kSamples == 4) {  // (the four depths in one compare)
                undrawn = _mm_movemask_ps(_mm_cmpeq_ps(_mm_loadu_ps(pixel_z), _mm_set1_ps(clear_depth)));
                all = 0xF;
            } else
#endif
            {
                for (int s = 0; s < S; ++s) undrawn += pixel_z[s] == clear_depth;
            }
            const float* const p = colour + std::ptrdiff_t{4} * S * i;
            if constexpr (kSamples == 1) {  // (resolve_tile's copy: every bit)
                Rgba v;
                std::memcpy(&v, undrawn ? clear : p, sizeof v);
                return v;
            }
            if (undrawn == 0) return sample_mean<kSamples, kPowerOfTwo>(p, S, inverse);
            if (undrawn == all) return clear_pixel;
            return sample_mean<kSamples, kPowerOfTwo>(p, S, inverse, [&](const float* q, int s) {
                return pixel_z[s] == clear_depth ? clear : q + 4 * s;  // its colour, or the clear one
            });
        });
    }
    finish_rows();
}

}  // namespace

void resolve_undrawn(const SampleWindow& samples, const SampleWindow& depth, int x0, int y0, int x1, int y1,
                     float clear_depth, const glm::vec4& clear, Image& out) {
    const int S = samples.samples;
    const float* const c = &clear.x;
    if (S == 1) resolve_undrawn_rows<1, true>(samples, depth, x0, y0, x1, y1, clear_depth, c, out);
    else if (S == 4) resolve_undrawn_rows<4, true>(samples, depth, x0, y0, x1, y1, clear_depth, c, out);
    else if ((S & (S - 1)) == 0) resolve_undrawn_rows<0, true>(samples, depth, x0, y0, x1, y1, clear_depth, c, out);
    else resolve_undrawn_rows<0, false>(samples, depth, x0, y0, x1, y1, clear_depth, c, out);
}

void write_pixels(const glm::vec4& value, int x0, int y0, int x1, int y1, Image& out) {
    Rgba v;
    std::memcpy(&v, &value, sizeof v);
    for (int y = y0; y < y1; ++y) write_row(&out.at(x0, y, 0), x1 - x0, [v](int) { return v; });
    finish_rows();
}

namespace {

// The 1-D weights of one axis: tap n ∈ [−reach, reach] (a neighbouring pixel) and sample s sit at
// n + offset_s − ½ pixels from the pixel's centre.
struct AxisTaps {
    int reach = 0;
    int samples = 0;
    std::vector<float> weights;  // [(n + reach)·S + s]

    float at(int n, int s) const { return weights[static_cast<std::size_t>(n + reach) * samples + s]; }
};

AxisTaps axis_taps(ResolveFilter filter, const std::vector<std::int32_t>& offsets) {
    AxisTaps a;
    a.samples = static_cast<int>(offsets.size());
    a.reach = static_cast<int>(std::ceil(filter_radius(filter))) + 1;
    a.weights.resize(static_cast<std::size_t>(2 * a.reach + 1) * a.samples);
    for (int n = -a.reach; n <= a.reach; ++n)
        for (int s = 0; s < a.samples; ++s)
            a.weights[static_cast<std::size_t>(n + a.reach) * a.samples + s] = static_cast<float>(
                filter_weight(filter, n + offsets[static_cast<std::size_t>(s)] / double(kSubpixelOne) - 0.5));
    return a;
}

// Rows per parallel task: a few rows of W·S samples each, enough to hide the pool's hand-off.
constexpr int kResolveRowsPerTask = 8;
static_assert(kResolveRowsPerTask >= 1, "a task holds at least one row");

}  // namespace

void resolve_framebuffer(const Framebuffer& fb, const SamplePattern& pattern, ResolveFilter filter, ThreadPool& pool,
                         Image& out) {
    const int W = fb.width, H = fb.height, S = fb.samples;
    if (pattern.count() != S)
        throw std::invalid_argument("resolve_framebuffer: the pattern has " + std::to_string(pattern.count()) +
                                    " samples, the framebuffer " + std::to_string(S));
    if (out.width != W || out.height != H || out.channels != 4) out = Image(W, H, 4);
    const AxisTaps tx = axis_taps(filter, pattern.x), ty = axis_taps(filter, pattern.y);
    const std::size_t tasks = static_cast<std::size_t>((H + kResolveRowsPerTask - 1) / kResolveRowsPerTask);
    auto rows_of = [&](std::size_t t) {
        return std::pair<int, int>(static_cast<int>(t) * kResolveRowsPerTask,
                                   std::min(H, static_cast<int>(t + 1) * kResolveRowsPerTask));
    };

    // Pass 1, along rows: per pixel and sample s, the sum over the neighbouring pixels of the
    // x-weight times sample s's colour, and (per column and sample) the sum of the x-weights
    // inside the frame. The sums in double, as the box filter's: in float, samples near the float
    // maximum summed to infinity (or, with negative lobes, to NaN) though the result is finite.
    std::vector<double> row_sums(fb.color.size());
    std::vector<double> x_weight(static_cast<std::size_t>(W) * S, 0.0);
    for (int x = 0; x < W; ++x)
        for (int n = std::max(-tx.reach, -x); n <= std::min(tx.reach, W - 1 - x); ++n)
            for (int s = 0; s < S; ++s) x_weight[static_cast<std::size_t>(x) * S + s] += tx.at(n, s);
    pool.parallel_for(tasks, [&](std::size_t t) {
        const auto [y0, y1] = rows_of(t);
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < W; ++x) {
                double* dst = &row_sums[fb.sample_index(x, y, 0) * 4];
                for (int n = std::max(-tx.reach, -x); n <= std::min(tx.reach, W - 1 - x); ++n) {
                    const float* src = &fb.color[fb.sample_index(x + n, y, 0) * 4];
                    for (int s = 0; s < S; ++s) {
                        const double w = tx.at(n, s);
                        for (int c = 0; c < 4; ++c) dst[4 * s + c] += w * src[4 * s + c];
                    }
                }
            }
    });

    // Pass 2, along columns: the y-weighted sums over the neighbouring rows and every sample,
    // divided by the total weight of the samples inside the frame.
    pool.parallel_for(tasks, [&](std::size_t t) {
        const auto [y0, y1] = rows_of(t);
        std::vector<double> y_weight(static_cast<std::size_t>(S));
        for (int y = y0; y < y1; ++y) {
            const int n0 = std::max(-ty.reach, -y), n1 = std::min(ty.reach, H - 1 - y);
            for (int s = 0; s < S; ++s) {
                y_weight[static_cast<std::size_t>(s)] = 0.0;
                for (int n = n0; n <= n1; ++n) y_weight[static_cast<std::size_t>(s)] += ty.at(n, s);
            }
            for (int x = 0; x < W; ++x) {
                double acc[4] = {0, 0, 0, 0};
                for (int n = n0; n <= n1; ++n) {
                    const double* src = &row_sums[fb.sample_index(x, y + n, 0) * 4];
                    for (int s = 0; s < S; ++s) {
                        const double w = ty.at(n, s);
                        for (int c = 0; c < 4; ++c) acc[c] += w * src[4 * s + c];
                    }
                }
                double total = 0.0;
                for (int s = 0; s < S; ++s)
                    total += x_weight[static_cast<std::size_t>(x) * S + s] * y_weight[static_cast<std::size_t>(s)];
                // (A filter with negative lobes can overshoot the largest sample: beyond float's
                // range, the nearest float is its largest.)
                constexpr double kMax = std::numeric_limits<float>::max();
                for (int c = 0; c < 4; ++c)
                    out.at(x, y, c) = static_cast<float>(std::clamp(acc[c] / total, -kMax, kMax));
            }
        }
    });
}

}  // namespace mipraster
