#pragma once
// The depth test of one triangle at the samples of one pixel under MSAA (private to the pipeline):
// four samples per double vector. Each value is the tile kernel's per-sample arithmetic,
// sample_depth(screen_weights(...)), on the same numbers in the same order (no fused
// multiply-add), so the depths and outcomes are the per-sample path's bits.
#include <cstdint>

#include <immintrin.h>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace mipraster {
namespace kernels {

/// The samples of one pixel of triangle t: edges 1 and 2 at the pixel's corner (bias not added)
/// and each sample's offset from it, as doubles (exact: offsets are below 2^40).
struct PixelSamples {
    std::int64_t corner1, corner2;
    const double *offset1, *offset2;  // [s] for s < count
    int count;                        // a multiple of 4
};

// |x| < 2^51: with an offset below 2^40 added, still an integer a double holds exactly.
inline bool below_2_to_51(std::int64_t x) {
    constexpr std::int64_t kBound = std::int64_t{1} << 51;
    return x > -kBound && x < kBound;
}

/// A triangle's depth plane, z0 + l1·dz1 + l2·dz2, in four lanes (made once per triangle: inside
/// a loop that stores depths, the triangle's fields would be read again every time).
struct DepthPlane4 {
    __m256d z0, dz1, dz2;
};
[[gnu::always_inline]] [[gnu::target("avx2")]] inline DepthPlane4 depth_plane4(const SetupTriangle& t) {
    return {_mm256_set1_pd(t.z0), _mm256_set1_pd(t.dz1), _mm256_set1_pd(t.dz2)};
}

/// The depth test of four samples at screen weights l1, l2 (edges 1 and 2) against depth[0 … 3],
/// at the lanes of `lanes` (bit k: sample k): z = z0 + l1·dz1 + l2·dz2 rounded to float, as
/// sample_depth computes it; the passing depths are stored when depth_write, and all four into
/// computed[0 … 3] where it is not null. Returns the lanes that passed.
[[gnu::always_inline]] [[gnu::target("avx2")]] inline std::uint32_t test_four_depths(
    const DepthPlane4& plane, __m256d l1, __m256d l2, std::uint32_t lanes, DepthFunc func, bool depth_write,
    float* depth, float* computed = nullptr) {
    const __m128i lane_bit = _mm_setr_epi32(1, 2, 4, 8);
    const __m128 z = _mm256_cvtpd_ps(
        _mm256_add_pd(_mm256_add_pd(plane.z0, _mm256_mul_pd(l1, plane.dz1)), _mm256_mul_pd(l2, plane.dz2)));
    if (computed) _mm_storeu_ps(computed, z);
    const __m128 stored = _mm_loadu_ps(depth);
    const __m128 asked = _mm_castsi128_ps(
        _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(static_cast<std::int32_t>(lanes)), lane_bit), lane_bit));
    const __m128 wins =
        _mm_and_ps(asked, func == DepthFunc::greater ? _mm_cmpgt_ps(z, stored) : _mm_cmplt_ps(z, stored));
    const auto won = static_cast<std::uint32_t>(_mm_movemask_ps(wins));
    if (won && depth_write) _mm_storeu_ps(depth, _mm_blendv_ps(stored, z, wins));
    return won;
}

/// Tests the depth of samples `covered` (bit s: sample s) against depth[s] (less or greater) and
/// stores the passing depths when depth_write; the passing samples go to `passed`. Returns
/// false, touching nothing, when an edge value reaches 2^51 in magnitude (its sums in double
/// could round): the per-sample path then runs. Needs AVX2 (BatchSampler::widest_vector() == 8;
/// elsewhere the kernel keeps the per-sample path). Inlined into the kernel in v3 builds: a call
/// per pixel, and the kernel's registers saved around it, were 9 % of the plane's MSAA frame.
#if defined(__AVX2__)
[[gnu::always_inline]]
#endif
[[gnu::target("avx2")]] inline bool test_pixel_samples_avx2(const SetupTriangle& t, const PixelSamples& p,
                                                            std::uint64_t covered, DepthFunc func, bool depth_write,
                                                            float* depth, std::uint64_t& passed) {
    const std::int64_t e1 = p.corner1 + t.bias[1], e2 = p.corner2 + t.bias[2];
    if (!below_2_to_51(e1) || !below_2_to_51(e2)) return false;
    // screen_weights converts e + offset + bias to double; here e + bias and the offset are
    // converted apart and added: the same integer exactly, below 2^52.
    const __m256d corner1 = _mm256_set1_pd(static_cast<double>(e1)), corner2 = _mm256_set1_pd(static_cast<double>(e2));
    const __m256d inv_area2 = _mm256_set1_pd(t.inv_area2);
    const DepthPlane4 plane = depth_plane4(t);
    passed = 0;
    for (int g = 0; g < p.count; g += 4) {
        const auto lanes = static_cast<std::uint32_t>((covered >> g) & 15u);
        if (!lanes) continue;
        const __m256d l1 = _mm256_mul_pd(_mm256_add_pd(corner1, _mm256_loadu_pd(p.offset1 + g)), inv_area2);
        const __m256d l2 = _mm256_mul_pd(_mm256_add_pd(corner2, _mm256_loadu_pd(p.offset2 + g)), inv_area2);
        passed |= std::uint64_t{test_four_depths(plane, l1, l2, lanes, func, depth_write, depth + g)} << g;
    }
    return true;
}

/// The edge offsets of samples s < S (a multiple of 4) from their pixel's corner, off[e][s] =
/// a_e·x[s] + b_e·y[s], four samples per int64 vector: the 32-bit factors' products in 64 bits,
/// the scalar products exactly. Per triangle and tile; the scalar loop was 5 % of many_small's SSAA
/// 4x frame (its triangles cover a pixel or two). Needs AVX2.
#if defined(__AVX2__)
[[gnu::always_inline]]
#endif
[[gnu::target("avx2")]] inline void sample_offsets_avx2(const SetupTriangle& t, const std::int32_t* x,
                                                        const std::int32_t* y, int S,
                                                        std::int64_t* const (&off)[3]) {
    for (int g = 0; g < S; g += 4) {
        const __m256i ox = _mm256_cvtepi32_epi64(_mm_loadu_si128(reinterpret_cast<const __m128i*>(x + g)));
        const __m256i oy = _mm256_cvtepi32_epi64(_mm_loadu_si128(reinterpret_cast<const __m128i*>(y + g)));
        for (int e = 0; e < 3; ++e) {
            const __m256i a = _mm256_set1_epi64x(t.edge_a[e]), b = _mm256_set1_epi64x(t.edge_b[e]);
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(off[e] + g),
                                _mm256_add_epi64(_mm256_mul_epi32(a, ox), _mm256_mul_epi32(b, oy)));
        }
    }
}

/// Coverage masks of a row of n pixels: bit s of mask[j] is set when sample s of pixel j is
/// inside, i.e. all three edge values row[e] + off[e][s] + j·step[e] are ≥ 0 (the sign bit of
/// their OR is clear). Four samples per int64 vector, the scalar loop's integer sums exactly;
/// `samples` is a multiple of 4. A small triangle's rows are a few pixels long: the scalar loop,
/// one sample at a time across the row, was a third of many_small's MSAA 4x kernel. Needs AVX2
/// (see test_pixel_samples_avx2).
#if defined(__AVX2__)
[[gnu::always_inline]]
#endif
[[gnu::target("avx2")]] inline void pixel_coverage_avx2(const std::int64_t (&row)[3],
                                                        const std::int64_t* const (&off)[3],
                                                        const std::int64_t (&step)[3], int n, int samples,
                                                        std::uint64_t* mask) {
    const __m256i step0 = _mm256_set1_epi64x(step[0]), step1 = _mm256_set1_epi64x(step[1]),
                  step2 = _mm256_set1_epi64x(step[2]);
    // (No lambda for the first values: a lambda does not inherit the target attribute.)
    const __m256i row0 = _mm256_set1_epi64x(row[0]), row1 = _mm256_set1_epi64x(row[1]),
                  row2 = _mm256_set1_epi64x(row[2]);
    for (int g = 0; g < samples; g += 4) {
        __m256i e0 = _mm256_add_epi64(row0, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(off[0] + g)));
        __m256i e1 = _mm256_add_epi64(row1, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(off[1] + g)));
        __m256i e2 = _mm256_add_epi64(row2, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(off[2] + g)));
        for (int j = 0; j < n; ++j) {
            const __m256i any = _mm256_or_si256(_mm256_or_si256(e0, e1), e2);
            const auto inside = static_cast<std::uint64_t>(~_mm256_movemask_pd(_mm256_castsi256_pd(any)) & 15);
            mask[j] = g == 0 ? inside : mask[j] | inside << g;
            e0 = _mm256_add_epi64(e0, step0);
            e1 = _mm256_add_epi64(e1, step1);
            e2 = _mm256_add_epi64(e2, step2);
        }
    }
}

/// The sample masks of a box of n ≤ kBoxPixels pixels by `rows` ≤ kTileSize rows (SSAA or MSAA):
/// bit s of mask[r][j] is set when sample s of pixel j of row r is inside, i.e. all three edge
/// values corner[e] + off[e][s] + j·step_x[e] + r·step_y[e] are ≥ 0 (the sign bit of their OR is
/// clear); bit j of pixels[r] when mask[r][j] has any. Four samples per int64 vector (`samples` a
/// multiple of 4), the per-sample test's integer sums exactly. Returns the OR of pixels. Not
/// inlined: inside the tile kernel, a small triangle's rows of masks spilled most of its values
/// (many_small SSAA 4x: 96 instructions a row). Needs AVX2.
inline constexpr int kBoxPixels = 8;
[[gnu::noinline]] [[gnu::target("avx2")]] inline std::uint32_t box_sample_masks_avx2(
    const std::int64_t (&corner)[3], const std::int64_t* const (&off)[3], const std::int64_t (&step_x)[3],
    const std::int64_t (&step_y)[3], int n, int rows, int samples, std::uint64_t (*mask)[kBoxPixels],
    std::uint8_t* pixels) {
    __m256i across[3], down[3];
    for (int e = 0; e < 3; ++e) across[e] = _mm256_set1_epi64x(step_x[e]), down[e] = _mm256_set1_epi64x(step_y[e]);
    std::uint32_t any_pixel = 0;
    for (int g = 0; g < samples; g += 4) {
        __m256i row[3];  // samples g … g + 3 of the row's first pixel
        for (int e = 0; e < 3; ++e)
            row[e] = _mm256_add_epi64(_mm256_set1_epi64x(corner[e]),
                                      _mm256_loadu_si256(reinterpret_cast<const __m256i*>(off[e] + g)));
        for (int r = 0; r < rows; ++r) {
            __m256i at[3] = {row[0], row[1], row[2]};
            std::uint32_t bits = 0;  // the row's pixels with one of these samples inside
            for (int j = 0; j < n; ++j) {
                const __m256i any = _mm256_or_si256(_mm256_or_si256(at[0], at[1]), at[2]);
                const auto inside = static_cast<std::uint64_t>(~_mm256_movemask_pd(_mm256_castsi256_pd(any)) & 15);
                mask[r][j] = g == 0 ? inside : mask[r][j] | inside << g;
                bits |= static_cast<std::uint32_t>(inside != 0) << j;
                for (int e = 0; e < 3; ++e) at[e] = _mm256_add_epi64(at[e], across[e]);
            }
            pixels[r] = static_cast<std::uint8_t>(g == 0 ? bits : pixels[r] | bits);
            any_pixel |= bits;
            for (int e = 0; e < 3; ++e) row[e] = _mm256_add_epi64(row[e], down[e]);
        }
    }
    return any_pixel;
}

// Edge values first + k·step in lanes k = 0 … 3: step in the odd lanes plus 2·step in the upper
// two (AVX2 has no 64-bit multiply).
[[gnu::always_inline]] [[gnu::target("avx2")]] inline __m256i four_steps(std::int64_t first, std::int64_t step) {
    const __m256i s = _mm256_set1_epi64x(step), twice = _mm256_add_epi64(s, s);
    return _mm256_add_epi64(_mm256_set1_epi64x(first),
                            _mm256_add_epi64(_mm256_and_si256(s, _mm256_setr_epi64x(0, -1, 0, -1)),
                                             _mm256_and_si256(twice, _mm256_setr_epi64x(0, 0, -1, -1))));
}

// Bits 0 … 3 of four pixels' points that lie outside: the sign bit of the OR of their three edge
// values.
[[gnu::always_inline]] [[gnu::target("avx2")]] inline std::uint32_t outside_four(const __m256i (&e)[3]) {
    return static_cast<std::uint32_t>(
        _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_or_si256(_mm256_or_si256(e[0], e[1]), e[2]))));
}

/// The coverage of a box of n ≤ 8 pixels by `rows` rows at one sample a pixel: bit j of cover[r]
/// is set when the sample of pixel j of row r is inside, i.e. all three edge values
/// first[e] + j·step_x[e] + r·step_y[e] are ≥ 0 (the sign bit of their OR is clear). A row's eight
/// pixels in two int64 vectors, the per-pixel test's integer sums exactly. Returns the OR of the
/// rows' masks. A small triangle's box, tested pixel by pixel with each row's edge values from
/// multiplies, was a third of many_small's kernel at one sample a pixel. Needs AVX2.
#if defined(__AVX2__)
[[gnu::always_inline]]
#endif
[[gnu::target("avx2")]] inline std::uint32_t box_coverage_avx2(const std::int64_t (&first)[3],
                                                               const std::int64_t (&step_x)[3],
                                                               const std::int64_t (&step_y)[3], int n, int rows,
                                                               std::uint8_t* cover) {
    __m256i left[3], right[3], down[3];  // pixels 0 … 3 and 4 … 7 of the current row
    for (int e = 0; e < 3; ++e) {
        left[e] = four_steps(first[e], step_x[e]);
        right[e] = _mm256_add_epi64(left[e], _mm256_set1_epi64x(4 * step_x[e]));
        down[e] = _mm256_set1_epi64x(step_y[e]);
    }
    const std::uint32_t in_box = (1u << n) - 1;
    std::uint32_t any = 0;
    for (int r = 0; r < rows; ++r) {
        std::uint32_t outside = outside_four(left);
        for (int e = 0; e < 3; ++e) left[e] = _mm256_add_epi64(left[e], down[e]);
        if (n > 4) {
            outside |= outside_four(right) << 4;
            for (int e = 0; e < 3; ++e) right[e] = _mm256_add_epi64(right[e], down[e]);
        }
        cover[r] = static_cast<std::uint8_t>(~outside & in_box);
        any |= cover[r];
    }
    return any;
}

/// The coverage of n ≤ kTileSize points along a row, one a pixel: bit j is set when all three
/// edge values first[e] + j·step[e] are ≥ 0. Four pixels per int64 vector, the integer test
/// exactly (MSAA rows ask it of their pixels' centres: tested pixel by pixel, with a row's
/// multiplies, it was 4 % of the plane's MSAA 4x frame). Needs AVX2.
#if defined(__AVX2__)
[[gnu::always_inline]]
#endif
[[gnu::target("avx2")]] inline std::uint32_t row_coverage_avx2(const std::int64_t (&first)[3],
                                                               const std::int64_t (&step)[3], int n) {
    static_assert(kTileSize <= 32, "a row's pixels in a uint32");
    __m256i e[3], four[3];
    for (int k = 0; k < 3; ++k) e[k] = four_steps(first[k], step[k]), four[k] = _mm256_set1_epi64x(4 * step[k]);
    std::uint32_t outside = 0;
    for (int j = 0; j < n; j += 4) {
        outside |= outside_four(e) << j;
        for (int k = 0; k < 3; ++k) e[k] = _mm256_add_epi64(e[k], four[k]);
    }
    return ~outside & (n >= 32 ? ~0u : (1u << n) - 1);
}

}  // namespace kernels
}  // namespace mipraster
