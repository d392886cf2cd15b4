// anisotropic_line with AVX2 (anisotropic_line.hpp), for the samplers BatchSampler covers. The
// bits are the reference's: each probe's position is the same double arithmetic, four per vector
// instead of two, with ⌊x⌋ one rounding instruction (exact) instead of a truncation and a compare;
// its quad is the same four texels blended the same way; the line's sum runs in probe order. A
// line that reaches outside the level wraps four indices per vector instead of texel by texel.
#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "anisotropic_line.hpp"

namespace mipraster {

using namespace texel;

#if defined(__x86_64__)

namespace {

constexpr int kChunk = 16;  // probes placed at a time

// wrap_index for repeat or clamp of four indices within ±(kProbeReach + 1). Repeat: a power-of-two
// size masks (two's complement); another subtracts n·trunc(i/n), the quotient from a double
// division. That remainder is in (−n, n) unless the division rounded across an integer (only for
// n ≥ 2²³), which leaves it in (−2n, 2n); the last steps bring either into [0, n).
[[gnu::target("avx2")]] inline __m128i wrap(__m128i i, int n, WrapMode mode) {
    const __m128i size = _mm_set1_epi32(n);
    if (mode == WrapMode::clamp) return _mm_min_epi32(_mm_max_epi32(i, _mm_setzero_si128()), _mm_set1_epi32(n - 1));
    if ((n & (n - 1)) == 0) return _mm_and_si128(i, _mm_set1_epi32(n - 1));
    const __m128i q = _mm256_cvttpd_epi32(_mm256_div_pd(_mm256_cvtepi32_pd(i), _mm256_set1_pd(n)));
    __m128i r = _mm_sub_epi32(i, _mm_mullo_epi32(q, size));  // within (−2n, 2n)
    for (int pass = 0; pass < 2; ++pass)  // r < 0: r + n
        r = _mm_add_epi32(r, _mm_and_si128(_mm_cmpgt_epi32(_mm_setzero_si128(), r), size));
    return _mm_sub_epi32(r, _mm_andnot_si128(_mm_cmpgt_epi32(size, r), size));  // r ≥ n: r − n
}

// Probes k0 … k0 + n − 1 of a line: for each, the quad's four texels (indices into the level) and
// its fractions.
struct Probes {
    std::int32_t texel[4][kChunk];
    float fx[kChunk], fy[kChunk];
};

[[gnu::target("avx2")]] void place(const ProbeLine& g, int k0, int n, int w, int h, bool wraps, const Sampler& s,
                                   Probes& p) {
    const __m256d step = _mm256_set1_pd(g.step);
    for (int c = 0; c < n; c += 4) {  // (a last partial vector places probes past the line's end: unread)
        const __m256d k = _mm256_add_pd(_mm256_set1_pd(k0 + c), _mm256_setr_pd(0.0, 1.0, 2.0, 3.0));
        const __m256d t = _mm256_mul_pd(k, step);
        const __m256d x = _mm256_add_pd(_mm256_set1_pd(g.x0), _mm256_mul_pd(t, _mm256_set1_pd(g.sx)));
        const __m256d y = _mm256_add_pd(_mm256_set1_pd(g.y0), _mm256_mul_pd(t, _mm256_set1_pd(g.sy)));
        const __m256d fx = _mm256_floor_pd(x), fy = _mm256_floor_pd(y);
        _mm_storeu_ps(p.fx + c, _mm256_cvtpd_ps(_mm256_sub_pd(x, fx)));
        _mm_storeu_ps(p.fy + c, _mm256_cvtpd_ps(_mm256_sub_pd(y, fy)));
        // Past the line's end a position may exceed the int range: the conversion gives INT_MIN there.
        __m128i i0 = _mm256_cvttpd_epi32(fx), j0 = _mm256_cvttpd_epi32(fy);
        const __m128i one = _mm_set1_epi32(1);
        __m128i i1 = _mm_add_epi32(i0, one), j1 = _mm_add_epi32(j0, one);
        if (wraps) {
            i0 = wrap(i0, w, s.wrap_u), i1 = wrap(i1, w, s.wrap_u);
            j0 = wrap(j0, h, s.wrap_v), j1 = wrap(j1, h, s.wrap_v);
        }
        const __m128i width = _mm_set1_epi32(w);
        const __m128i row0 = _mm_mullo_epi32(j0, width), row1 = _mm_mullo_epi32(j1, width);  // (wraps around, defined)
        _mm_storeu_si128(reinterpret_cast<__m128i*>(p.texel[0] + c), _mm_add_epi32(row0, i0));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(p.texel[1] + c), _mm_add_epi32(row0, i1));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(p.texel[2] + c), _mm_add_epi32(row1, i0));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(p.texel[3] + c), _mm_add_epi32(row1, i1));
    }
}

// Probe c's bilinear quad.
[[gnu::target("avx2")]] inline Texel quad(const glm::vec4* t, const Probes& p, int c) {
    return lerp_quad(load(t[p.texel[0][c]]), load(t[p.texel[1][c]]), load(t[p.texel[2][c]]), load(t[p.texel[3][c]]),
                     p.fx[c], p.fy[c]);
}

[[gnu::target("avx2")]] Texel line_mean(const TextureLevel& level, const ProbeLine& g, int count, const Sampler& s) {
    const glm::vec4* t = level.texels.data();
    Probes p;
    Texel first = splat(0.0f), difference = splat(0.0f);
    for (int k0 = 0; k0 < count; k0 += kChunk) {
        const int n = std::min(kChunk, count - k0);
        place(g, k0, n, level.width, level.height, !g.inside, s, p);
        int c = 0;
        if (k0 == 0) first = quad(t, p, c++);
        for (; c < n; ++c) difference += quad(t, p, c) - first;
    }
    return first + difference * splat(static_cast<float>(g.step));
}

// line_mean on two levels at once: each sum in its own probe order (the same bits), the two
// chains of additions side by side so that they overlap.
[[gnu::target("avx2")]] void line_means(const TextureLevel& a, const ProbeLine& ga, const TextureLevel& b,
                                        const ProbeLine& gb, int count, const Sampler& s, Texel& mean_a,
                                        Texel& mean_b) {
    const glm::vec4 *ta = a.texels.data(), *tb = b.texels.data();
    Probes pa, pb;
    Texel first_a = splat(0.0f), difference_a = splat(0.0f), first_b = splat(0.0f), difference_b = splat(0.0f);
    for (int k0 = 0; k0 < count; k0 += kChunk) {
        const int n = std::min(kChunk, count - k0);
        place(ga, k0, n, a.width, a.height, !ga.inside, s, pa);
        place(gb, k0, n, b.width, b.height, !gb.inside, s, pb);
        int c = 0;
        if (k0 == 0) {
            first_a = quad(ta, pa, 0);
            first_b = quad(tb, pb, 0);
            c = 1;
        }
        for (; c < n; ++c) {
            difference_a += quad(ta, pa, c) - first_a;
            difference_b += quad(tb, pb, c) - first_b;
        }
    }
    mean_a = first_a + difference_a * splat(static_cast<float>(ga.step));
    mean_b = first_b + difference_b * splat(static_cast<float>(gb.step));
}

// Whether line_mean takes g on `level` (else the reference does: too far out for int indices, or
// a level whose texel indices overflow an int).
bool vectors_reach(const ProbeLine& g, const TextureLevel& level) {
    return g.near && level.texels.size() <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
}

// The line g of the lookup (u, v, du, dv) on `level`: line_mean where it reaches, else the reference.
[[gnu::target("avx2")]] Texel line_or_reference(const TextureLevel& level, const ProbeLine& g, const Sampler& s,
                                                double u, double v, double du, double dv, int count) {
    return vectors_reach(g, level) ? line_mean(level, g, count, s) : anisotropic_line(level, s, u, v, du, dv, count);
}

// probe_line on two levels at once, for repeat and clamp (the samplers BatchSampler covers, as
// wrap() above): [x on a, x on b, y on a, y on b] in one vector, each element the same double
// arithmetic as probe_line's (its std::min and std::max as selects), the wrap's division four at
// a time instead of one per level and axis.
[[gnu::target("avx2")]] void probe_lines(const TextureLevel& a, const TextureLevel& b, const Sampler& s, double u,
                                         double v, double du, double dv, int count, ProbeLine& ga, ProbeLine& gb) {
    const __m256d size = _mm256_setr_pd(a.width, b.width, a.height, b.height);
    const __m256d x = _mm256_mul_pd(_mm256_setr_pd(u, u, v, v), size);
    const __m256d repeats = _mm256_castsi256_pd(_mm256_setr_epi64x(-(s.wrap_u == WrapMode::repeat),
                                                                   -(s.wrap_u == WrapMode::repeat),
                                                                   -(s.wrap_v == WrapMode::repeat),
                                                                   -(s.wrap_v == WrapMode::repeat)));
    // reduce(): a coordinate inside [0, n) stays; one outside moves by whole periods, x − n·⌊x/n⌋.
    const __m256d inside_range = _mm256_and_pd(_mm256_cmp_pd(x, _mm256_setzero_pd(), _CMP_GE_OQ),
                                               _mm256_cmp_pd(x, size, _CMP_LT_OQ));
    const __m256d periods = _mm256_round_pd(_mm256_div_pd(x, size), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    const __m256d reduced = _mm256_sub_pd(x, _mm256_mul_pd(size, periods));
    const __m256d centre = _mm256_blendv_pd(x, reduced, _mm256_andnot_pd(inside_range, repeats));
    const double step = 1.0 / count;
    const __m256d slope = _mm256_mul_pd(_mm256_setr_pd(du, du, dv, dv), size);
    const __m256d first = _mm256_add_pd(_mm256_sub_pd(centre, _mm256_set1_pd(0.5)),
                                        _mm256_mul_pd(_mm256_set1_pd(0.5 * step - 0.5), slope));
    const __m256d last = _mm256_add_pd(first, _mm256_mul_pd(_mm256_set1_pd((count - 1) * step), slope));
    const __m256d lo = _mm256_blendv_pd(first, last, _mm256_cmp_pd(last, first, _CMP_LT_OQ));   // std::min
    const __m256d hi = _mm256_blendv_pd(first, last, _mm256_cmp_pd(first, last, _CMP_LT_OQ));   // std::max
    const __m256d last_texel = _mm256_sub_pd(size, _mm256_set1_pd(1.0));
    const int inside = _mm256_movemask_pd(_mm256_and_pd(_mm256_cmp_pd(lo, _mm256_setzero_pd(), _CMP_GE_OQ),
                                                        _mm256_cmp_pd(hi, last_texel, _CMP_LT_OQ)));
    const __m256d reach = _mm256_set1_pd(kProbeReach);
    const int near = _mm256_movemask_pd(_mm256_and_pd(_mm256_cmp_pd(lo, _mm256_sub_pd(_mm256_setzero_pd(), reach),
                                                                    _CMP_GT_OQ),
                                                      _mm256_cmp_pd(hi, reach, _CMP_LT_OQ)));
    alignas(32) double x0[4], sx[4];
    _mm256_store_pd(x0, first);
    _mm256_store_pd(sx, slope);
    ga = {x0[0], x0[2], sx[0], sx[2], step, (inside & 0b0101) == 0b0101, (near & 0b0101) == 0b0101};
    gb = {x0[1], x0[3], sx[1], sx[3], step, (inside & 0b1010) == 0b1010, (near & 0b1010) == 0b1010};
}

}  // namespace

[[gnu::target("avx2")]] Texel anisotropic_line_avx2(const TextureLevel& level, const Sampler& s, double u, double v,
                                                     double du, double dv, int count) {
    return line_or_reference(level, probe_line(level, s, u, v, du, dv, count), s, u, v, du, dv, count);
}

[[gnu::target("avx2")]] void anisotropic_lines_avx2(const TextureLevel& a, const TextureLevel& b, const Sampler& s,
                                                    double u, double v, double du, double dv, int count, Texel& mean_a,
                                                    Texel& mean_b) {
    ProbeLine ga, gb;
    probe_lines(a, b, s, u, v, du, dv, count, ga, gb);
    if (vectors_reach(ga, a) && vectors_reach(gb, b)) return line_means(a, ga, b, gb, count, s, mean_a, mean_b);
    mean_a = line_or_reference(a, ga, s, u, v, du, dv, count);  // (the lines already placed, not again)
    mean_b = line_or_reference(b, gb, s, u, v, du, dv, count);
}

#else  // (other CPUs never call it: BatchSampler uses it only where AVX2 is)

Texel anisotropic_line_avx2(const TextureLevel& level, const Sampler& s, double u, double v, double du, double dv,
                            int count) {
    return anisotropic_line(level, s, u, v, du, dv, count);
}

void anisotropic_lines_avx2(const TextureLevel& a, const TextureLevel& b, const Sampler& s, double u, double v,
                            double du, double dv, int count, Texel& mean_a, Texel& mean_b) {
    mean_a = anisotropic_line(a, s, u, v, du, dv, count);
    mean_b = anisotropic_line(b, s, u, v, du, dv, count);
}

#endif

}  // namespace mipraster
