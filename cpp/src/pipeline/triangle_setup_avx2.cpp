// setup_four_triangles: setup_triangle (triangle_setup.cpp) for four triangles at once, one per
// vector element, with the same integer and double operations element by element; and
// classify_and_project_four: outcode and project_vertex for four vertices the same way. The
// scalar setup took a fifth of a frame of a million small triangles, most of it the depth planes'
// double arithmetic, one triangle's chain of operations after the other.
//
// Where AVX2 has no instruction for a scalar step, the step is built from exact pieces: int64
// products from 32 × 32-bit multiplies (every factor fits 32 bits: coordinates within
// ±kMaxFixedCoordinate), ⌊x / 256⌋ of an int32 as an arithmetic shift, and int64 → double as
// high·2³² + low, each exact, added with one rounding (the conversion's).
#include <immintrin.h>

#include <cstdint>
#include <limits>

#include "mipraster/pipeline/triangle_setup.hpp"

namespace mipraster {

#if defined(__x86_64__)

namespace {

// A vector's elements into an array.
[[gnu::target("avx2")]] inline void store(double (&to)[4], __m256d x) { _mm256_storeu_pd(to, x); }
[[gnu::target("avx2")]] inline void store(std::int64_t (&to)[4], __m256i x) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(to), x);
}
[[gnu::target("avx2")]] inline void store(std::int32_t (&to)[4], __m128i x) {
    _mm_storeu_si128(reinterpret_cast<__m128i*>(to), x);
}

// static_cast<double> of four int64, rounded as the scalar conversion rounds: the high (signed)
// and low (unsigned) 32 bits are exact doubles, and their sum rounds once.
[[gnu::target("avx2")]] inline __m256d to_double(__m256i x) {
    const __m256i odd = _mm256_setr_epi32(1, 3, 5, 7, 0, 2, 4, 6), even = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
    const __m128i high = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(x, odd));
    const __m128i low = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(x, even));
    const __m256d low_unsigned = _mm256_add_pd(_mm256_cvtepi32_pd(_mm_xor_si128(low, _mm_set1_epi32(INT32_MIN))),
                                               _mm256_set1_pd(0x1p31));
    return _mm256_add_pd(_mm256_mul_pd(_mm256_cvtepi32_pd(high), _mm256_set1_pd(0x1p32)), low_unsigned);
}

// Products of int32 elements as int64.
[[gnu::target("avx2")]] inline __m256i multiply(__m128i a, __m128i b) {
    return _mm256_mul_epi32(_mm256_cvtepi32_epi64(a), _mm256_cvtepi32_epi64(b));
}

// x < y ? y : x (std::max's choice) and y < x ? y : x (std::min's), element by element.
[[gnu::target("avx2")]] inline __m256d max_of(__m256d x, __m256d y) {
    return _mm256_blendv_pd(x, y, _mm256_cmp_pd(x, y, _CMP_LT_OQ));
}
[[gnu::target("avx2")]] inline __m256d min_of(__m256d x, __m256d y) {
    return _mm256_blendv_pd(x, y, _mm256_cmp_pd(y, x, _CMP_LT_OQ));
}

// The pixel of a 1/256 px coordinate (floor_to_pixel of triangle_setup.cpp, for int32).
inline __m128i to_pixel(__m128i x) { return _mm_srai_epi32(x, kSubpixelBits); }

// All-ones where x is finite (std::isfinite).
[[gnu::target("avx2")]] inline __m256d finite(__m256d x) {
    return _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), x),
                         _mm256_set1_pd(std::numeric_limits<double>::infinity()), _CMP_LT_OQ);
}

}  // namespace

[[gnu::target("avx2")]] int setup_four_triangles(const ScreenVertex* const (&v)[4][3], int count,
                                                 const Viewport& viewport, CullMode cull, SetupTriangle (&out)[4],
                                                 SetupCounters& counters) {
    // The vertices' fields, vertex k of triangle i in element i.
    __m128i X[3], Y[3];
    __m256d inv_w[3], depth[3], snap_x[3], snap_y[3];
    const auto lane = [&](int i) { return i < count ? i : 0; };  // (lanes past the count repeat the first)
    for (int k = 0; k < 3; ++k) {
        const ScreenVertex &a = *v[0][k], &b = *v[lane(1)][k], &c = *v[lane(2)][k], &d = *v[lane(3)][k];
        X[k] = _mm_setr_epi32(a.x, b.x, c.x, d.x);
        Y[k] = _mm_setr_epi32(a.y, b.y, c.y, d.y);
        inv_w[k] = _mm256_setr_pd(a.inv_w, b.inv_w, c.inv_w, d.inv_w);
        depth[k] = _mm256_setr_pd(a.depth, b.depth, c.depth, d.depth);
        snap_x[k] = _mm256_cvtps_pd(_mm_setr_ps(a.snap_x, b.snap_x, c.snap_x, d.snap_x));
        snap_y[k] = _mm256_cvtps_pd(_mm_setr_ps(a.snap_y, b.snap_y, c.snap_y, d.snap_y));
    }
    const __m256d zero = _mm256_setzero_pd();

    // Step 1: valid vertices (inv_w > 0).
    const int valid = _mm256_movemask_pd(_mm256_and_pd(
        _mm256_and_pd(_mm256_cmp_pd(inv_w[0], zero, _CMP_GT_OQ), _mm256_cmp_pd(inv_w[1], zero, _CMP_GT_OQ)),
        _mm256_cmp_pd(inv_w[2], zero, _CMP_GT_OQ)));

    // Step 2: twice the signed area (coordinate differences fit 31 bits), orientation and culling.
    const __m256i area2 = _mm256_sub_epi64(multiply(_mm_sub_epi32(X[1], X[0]), _mm_sub_epi32(Y[2], Y[0])),
                                           multiply(_mm_sub_epi32(Y[1], Y[0]), _mm_sub_epi32(X[2], X[0])));
    const __m256i zero64 = _mm256_setzero_si256();
    const int degenerate = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(area2, zero64)));
    const __m256i clockwise64 = _mm256_cmpgt_epi64(area2, zero64);  // area2 > 0: sign = 1
    const int clockwise = _mm256_movemask_pd(_mm256_castsi256_pd(clockwise64));
    const int counter_clockwise = ~clockwise & ~degenerate & 0xF;
    const int culled = cull == CullMode::back ? clockwise : cull == CullMode::front ? counter_clockwise : 0;

    // Step 3: bounds in pixels (⌊x / 256⌋: an arithmetic shift), those with a sample position inside
    // the triangle's box, inside the viewport; outside it, or between the samples (as setup_triangle).
    const __m128i zero32 = _mm_setzero_si128();
    const __m128i last_x = _mm_set1_epi32(viewport.width - 1), last_y = _mm_set1_epi32(viewport.height - 1);
    const __m128i lo_x = _mm_min_epi32(_mm_min_epi32(X[0], X[1]), X[2]);
    const __m128i hi_x = _mm_max_epi32(_mm_max_epi32(X[0], X[1]), X[2]);
    const __m128i lo_y = _mm_min_epi32(_mm_min_epi32(Y[0], Y[1]), Y[2]);
    const __m128i hi_y = _mm_max_epi32(_mm_max_epi32(Y[0], Y[1]), Y[2]);
    const int outside = _mm_movemask_ps(_mm_castsi128_ps(
        _mm_or_si128(_mm_or_si128(_mm_cmpgt_epi32(zero32, to_pixel(hi_x)), _mm_cmpgt_epi32(to_pixel(lo_x), last_x)),
                     _mm_or_si128(_mm_cmpgt_epi32(zero32, to_pixel(hi_y)), _mm_cmpgt_epi32(to_pixel(lo_y), last_y)))));
    const __m128i to_first_x = _mm_set1_epi32(Viewport::kLastSubpixel - viewport.sample_x1);
    const __m128i to_first_y = _mm_set1_epi32(Viewport::kLastSubpixel - viewport.sample_y1);
    const __m128i min_x = _mm_max_epi32(to_pixel(_mm_add_epi32(lo_x, to_first_x)), zero32);
    const __m128i max_x = _mm_min_epi32(to_pixel(_mm_sub_epi32(hi_x, _mm_set1_epi32(viewport.sample_x0))), last_x);
    const __m128i min_y = _mm_max_epi32(to_pixel(_mm_add_epi32(lo_y, to_first_y)), zero32);
    const __m128i max_y = _mm_min_epi32(to_pixel(_mm_sub_epi32(hi_y, _mm_set1_epi32(viewport.sample_y0))), last_y);
    const int between_samples = _mm_movemask_ps(
        _mm_castsi128_ps(_mm_or_si128(_mm_cmpgt_epi32(min_x, max_x), _mm_cmpgt_epi32(min_y, max_y))));

    // Each triangle's outcome, under the first reason that applies, as setup_triangle counts it.
    int set_up = 0;
    for (int i = 0; i < count; ++i) {
        const int bit = 1 << i;
        if (!(valid & bit)) ++counters.dropped_nonfinite;
        else if (degenerate & bit) ++counters.culled_degenerate;
        else if (culled & bit) ++counters.culled_backface;
        else if (outside & bit) ++counters.culled_outside;
        else if (between_samples & bit) ++counters.culled_between_samples;
        else set_up |= bit;
    }
    if (!set_up) return 0;

    // Step 4: edge equations with the top-left rule. sign·d as (d ^ s) − s, s = 0 or −1.
    const __m128i negative = _mm_xor_si128(_mm256_castsi256_si128(_mm256_permutevar8x32_epi32(
                                               clockwise64, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7))),
                                           _mm_set1_epi32(-1));  // sign = −1
    const auto times_sign = [&](__m128i d) { return _mm_sub_epi32(_mm_xor_si128(d, negative), negative); };
    std::int32_t edge_a[3][4], edge_b[3][4], bias[3][4];
    std::int64_t edge_c[3][4];
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3, k = (i + 2) % 3;
        const __m128i a = times_sign(_mm_sub_epi32(Y[j], Y[k])), b = times_sign(_mm_sub_epi32(X[k], X[j]));
        const __m256i c = _mm256_sub_epi64(zero64, _mm256_add_epi64(multiply(a, X[j]), multiply(b, Y[j])));
        const __m128i top_left = _mm_or_si128(
            _mm_cmpgt_epi32(a, zero32), _mm_and_si128(_mm_cmpeq_epi32(a, zero32), _mm_cmpgt_epi32(b, zero32)));
        const __m128i one_unless_top_left = _mm_andnot_si128(top_left, _mm_set1_epi32(1));
        store(edge_a[i], a);
        store(edge_b[i], b);
        store(bias[i], one_unless_top_left);
        store(edge_c[i], _mm256_sub_epi64(c, _mm256_cvtepi32_epi64(one_unless_top_left)));
    }
    // sign·area2 = |area2| ≥ 1 for the triangles set up.
    const __m256i magnitude = _mm256_blendv_epi8(_mm256_sub_epi64(zero64, area2), area2, clockwise64);
    double inv_area2[4];
    store(inv_area2, _mm256_div_pd(_mm256_set1_pd(1.0), to_double(magnitude)));

    // Step 5: the depth planes, each vertex's depth moved along the unsnapped plane to where it
    // snapped (see setup_triangle).
    __m256d z[3] = {depth[0], depth[1], depth[2]};
    {
        __m256d px[3], py[3];
        for (int k = 0; k < 3; ++k) {
            px[k] = _mm256_sub_pd(_mm256_cvtepi32_pd(X[k]), snap_x[k]);
            py[k] = _mm256_sub_pd(_mm256_cvtepi32_pd(Y[k]), snap_y[k]);
        }
        const __m256d ex1 = _mm256_sub_pd(px[1], px[0]), ey1 = _mm256_sub_pd(py[1], py[0]);
        const __m256d ex2 = _mm256_sub_pd(px[2], px[0]), ey2 = _mm256_sub_pd(py[2], py[0]);
        const __m256d dz1 = _mm256_sub_pd(z[1], z[0]), dz2 = _mm256_sub_pd(z[2], z[0]);
        const __m256d inverse = _mm256_div_pd(_mm256_set1_pd(1.0),
                                              _mm256_sub_pd(_mm256_mul_pd(ex1, ey2), _mm256_mul_pd(ey1, ex2)));
        const __m256d gx = _mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(dz1, ey2), _mm256_mul_pd(dz2, ey1)), inverse);
        const __m256d gy = _mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(dz2, ex1), _mm256_mul_pd(dz1, ex2)), inverse);
        const __m256d range = _mm256_sub_pd(max_of(max_of(z[0], z[1]), z[2]), min_of(min_of(z[0], z[1]), z[2]));
        const __m256d low = _mm256_xor_pd(range, _mm256_set1_pd(-0.0));  // −range
        for (int k = 0; k < 3; ++k) {
            const __m256d shift = _mm256_add_pd(_mm256_mul_pd(gx, snap_x[k]), _mm256_mul_pd(gy, snap_y[k]));
            // std::clamp(shift, −range, range): shift < −range ? −range : range < shift ? range : shift.
            const __m256d below_high = _mm256_blendv_pd(shift, range, _mm256_cmp_pd(range, shift, _CMP_LT_OQ));
            const __m256d clamped = _mm256_blendv_pd(below_high, low, _mm256_cmp_pd(shift, low, _CMP_LT_OQ));
            const __m256d moves = _mm256_and_pd(_mm256_cmp_pd(shift, zero, _CMP_NEQ_UQ), finite(shift));
            z[k] = _mm256_blendv_pd(z[k], _mm256_add_pd(z[k], clamped), moves);
        }
    }
    double z0[4], dz1[4], dz2[4];
    store(z0, z[0]);
    store(dz1, _mm256_sub_pd(z[1], z[0]));
    store(dz2, _mm256_sub_pd(z[2], z[0]));

    // 1/w scaled by the power of two that brings the largest to [1, 2): the scale's exponent field
    // is 2046 − the largest's.
    const __m256d largest = max_of(max_of(inv_w[0], inv_w[1]), inv_w[2]);
    const __m256i field = _mm256_srli_epi64(_mm256_castpd_si256(largest), 52);
    const __m256d scale = _mm256_castsi256_pd(_mm256_slli_epi64(_mm256_sub_epi64(_mm256_set1_epi64x(2046), field), 52));
    float scaled_inv_w[3][4];
    const __m128 smallest = _mm_set1_ps(std::numeric_limits<float>::min());
    for (int k = 0; k < 3; ++k) {
        const __m128 w = _mm256_cvtpd_ps(_mm256_mul_pd(inv_w[k], scale));
        _mm_storeu_ps(scaled_inv_w[k], _mm_blendv_ps(w, smallest, _mm_cmplt_ps(w, smallest)));  // std::max
    }

    std::int32_t bounds[4][4];
    store(bounds[0], min_x), store(bounds[1], min_y), store(bounds[2], max_x), store(bounds[3], max_y);
    for (int i = 0; i < 4; ++i) {
        if (!(set_up >> i & 1)) continue;
        SetupTriangle& t = out[i];
        for (int e = 0; e < 3; ++e) {
            t.edge_a[e] = edge_a[e][i];
            t.edge_b[e] = edge_b[e][i];
            t.edge_c[e] = edge_c[e][i];
            t.bias[e] = static_cast<std::int8_t>(bias[e][i]);
            t.inv_w[e] = scaled_inv_w[e][i];
        }
        t.min_x = bounds[0][i], t.min_y = bounds[1][i], t.max_x = bounds[2][i], t.max_y = bounds[3][i];
        t.inv_area2 = inv_area2[i];
        t.z0 = z0[i], t.dz1 = dz1[i], t.dz2 = dz2[i];
    }
    return set_up;
}

[[gnu::target("avx2")]] void classify_and_project_four(const glm::dvec4* p, const ClipVolume& volume,
                                                       const Viewport& viewport, std::uint8_t* outcodes,
                                                       ScreenVertex* screen) {
    // The four positions' x, y, z and w, vertex i in element i.
    const __m256d r0 = _mm256_loadu_pd(&p[0].x), r1 = _mm256_loadu_pd(&p[1].x);
    const __m256d r2 = _mm256_loadu_pd(&p[2].x), r3 = _mm256_loadu_pd(&p[3].x);
    const __m256d xz01 = _mm256_unpacklo_pd(r0, r1), yw01 = _mm256_unpackhi_pd(r0, r1);
    const __m256d xz23 = _mm256_unpacklo_pd(r2, r3), yw23 = _mm256_unpackhi_pd(r2, r3);
    const __m256d X = _mm256_permute2f128_pd(xz01, xz23, 0x20), Z = _mm256_permute2f128_pd(xz01, xz23, 0x31);
    const __m256d Y = _mm256_permute2f128_pd(yw01, yw23, 0x20), W = _mm256_permute2f128_pd(yw01, yw23, 0x31);

    const int all_finite =
        _mm256_movemask_pd(_mm256_and_pd(_mm256_and_pd(finite(X), finite(Y)), _mm256_and_pd(finite(Z), finite(W))));
    // ClipPlane::distance, outside where !(d ≥ 0).
    int outside[kClipPlaneCount];
    for (int k = 0; k < kClipPlaneCount; ++k) {
        const ClipPlane& plane = volume.planes[k];
        const __m256d d = _mm256_add_pd(
            _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(plane.normal.x), X),
                                                      _mm256_mul_pd(_mm256_set1_pd(plane.normal.y), Y)),
                                        _mm256_mul_pd(_mm256_set1_pd(plane.normal.z), Z)),
                          _mm256_mul_pd(_mm256_set1_pd(plane.normal.w), W)),
            _mm256_set1_pd(plane.offset));
        outside[k] = _mm256_movemask_pd(_mm256_cmp_pd(d, _mm256_setzero_pd(), _CMP_NGE_UQ));
    }
    int inside = 0;  // (bit i: vertex i's outcode is 0)
    for (int i = 0; i < 4; ++i) {
        std::uint8_t code = kNonFinite;
        if (all_finite >> i & 1) {
            code = 0;
            for (int k = 0; k < kClipPlaneCount; ++k) code |= static_cast<std::uint8_t>((outside[k] >> i & 1) << k);
        }
        outcodes[i] = code;
        inside |= (code == 0) << i;
    }
    if (!inside) return;

    // project_vertex's operations, in its order.
    const __m256d one = _mm256_set1_pd(1.0), subpixel = _mm256_set1_pd(static_cast<double>(kSubpixelOne));
    const __m256d inv_w = _mm256_div_pd(one, W);
    const __m256d x = _mm256_mul_pd(
        _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(X, inv_w), one), _mm256_set1_pd(0.5 * viewport.width)), subpixel);
    const __m256d y = _mm256_mul_pd(
        _mm256_mul_pd(_mm256_sub_pd(one, _mm256_mul_pd(Y, inv_w)), _mm256_set1_pd(0.5 * viewport.height)), subpixel);
    // nearbyint: to nearest, ties to even (the default rounding mode).
    const __m256d xs = _mm256_round_pd(x, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    const __m256d ys = _mm256_round_pd(y, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    const __m256d z = _mm256_mul_pd(Z, inv_w);
    const __m256d depth = viewport.depth_convention == DepthConvention::opengl
                              ? _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(0.5), z), _mm256_set1_pd(0.5))
                              : z;
    const __m256d limit = _mm256_set1_pd(static_cast<double>(kMaxFixedCoordinate));
    const __m256d sign_bit = _mm256_set1_pd(-0.0);
    const __m256d in_range = _mm256_and_pd(_mm256_cmp_pd(_mm256_andnot_pd(sign_bit, xs), limit, _CMP_LE_OQ),
                                           _mm256_cmp_pd(_mm256_andnot_pd(sign_bit, ys), limit, _CMP_LE_OQ));
    const __m256d normal_positive = _mm256_and_pd(  // inv_w > 0 and std::isnormal(inv_w)
        _mm256_cmp_pd(inv_w, _mm256_set1_pd(std::numeric_limits<double>::min()), _CMP_GE_OQ),
        finite(inv_w));
    const int valid = _mm256_movemask_pd(_mm256_and_pd(_mm256_and_pd(in_range, finite(depth)), normal_positive));
    std::int32_t xi[4], yi[4];
    float snap_x[4], snap_y[4];
    double w[4], depths[4];
    // (Integer conversions of the invalid elements too: out of range, they give INT_MIN, unused.)
    _mm_storeu_si128(reinterpret_cast<__m128i*>(xi), _mm256_cvttpd_epi32(xs));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(yi), _mm256_cvttpd_epi32(ys));
    _mm_storeu_ps(snap_x, _mm256_cvtpd_ps(_mm256_sub_pd(xs, x)));
    _mm_storeu_ps(snap_y, _mm256_cvtpd_ps(_mm256_sub_pd(ys, y)));
    _mm256_storeu_pd(w, inv_w);
    _mm256_storeu_pd(depths, depth);
    for (int i = 0; i < 4; ++i) {
        if (!(inside >> i & 1)) continue;
        ScreenVertex v{};
        v.depth = depths[i];
        if (valid >> i & 1) {
            v.x = xi[i], v.y = yi[i];
            v.snap_x = snap_x[i], v.snap_y = snap_y[i];
            v.inv_w = w[i];
        }
        screen[i] = v;
    }
}

bool setup_in_fours() {
    static const bool avx2 = __builtin_cpu_supports("avx2");
    return avx2;
}

#else

int setup_four_triangles(const ScreenVertex* const (&v)[4][3], int count, const Viewport& viewport, CullMode cull,
                         SetupTriangle (&out)[4], SetupCounters& counters) {
    int set_up = 0;
    for (int i = 0; i < count; ++i)
        if (setup_triangle({*v[i][0], *v[i][1], *v[i][2]}, viewport, cull, out[i], counters)) set_up |= 1 << i;
    return set_up;
}

void classify_and_project_four(const glm::dvec4* p, const ClipVolume& volume, const Viewport& viewport,
                               std::uint8_t* outcodes, ScreenVertex* screen) {
    for (int i = 0; i < 4; ++i) {
        const bool finite = std::isfinite(p[i].x) && std::isfinite(p[i].y) && std::isfinite(p[i].z) &&
                            std::isfinite(p[i].w);
        outcodes[i] = finite ? outcode(p[i], volume) : kNonFinite;
        if (outcodes[i] == 0) screen[i] = project_vertex(p[i], viewport);
    }
}

bool setup_in_fours() { return false; }

#endif

}  // namespace mipraster
