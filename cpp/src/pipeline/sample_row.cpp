#include "sample_row.hpp"

#include <cstddef>

#include <immintrin.h>

#include "pixel_samples.hpp"

namespace mipraster {
namespace kernels {

namespace {

// Whether e_i + bias_i stays below `bound` in magnitude at the first and last of the n pixels.
bool row_within(const SetupTriangle& t, const std::int64_t (&e)[3], int n, std::int64_t bound) {
    for (int i = 0; i < 3; ++i) {
        const std::int64_t first = e[i] + t.bias[i], last = first + std::int64_t{t.edge_a[i]} * kSubpixelOne * (n - 1);
        if (!(first > -bound && first < bound && last > -bound && last < bound)) return false;
    }
    return true;
}

// Below 2^52 every integer between two such values, and their sums with the row's steps, is a
// double, so the sums below are exact.
inline bool exact_row(const SetupTriangle& t, const std::int64_t (&e)[3], int n) {
    return row_within(t, e, n, std::int64_t{1} << 52);
}

// The row's edge values plus bias, e_i + bias_i + j·step_i at pixel j, two pixels per register:
// the per-sample path converts each to double; here the first is converted once and the steps
// added, the same integers exactly while exact_row holds.
struct RowEdges {
    __m128d first[3], step[3];
    RowEdges(const SetupTriangle& t, const std::int64_t (&e)[3]) {
        for (int i = 0; i < 3; ++i) {
            first[i] = _mm_set1_pd(static_cast<double>(e[i] + t.bias[i]));
            step[i] = _mm_set1_pd(static_cast<double>(std::int64_t{t.edge_a[i]} * kSubpixelOne));
        }
    }
    // Edge i at pixels j and j + 1.
    __m128d at(int i, int j) const {
        return _mm_add_pd(first[i], _mm_mul_pd(_mm_set_pd(double(j + 1), double(j)), step[i]));
    }
};

// The stored depths of `lanes` ≤ 4 pixels `stride` floats apart. A short group or a stride is
// built in registers (scalar stores then a vector load would wait for store forwarding).
inline __m128 stored_depths(const float* p, int stride, int lanes) {
    if (lanes == 4 && stride == 1) return _mm_loadu_ps(p);
    return _mm_setr_ps(p[0], lanes > 1 ? p[stride] : 0.0f, lanes > 2 ? p[2 * stride] : 0.0f,
                       lanes > 3 ? p[3 * stride] : 0.0f);
}

// Stores the depths of the passed lanes (bits of `passed`, the lanes where `wins` is set).
inline void store_depths(float* p, int stride, int lanes, std::uint32_t passed, __m128 wins, __m128 depths, __m128 s) {
    if (lanes == 4 && stride == 1) return _mm_storeu_ps(p, _mm_or_ps(_mm_and_ps(wins, depths), _mm_andnot_ps(wins, s)));
    alignas(16) float z[4];
    _mm_store_ps(z, depths);
    for (std::uint32_t m = passed; m; m &= m - 1) p[__builtin_ctz(m) * stride] = z[__builtin_ctz(m)];
}

}  // namespace

bool sample_rows_exact(const SetupTriangle& t, const std::int64_t (&corner)[3], int n) {
    // A sample's offset from its pixel's corner moves an edge value by less than 2^40 (|a|, |b| <
    // 2^31, offsets < 256): from 2^51 at the corners no sample's row reaches 2^52.
    return row_within(t, corner, n, std::int64_t{1} << 51);
}

// SSE2 (the x86-64 baseline): two doubles per register. Each product and sum is rounded on its
// own, as in the per-sample path (intrinsics are never contracted).
bool test_sample_row_sse2(const SetupTriangle& t, const std::int64_t (&e)[3], int n, std::uint32_t tested,
                          DepthFunc func, bool depth_write, float* depth, int stride, SampleRow& out) {
    if (!exact_row(t, e, n)) return false;
    const RowEdges edges(t, e);
    __m128d bias[3];
    for (int i = 0; i < 3; ++i) bias[i] = _mm_set1_pd(static_cast<double>(t.bias[i]));
    const __m128d inv_area2 = _mm_set1_pd(t.inv_area2), z0 = _mm_set1_pd(t.z0), dz1 = _mm_set1_pd(t.dz1),
                  dz2 = _mm_set1_pd(t.dz2);
    const bool greater = func == DepthFunc::greater, tests = func != DepthFunc::none;
    out.covered = out.passed = 0;
    const __m128i lane_bit = _mm_set_epi32(8, 4, 2, 1);
    for (int j = 0; j < n; j += 4) {
        // Two pixels per half: j, j + 1 and j + 2, j + 3.
        __m128d l0[2], l1[2], l2[2], inside[2];
        __m128 z[2];
        for (int h = 0; h < 2; ++h) {
            const __m128d d0 = edges.at(0, j + 2 * h), d1 = edges.at(1, j + 2 * h), d2 = edges.at(2, j + 2 * h);
            // e_i ≥ 0 ⇔ e_i + bias_i ≥ bias_i, both exact.
            inside[h] =
                _mm_and_pd(_mm_and_pd(_mm_cmpge_pd(d0, bias[0]), _mm_cmpge_pd(d1, bias[1])), _mm_cmpge_pd(d2, bias[2]));
            l0[h] = _mm_mul_pd(d0, inv_area2);  // screen_weights
            l1[h] = _mm_mul_pd(d1, inv_area2);
            l2[h] = _mm_mul_pd(d2, inv_area2);
            z[h] = _mm_cvtpd_ps(_mm_add_pd(_mm_add_pd(z0, _mm_mul_pd(l1[h], dz1)), _mm_mul_pd(l2[h], dz2)));  // sample_depth
        }
        // The four lanes as floats: each 64-bit mask's low half, the two halves' depths side by side.
        const __m128 covered = _mm_shuffle_ps(_mm_castpd_ps(inside[0]), _mm_castpd_ps(inside[1]), _MM_SHUFFLE(2, 0, 2, 0));
        const __m128 depths = _mm_movelh_ps(z[0], z[1]);
        const int lanes = n - j < 4 ? n - j : 4;
        const std::uint32_t in_row = (1u << lanes) - 1u;
        out.covered |= (static_cast<std::uint32_t>(_mm_movemask_ps(covered)) & in_row) << j;
        const __m128 asked = _mm_and_ps(
            covered, _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(static_cast<std::int32_t>(tested >> j)), lane_bit), lane_bit)));
        if (!(_mm_movemask_ps(asked) & in_row)) continue;
        float* const stored = tests ? depth + j * stride : nullptr;
        const __m128 s = tests ? stored_depths(stored, stride, lanes) : _mm_setzero_ps();
        const __m128 wins =
            tests ? _mm_and_ps(asked, greater ? _mm_cmpgt_ps(depths, s) : _mm_cmplt_ps(depths, s)) : asked;
        const std::uint32_t passed = static_cast<std::uint32_t>(_mm_movemask_ps(wins)) & in_row;
        if (!passed) continue;
        out.passed |= passed << j;
        for (int h = 0; h < 2; ++h) {
            _mm_storeu_pd(out.l0 + j + 2 * h, l0[h]);
            _mm_storeu_pd(out.l1 + j + 2 * h, l1[h]);
            _mm_storeu_pd(out.l2 + j + 2 * h, l2[h]);
        }
        if (tests && depth_write) store_depths(stored, stride, lanes, passed, wins, depths, s);
    }
    return true;
}

namespace {

// Whether the samples with edge values plus bias d at a row's first pixel (four, or one in every
// lane) are inside the triangle at all n pixels: along the row the values are exact integers moving
// by a constant, so the first and the last pixel bound every one between (the inside of a large
// triangle).
[[gnu::always_inline]] [[gnu::target("avx2")]] inline bool inside_along(const __m256d (&d)[3],
                                                                       const __m256d (&step)[3],
                                                                       const __m256d (&bias)[3], int n) {
    const __m256d last = _mm256_set1_pd(n - 1.0);
    __m256d inside = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    for (int i = 0; i < 3; ++i) {
        const __m256d at_last = _mm256_add_pd(d[i], _mm256_mul_pd(last, step[i]));
        inside = _mm256_and_pd(inside, _mm256_and_pd(_mm256_cmp_pd(d[i], bias[i], _CMP_GE_OQ),
                                                     _mm256_cmp_pd(at_last, bias[i], _CMP_GE_OQ)));
    }
    return n > 0 && _mm256_movemask_pd(inside) == 15;
}

// test_sample_row_avx2's per-triangle terms, one value in every lane.
struct RowTerms {
    __m256d step[3], bias[3], inv_area2, z0, dz1, dz2;
};

[[gnu::always_inline]] [[gnu::target("avx2")]] inline void splat_row_terms(const SetupTriangle& t, RowTerms& k) {
    for (int i = 0; i < 3; ++i) {
        k.step[i] = _mm256_set1_pd(static_cast<double>(std::int64_t{t.edge_a[i]} * kSubpixelOne));
        k.bias[i] = _mm256_set1_pd(static_cast<double>(t.bias[i]));
    }
    k.inv_area2 = _mm256_set1_pd(t.inv_area2), k.z0 = _mm256_set1_pd(t.z0);
    k.dz1 = _mm256_set1_pd(t.dz1), k.dz2 = _mm256_set1_pd(t.dz2);
}

// Four pixels (indices x) of a sample's row whose first pixel's edge values plus bias are `first`:
// which are inside (bits 0 … 3), their screen weights and depths, the per-sample path's
// arithmetic (RowEdges::at; e_i ≥ 0 ⇔ e_i + bias_i ≥ bias_i, both exact).
struct FourPixels {
    __m256d l0, l1, l2;
    __m128 depths;
    std::uint32_t inside;
};

// kInside: the row is known to lie inside the triangle (inside_along), so the tests are left out.
template <bool kInside>
[[gnu::always_inline]] [[gnu::target("avx2")]] inline void four_pixels(const RowTerms& k, const __m256d (&first)[3],
                                                                      const __m256d& x, FourPixels& p) {
    __m256d d[3];
    for (int i = 0; i < 3; ++i) d[i] = _mm256_add_pd(first[i], _mm256_mul_pd(x, k.step[i]));
    p.l0 = _mm256_mul_pd(d[0], k.inv_area2), p.l1 = _mm256_mul_pd(d[1], k.inv_area2);
    p.l2 = _mm256_mul_pd(d[2], k.inv_area2);
    p.depths = _mm256_cvtpd_ps(
        _mm256_add_pd(_mm256_add_pd(k.z0, _mm256_mul_pd(p.l1, k.dz1)), _mm256_mul_pd(p.l2, k.dz2)));
    if constexpr (kInside) {
        p.inside = 15;
    } else {
        const __m256d inside = _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(d[0], k.bias[0], _CMP_GE_OQ),
                                                           _mm256_cmp_pd(d[1], k.bias[1], _CMP_GE_OQ)),
                                             _mm256_cmp_pd(d[2], k.bias[2], _CMP_GE_OQ));
        p.inside = static_cast<std::uint32_t>(_mm256_movemask_pd(inside));
    }
}

// All bits of lane k where bit k of `bits` is set (k < 4).
[[gnu::always_inline]] [[gnu::target("avx2")]] inline __m128 lane_mask(std::uint32_t bits) {
    return _mm_castsi128_ps(_mm_cmpgt_epi32(
        _mm_and_si128(_mm_set1_epi32(static_cast<std::int32_t>(bits)), _mm_setr_epi32(1, 2, 4, 8)), _mm_setzero_si128()));
}

// test_sample_row_avx2's loop over the row's pixels, four at a time (kTests: a depth test, less
// or greater; without one, every covered pixel asked for passes and depth is left alone).
template <bool kTests>
[[gnu::always_inline]] [[gnu::target("avx2")]] inline void sample_row(const RowTerms& k, const __m256d (&first)[3],
                                                                     int n, std::uint32_t tested, bool greater,
                                                                     bool depth_write, float* depth, int stride,
                                                                     SampleRow& out) {
    out.covered = out.passed = 0;
    // Pixel indices j … j + 3 (small integers: stepping them by 4 is exact; built from j each
    // time, the conversions were a chain the loop waited on).
    const __m256d four = _mm256_set1_pd(4.0);
    __m256d x = _mm256_set_pd(3.0, 2.0, 1.0, 0.0);
    for (int j = 0; j < n; j += 4, x = _mm256_add_pd(x, four)) {
        FourPixels p;
        four_pixels<false>(k, first, x, p);
        const int lanes = n - j < 4 ? n - j : 4;
        const std::uint32_t covered = p.inside & ((1u << lanes) - 1u);
        out.covered |= covered << j;
        const std::uint32_t asked = covered & (tested >> j);
        if (!asked) continue;
        std::uint32_t passed = asked;
        float* stored = nullptr;
        __m128 s = _mm_setzero_ps();
        if constexpr (kTests) {
            stored = depth + j * stride;
            s = stored_depths(stored, stride, lanes);
            passed &= static_cast<std::uint32_t>(
                _mm_movemask_ps(greater ? _mm_cmpgt_ps(p.depths, s) : _mm_cmplt_ps(p.depths, s)));
            if (!passed) continue;
        }
        out.passed |= passed << j;
        _mm256_storeu_pd(out.l0 + j, p.l0);
        _mm256_storeu_pd(out.l1 + j, p.l1);
        _mm256_storeu_pd(out.l2 + j, p.l2);
        if (kTests && depth_write) store_depths(stored, stride, lanes, passed, lane_mask(passed), p.depths, s);
    }
}

}  // namespace

// AVX2: the same operations on four doubles per register (one group of four pixels each), so the
// same bits; the depth test and stores are the SSE2 path's.
[[gnu::target("avx2")]] bool test_sample_row_avx2(const SetupTriangle& t, const std::int64_t (&e)[3], int n,
                                                  std::uint32_t tested, DepthFunc func, bool depth_write, float* depth,
                                                  int stride, SampleRow& out) {
    if (!exact_row(t, e, n)) return false;
    RowTerms k;
    splat_row_terms(t, k);
    __m256d first[3];
    for (int i = 0; i < 3; ++i) first[i] = _mm256_set1_pd(static_cast<double>(e[i] + t.bias[i]));
    const bool greater = func == DepthFunc::greater;
    if (func == DepthFunc::none)
        sample_row<false>(k, first, n, tested, greater, depth_write, depth, stride, out);
    else
        sample_row<true>(k, first, n, tested, greater, depth_write, depth, stride, out);
    return true;
}

namespace {

// test_four_sample_rows_avx2's loop over the rows' pixels, four at a time (kInside: inside_along
// holds for all four samples).
template <bool kInside>
[[gnu::always_inline]] [[gnu::target("avx2")]] inline void four_sample_rows(const RowTerms& k,
                                                                           const __m256d (&first)[4][3], int n,
                                                                           std::uint32_t tested, bool greater,
                                                                           bool depth_write, float* depth, int stride,
                                                                           SampleRow (&out)[4]) {
    const __m256d four = _mm256_set1_pd(4.0);
    __m256d x = _mm256_set_pd(3.0, 2.0, 1.0, 0.0);
    for (int j = 0; j < n; j += 4, x = _mm256_add_pd(x, four)) {
        const int lanes = n - j < 4 ? n - j : 4;
        FourPixels p[4];
        std::uint32_t asked[4], any_asked = 0;
        for (int s = 0; s < 4; ++s) {
            four_pixels<kInside>(k, first[s], x, p[s]);
            const std::uint32_t covered = p[s].inside & ((1u << lanes) - 1u);
            out[s].covered |= covered << j;
            asked[s] = covered & (tested >> j);
            any_asked |= asked[s];
        }
        if (!any_asked) continue;
        // stored[p]: pixel p's four samples; transposed, stored[s]: sample s of the pixels.
        float* const pixels = depth + static_cast<std::ptrdiff_t>(j) * stride;
        __m128 stored[4];
        for (int q = 0; q < 4; ++q) stored[q] = q < lanes ? _mm_loadu_ps(pixels + q * stride) : _mm_setzero_ps();
        _MM_TRANSPOSE4_PS(stored[0], stored[1], stored[2], stored[3]);
        bool wrote = false;
        for (int s = 0; s < 4; ++s) {
            const __m128 wins = greater ? _mm_cmpgt_ps(p[s].depths, stored[s]) : _mm_cmplt_ps(p[s].depths, stored[s]);
            const std::uint32_t passed = static_cast<std::uint32_t>(_mm_movemask_ps(wins)) & asked[s];
            if (!passed) continue;
            out[s].passed |= passed << j;
            _mm256_storeu_pd(out[s].l0 + j, p[s].l0);
            _mm256_storeu_pd(out[s].l1 + j, p[s].l1);
            _mm256_storeu_pd(out[s].l2 + j, p[s].l2);
            if (!depth_write) continue;
            stored[s] = _mm_blendv_ps(stored[s], p[s].depths, lane_mask(passed));
            wrote = true;
        }
        if (!wrote) continue;
        _MM_TRANSPOSE4_PS(stored[0], stored[1], stored[2], stored[3]);
        for (int q = 0; q < lanes; ++q) _mm_storeu_ps(pixels + q * stride, stored[q]);
    }
}

}  // namespace

// test_sample_row_avx2 for four samples at once: per sample the same operations; the depths of
// four pixels are read and written as four vectors of four samples, transposed in registers.
[[gnu::target("avx2")]] bool test_four_sample_rows_avx2(const SetupTriangle& t, const std::int64_t (&e)[4][3], int n,
                                                        std::uint32_t tested, DepthFunc func, bool depth_write,
                                                        float* depth, int stride, SampleRow (&out)[4]) {
    for (int s = 0; s < 4; ++s)
        if (!exact_row(t, e[s], n)) return false;
    RowTerms k;
    splat_row_terms(t, k);
    __m256d first[4][3];
    for (int s = 0; s < 4; ++s)
        for (int i = 0; i < 3; ++i) first[s][i] = _mm256_set1_pd(static_cast<double>(e[s][i] + t.bias[i]));
    const bool greater = func == DepthFunc::greater;
    for (SampleRow& row : out) row.covered = row.passed = 0;
    bool inside = true;
    for (int s = 0; s < 4 && inside; ++s) inside = inside_along(first[s], k.step, k.bias, n);
    if (inside)
        four_sample_rows<true>(k, first, n, tested, greater, depth_write, depth, stride, out);
    else
        four_sample_rows<false>(k, first, n, tested, greater, depth_write, depth, stride, out);
    return true;
}

namespace {

// test_pixel_row_avx2's step for four samples of a pixel at edge values d (exact integers, bias
// added): `covered` counts those inside; their depth test against depth[at … at + 3] (the
// computed depths into tested[at … at + 3] where it is not null). Returns the passed ones.
// kInside: all four are known to be inside (inside_along), and the edge tests are left out. (A
// function, not a lambda: a lambda does not take its function's target, and a baseline build
// could not inline the intrinsics into it.)
template <bool kInside>
[[gnu::always_inline]] [[gnu::target("avx2")]] inline std::uint32_t four_samples(
    const __m256d (&d)[3], const __m256d (&bias)[3], __m256d inv_area2, const DepthPlane4& plane, DepthFunc func,
    bool depth_write, float* depth, float* tested, std::ptrdiff_t at, std::uint64_t& covered) {
    std::uint32_t lanes = 15;
    if constexpr (!kInside) {
        const __m256d inside = _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(d[0], bias[0], _CMP_GE_OQ),
                                                           _mm256_cmp_pd(d[1], bias[1], _CMP_GE_OQ)),
                                             _mm256_cmp_pd(d[2], bias[2], _CMP_GE_OQ));
        lanes = static_cast<std::uint32_t>(_mm256_movemask_pd(inside));
    }
    covered += static_cast<std::uint64_t>(__builtin_popcount(lanes));
    if (!lanes) return 0;
    const __m256d l1 = _mm256_mul_pd(d[1], inv_area2), l2 = _mm256_mul_pd(d[2], inv_area2);
    return test_four_depths(plane, l1, l2, lanes, func, depth_write, depth + at, tested ? tested + at : nullptr);
}

// A row's edge terms, as test_pixel_row_avx2 steps them.
struct PixelRowTerms {
    __m256d pixel[3], step[3], bias[3], inv_area2;
    DepthPlane4 plane;
};

// test_pixel_row_avx2's loop over the pixels (kInside: every sample of the row is inside).
template <bool kInside>
[[gnu::always_inline]] [[gnu::target("avx2")]] inline PixelRowTest pixel_row(const PixelRowTerms& k, int n,
                                                                            const double* const (&offsets)[3], int S,
                                                                            DepthFunc func, bool depth_write,
                                                                            float* depth, std::uint64_t* samples,
                                                                            float* tested_depths) {
    PixelRowTest found;
    const auto record = [&](int j, std::uint64_t passed) {
        samples[j] = passed;
        found.passed += static_cast<std::uint64_t>(__builtin_popcountll(passed));
        found.pixels |= static_cast<std::uint32_t>(passed != 0) << j;
    };
    // The edge values move from pixel to pixel by adds: corner + bias + j·step + offset, exact
    // integers (below 2^52), are the same doubles in any order of the sums.
    if (S == 4) {  // (MSAA 4x) one vector a pixel, its samples' edge values stepped directly
        __m256d d[3];
        for (int i = 0; i < 3; ++i) d[i] = _mm256_add_pd(k.pixel[i], _mm256_loadu_pd(offsets[i]));
        for (int j = 0; j < n; ++j) {
            record(j, four_samples<kInside>(d, k.bias, k.inv_area2, k.plane, func, depth_write, depth, tested_depths,
                                            4 * j, found.covered));
            for (int i = 0; i < 3; ++i) d[i] = _mm256_add_pd(d[i], k.step[i]);
        }
        return found;
    }
    __m256d pixel[3] = {k.pixel[0], k.pixel[1], k.pixel[2]};
    for (int j = 0; j < n; ++j) {
        std::uint64_t passed = 0;
        for (int g = 0; g < S; g += 4) {
            __m256d d[3];
            for (int i = 0; i < 3; ++i) d[i] = _mm256_add_pd(pixel[i], _mm256_loadu_pd(offsets[i] + g));
            const std::ptrdiff_t at = static_cast<std::ptrdiff_t>(j) * S + g;
            passed |= std::uint64_t{four_samples<kInside>(d, k.bias, k.inv_area2, k.plane, func, depth_write, depth,
                                                          tested_depths, at, found.covered)}
                      << g;
        }
        record(j, passed);
        for (int i = 0; i < 3; ++i) pixel[i] = _mm256_add_pd(pixel[i], k.step[i]);
    }
    return found;
}

}  // namespace

[[gnu::target("avx2")]] PixelRowTest test_pixel_row_avx2(const SetupTriangle& t, const std::int64_t (&corner)[3],
                                                         int n, const double* const (&offsets)[3], int S,
                                                         DepthFunc func, bool depth_write, float* depth,
                                                         std::uint64_t* samples, float* tested_depths) {
    PixelRowTerms k;
    for (int i = 0; i < 3; ++i) {
        k.pixel[i] = _mm256_set1_pd(static_cast<double>(corner[i] + t.bias[i]));
        k.step[i] = _mm256_set1_pd(static_cast<double>(std::int64_t{t.edge_a[i]} * kSubpixelOne));
        k.bias[i] = _mm256_set1_pd(static_cast<double>(t.bias[i]));
    }
    k.inv_area2 = _mm256_set1_pd(t.inv_area2);
    k.plane = depth_plane4(t);
    bool inside = true;
    for (int g = 0; g < S && inside; g += 4) {
        __m256d d[3];
        for (int i = 0; i < 3; ++i) d[i] = _mm256_add_pd(k.pixel[i], _mm256_loadu_pd(offsets[i] + g));
        inside = inside_along(d, k.step, k.bias, n);
    }
    return inside ? pixel_row<true>(k, n, offsets, S, func, depth_write, depth, samples, tested_depths)
                  : pixel_row<false>(k, n, offsets, S, func, depth_write, depth, samples, tested_depths);
}

namespace {
const bool kHasAvx2 = __builtin_cpu_supports("avx2");
}

bool test_sample_row(const SetupTriangle& t, const std::int64_t (&e)[3], int n, std::uint32_t tested, DepthFunc func,
                     bool depth_write, float* depth, int stride, SampleRow& out) {
    return (kHasAvx2 ? test_sample_row_avx2 : test_sample_row_sse2)(t, e, n, tested, func, depth_write, depth, stride,
                                                                   out);
}

bool sample_row_weights_sse2(const SetupTriangle& t, const std::int64_t (&e)[3], int n, double* l0, double* l1,
                             double* l2) {
    if (!exact_row(t, e, n)) return false;
    const RowEdges edges(t, e);
    double* const out[3] = {l0, l1, l2};
    const __m128d inv_area2 = _mm_set1_pd(t.inv_area2);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < n; j += 2) _mm_storeu_pd(out[i] + j, _mm_mul_pd(edges.at(i, j), inv_area2));
    return true;
}

[[gnu::target("avx2")]] bool sample_row_weights_avx2(const SetupTriangle& t, const std::int64_t (&e)[3], int n,
                                                     double* l0, double* l1, double* l2) {
    if (!exact_row(t, e, n)) return false;
    double* const out[3] = {l0, l1, l2};
    const __m256d inv_area2 = _mm256_set1_pd(t.inv_area2);
    for (int i = 0; i < 3; ++i) {
        const __m256d first = _mm256_set1_pd(static_cast<double>(e[i] + t.bias[i]));
        const __m256d step = _mm256_set1_pd(static_cast<double>(std::int64_t{t.edge_a[i]} * kSubpixelOne));
        __m256d x = _mm256_set_pd(3.0, 2.0, 1.0, 0.0);  // (stepped as in test_sample_row_avx2)
        for (int j = 0; j < n; j += 4, x = _mm256_add_pd(x, _mm256_set1_pd(4.0)))
            _mm256_storeu_pd(out[i] + j, _mm256_mul_pd(_mm256_add_pd(first, _mm256_mul_pd(x, step)), inv_area2));
    }
    return true;
}

bool sample_row_weights(const SetupTriangle& t, const std::int64_t (&e)[3], int n, double* l0, double* l1, double* l2) {
    return (kHasAvx2 ? sample_row_weights_avx2 : sample_row_weights_sse2)(t, e, n, l0, l1, l2);
}

}  // namespace kernels
}  // namespace mipraster
