// anisotropic_line with AVX2 (anisotropic_line.hpp) for the lanes of a lookup batch that take lines
// of probes, for the samplers BatchSampler covers (repeat and clamp). The bits are the reference's:
// each line's placement and each probe's position are the same double arithmetic, with ⌊x⌋ one
// rounding instruction (exact) instead of a truncation and a compare; each quad is the same four
// texels blended the same way; each line's sum runs in probe order. Indices outside a level wrap
// four per vector instead of texel by texel.
//
// Four lanes go through at a time, each step for all four before the next: their lines placed
// (one lane per vector element), their probes placed (probe k of the four lines in one vector),
// then their sums. One lane at a time, each step waited for the one before it (a division,
// roundings, conversions, stores and loads), and a lane's work was too long for the CPU to
// overlap it with the next lane's; a short line also left most of its probe vector unused.
#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "anisotropic_line.hpp"

namespace mipraster {

using namespace texel;

#if defined(__x86_64__)

namespace {

constexpr int kChunk = 16;  // probes of each line placed at a time

// wrap_index for repeat or clamp of four indices within ±(kProbeReach + 1), on levels of `size`
// texels (per element). Repeat: powers of two mask (two's complement); other sizes subtract
// n·trunc(i/n), the quotient from a double division. That remainder is in (−n, n) unless the
// division rounded across an integer (only for n ≥ 2²³), which leaves it in (−2n, 2n); the last
// steps bring either into [0, n). Both give the same index where both apply.
[[gnu::target("avx2")]] inline __m128i wrap(__m128i i, __m128i size, bool powers_of_two, WrapMode mode) {
    const __m128i zero = _mm_setzero_si128(), last = _mm_sub_epi32(size, _mm_set1_epi32(1));
    if (mode == WrapMode::clamp) return _mm_min_epi32(_mm_max_epi32(i, zero), last);
    if (powers_of_two) return _mm_and_si128(i, last);
    const __m128i q = _mm256_cvttpd_epi32(_mm256_div_pd(_mm256_cvtepi32_pd(i), _mm256_cvtepi32_pd(size)));
    __m128i r = _mm_sub_epi32(i, _mm_mullo_epi32(q, size));  // within (−2n, 2n)
    for (int pass = 0; pass < 2; ++pass)  // r < 0: r + n
        r = _mm_add_epi32(r, _mm_and_si128(_mm_cmpgt_epi32(zero, r), size));
    return _mm_sub_epi32(r, _mm_andnot_si128(_mm_cmpgt_epi32(size, r), size));  // r ≥ n: r − n
}

// probe_line's arithmetic on one axis of four lines (coordinate c, derivative d, level size n,
// step 1/count and span (count − 1)·step per element): element by element the same double
// operations, its std::min and std::max as selects. Gives the first probe's position and the
// slope, and narrows `inside` and `near` by this axis (all-ones elements where they hold).
// powers_of_two: every n is one, so x = c·n is exact and x/n is c: ⌊x/n⌋ without the division
// (the divider was the busiest unit of the lines' placement).
[[gnu::target("avx2")]] inline void axis_lines(__m256d c, __m256d d, __m256d size, bool powers_of_two, __m256d step,
                                               __m256d span, WrapMode mode, __m256d& first, __m256d& slope,
                                               __m256d& inside, __m256d& near) {
    const __m256d x = _mm256_mul_pd(c, size);
    if (mode == WrapMode::repeat) {  // reduce(): inside [0, n) it stays, else x − n·⌊x/n⌋
        const __m256d inside_range = _mm256_and_pd(_mm256_cmp_pd(x, _mm256_setzero_pd(), _CMP_GE_OQ),
                                                   _mm256_cmp_pd(x, size, _CMP_LT_OQ));
        const __m256d quotient = powers_of_two ? c : _mm256_div_pd(x, size);
        const __m256d periods = _mm256_round_pd(quotient, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
        const __m256d reduced = _mm256_sub_pd(x, _mm256_mul_pd(size, periods));
        first = _mm256_blendv_pd(reduced, x, inside_range);
    } else {
        first = x;
    }
    slope = _mm256_mul_pd(d, size);
    const __m256d half = _mm256_set1_pd(0.5);
    const __m256d back = _mm256_sub_pd(_mm256_mul_pd(half, step), half);  // (½·step − ½): probe 0's offset
    first = _mm256_add_pd(_mm256_sub_pd(first, half), _mm256_mul_pd(back, slope));
    const __m256d last = _mm256_add_pd(first, _mm256_mul_pd(span, slope));
    const __m256d lo = _mm256_blendv_pd(first, last, _mm256_cmp_pd(last, first, _CMP_LT_OQ));  // std::min
    const __m256d hi = _mm256_blendv_pd(first, last, _mm256_cmp_pd(first, last, _CMP_LT_OQ));  // std::max
    const __m256d last_texel = _mm256_sub_pd(size, _mm256_set1_pd(1.0));
    inside = _mm256_and_pd(inside, _mm256_and_pd(_mm256_cmp_pd(lo, _mm256_setzero_pd(), _CMP_GE_OQ),
                                                 _mm256_cmp_pd(hi, last_texel, _CMP_LT_OQ)));
    const __m256d reach = _mm256_set1_pd(kProbeReach);
    near = _mm256_and_pd(near, _mm256_and_pd(_mm256_cmp_pd(lo, _mm256_sub_pd(_mm256_setzero_pd(), reach), _CMP_GT_OQ),
                                             _mm256_cmp_pd(hi, reach, _CMP_LT_OQ)));
}

// Four lines on one level each (element j: the line of lane j of a group): probe k of line j at
// (x0 + k·step·sx, y0 + k·step·sy) in texels of a width × height level, as probe_line places it.
struct FourLines {
    __m256d x0, y0, sx, sy;
    __m128i width, height;
    bool powers_of_two;  // every element's width and height
    int inside, near;    // bit j: line j's quads all lie inside its level / within ±kProbeReach
};

[[gnu::target("avx2")]] FourLines four_lines(__m256d u, __m256d v, __m256d du, __m256d dv, __m128i width,
                                             __m128i height, __m256d step, __m256d span, const Sampler& s) {
    FourLines f;
    f.width = width, f.height = height;
    const __m128i sizes_minus_one = _mm_or_si128(_mm_and_si128(width, _mm_sub_epi32(width, _mm_set1_epi32(1))),
                                                 _mm_and_si128(height, _mm_sub_epi32(height, _mm_set1_epi32(1))));
    f.powers_of_two = _mm_testz_si128(sizes_minus_one, sizes_minus_one);
    __m256d inside = _mm256_castsi256_pd(_mm256_set1_epi64x(-1)), near = inside;
    axis_lines(u, du, _mm256_cvtepi32_pd(width), f.powers_of_two, step, span, s.wrap_u, f.x0, f.sx, inside, near);
    axis_lines(v, dv, _mm256_cvtepi32_pd(height), f.powers_of_two, step, span, s.wrap_v, f.y0, f.sy, inside, near);
    f.inside = _mm256_movemask_pd(inside), f.near = _mm256_movemask_pd(near);
    return f;
}

// Probes k0 … k0 + n − 1 of four lines: the quads' texels (indices into each line's level; only
// corner 0 where the lines lie inside their levels) and fractions, [corner][probe][line]. Lines
// shorter than k0 + n get probes past their end (unread).
struct FourProbes {
    std::int32_t texel[4][kChunk][4];
    float fx[kChunk][4], fy[kChunk][4];
};

// `inside`: the lines whose probes are read all lie inside their levels; then only a quad's first
// texel is placed, ⌊y⌋·width + ⌊x⌋ in double (exact: below the level's texel count, which fits an
// int); else all four, their indices wrapped.
[[gnu::target("avx2")]] void place_probes(const FourLines& f, bool inside, __m256d step, int k0, int n,
                                          const Sampler& s, FourProbes& p) {
    const __m256d width = _mm256_cvtepi32_pd(f.width);
    const __m128i one = _mm_set1_epi32(1);
    for (int c = 0; c < n; ++c) {
        const __m256d t = _mm256_mul_pd(_mm256_set1_pd(k0 + c), step);
        const __m256d x = _mm256_add_pd(f.x0, _mm256_mul_pd(t, f.sx));
        const __m256d y = _mm256_add_pd(f.y0, _mm256_mul_pd(t, f.sy));
        const __m256d fx = _mm256_floor_pd(x), fy = _mm256_floor_pd(y);
        _mm_storeu_ps(p.fx[c], _mm256_cvtpd_ps(_mm256_sub_pd(x, fx)));
        _mm_storeu_ps(p.fy[c], _mm256_cvtpd_ps(_mm256_sub_pd(y, fy)));
        // Past a line's end, or on a line the reference takes, a value may exceed the int range:
        // the conversion gives INT_MIN there (and the sums below wrap around, defined; unread).
        if (inside) {  // (the other corners follow from the first: see quad)
            _mm_storeu_si128(reinterpret_cast<__m128i*>(p.texel[0][c]),
                             _mm256_cvttpd_epi32(_mm256_add_pd(_mm256_mul_pd(fy, width), fx)));
            continue;
        }
        const __m128i i0 = _mm256_cvttpd_epi32(fx), j0 = _mm256_cvttpd_epi32(fy);
        const __m128i i1 = wrap(_mm_add_epi32(i0, one), f.width, f.powers_of_two, s.wrap_u);
        const __m128i j1 = wrap(_mm_add_epi32(j0, one), f.height, f.powers_of_two, s.wrap_v);
        const __m128i i = wrap(i0, f.width, f.powers_of_two, s.wrap_u);
        const __m128i row0 = _mm_mullo_epi32(wrap(j0, f.height, f.powers_of_two, s.wrap_v), f.width);
        const __m128i row1 = _mm_mullo_epi32(j1, f.width);
        const __m128i texel[4] = {_mm_add_epi32(row0, i), _mm_add_epi32(row0, i1), _mm_add_epi32(row1, i),
                                  _mm_add_epi32(row1, i1)};
        for (int corner = 0; corner < 4; ++corner)
            _mm_storeu_si128(reinterpret_cast<__m128i*>(p.texel[corner][c]), texel[corner]);
    }
}

// Probe c's bilinear quad on line j. kInside: the group's lines lie inside their levels, and only
// each quad's first texel was placed; the others are the next one and the two below them (`width`
// texels on).
template <bool kInside>
[[gnu::target("avx2")]] inline Texel quad(const glm::vec4* t, const FourProbes& p, int c, int j, std::ptrdiff_t width) {
    if constexpr (kInside) {
        const glm::vec4* a = t + p.texel[0][c][j];
        return lerp_quad(load(a[0]), load(a[1]), load(a[width]), load(a[width + 1]), p.fx[c][j], p.fy[c][j]);
    }
    return lerp_quad(load(t[p.texel[0][c][j]]), load(t[p.texel[1][c][j]]), load(t[p.texel[2][c][j]]),
                     load(t[p.texel[3][c][j]]), p.fx[c][j], p.fy[c][j]);
}

// A line's running sum, as the reference adds its probes: the first quad, and the differences of
// the others from it (so that a constant texture gives back its value exactly).
struct LineSum {
    Texel first = splat(0.0f), difference = splat(0.0f);
};

// Adds probes k0 … end − 1 (placed from k0) of line j, on a level `width` texels wide, to `sum`.
template <bool kInside>
[[gnu::target("avx2")]] inline void add_probes(const glm::vec4* t, const FourProbes& p, std::ptrdiff_t width, int j,
                                               int k0, int end, LineSum& sum) {
    int k = k0;
    if (k == 0) {
        sum.first = quad<kInside>(t, p, 0, j, width);
        ++k;
    }
    for (; k < end; ++k) sum.difference += quad<kInside>(t, p, k - k0, j, width) - sum.first;
}

// A texel of each of two levels in one register (the finer level's in the low half), and the
// blends of texel.hpp on both halves at once: per half the same operations as lerp.
[[gnu::target("avx2")]] inline __m256 pair(const glm::vec4& finer, const glm::vec4& coarser) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&finer.x)), _mm_loadu_ps(&coarser.x), 1);
}
[[gnu::target("avx2")]] inline __m256 lerp_pair(__m256 a, __m256 b, __m256 t) {
    return _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
}
[[gnu::target("avx2")]] inline __m256 halves(float finer, float coarser) {
    return _mm256_set_m128(_mm_set1_ps(coarser), _mm_set1_ps(finer));
}

// Probe c's quads on line j of two levels (finer level ta, coarser tb) at once, as quad<kInside>
// on each.
template <bool kInside>
[[gnu::target("avx2")]] inline __m256 quads(const glm::vec4* ta, const FourProbes& pa, std::ptrdiff_t wa,
                                            const glm::vec4* tb, const FourProbes& pb, std::ptrdiff_t wb, int c,
                                            int j) {
    __m256 corner[4];
    if constexpr (kInside) {
        const glm::vec4 *a = ta + pa.texel[0][c][j], *b = tb + pb.texel[0][c][j];
        corner[0] = pair(a[0], b[0]), corner[1] = pair(a[1], b[1]);
        corner[2] = pair(a[wa], b[wb]), corner[3] = pair(a[wa + 1], b[wb + 1]);
    } else {
        for (int k = 0; k < 4; ++k) corner[k] = pair(ta[pa.texel[k][c][j]], tb[pb.texel[k][c][j]]);
    }
    const __m256 fx = halves(pa.fx[c][j], pb.fx[c][j]);
    return lerp_pair(lerp_pair(corner[0], corner[1], fx), lerp_pair(corner[2], corner[3], fx),
                     halves(pa.fy[c][j], pb.fy[c][j]));
}

// add_probes on two levels at once: each level's sum in its own half of a register, in its probe
// order (the same bits as one level at a time, half the instructions).
template <bool kInside>
[[gnu::target("avx2")]] inline void add_probes(const glm::vec4* ta, const FourProbes& pa, std::ptrdiff_t wa,
                                               const glm::vec4* tb, const FourProbes& pb, std::ptrdiff_t wb, int j,
                                               int k0, int end, LineSum& a, LineSum& b) {
    __m256 first = _mm256_set_m128(__m128(b.first), __m128(a.first));
    __m256 difference = _mm256_set_m128(__m128(b.difference), __m128(a.difference));
    int k = k0;
    if (k == 0) {
        first = quads<kInside>(ta, pa, wa, tb, pb, wb, 0, j);
        ++k;
    }
    for (; k < end; ++k)
        difference = _mm256_add_ps(difference, _mm256_sub_ps(quads<kInside>(ta, pa, wa, tb, pb, wb, k - k0, j), first));
    a.first = Texel(_mm256_castps256_ps128(first)), a.difference = Texel(_mm256_castps256_ps128(difference));
    b.first = Texel(_mm256_extractf128_ps(first, 1)), b.difference = Texel(_mm256_extractf128_ps(difference, 1));
}

// Whether the vectors take a line on `level` (else the reference does: too far out for int
// indices, or a level whose texel indices overflow an int).
bool vectors_reach(bool near, const TextureLevel& level) {
    return near && level.texels.size() <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
}

// Lanes first … first + n − 1 (n ≤ 4) of `lanes`.
[[gnu::target("avx2")]] void four_lanes(const LineLanes& lanes, int first, int n, const Sampler& s, Texel* mean_finer,
                                        Texel* mean_coarser) {
    // The inputs straight from the caller's arrays (lanes past n as zeros; their counts as 1): a
    // vector loaded from scalars just stored waits for them to reach the cache.
    const __m256i used = _mm256_cmpgt_epi64(_mm256_set1_epi64x(n), _mm256_setr_epi64x(0, 1, 2, 3));
    const __m128i used_ints = _mm_cmpgt_epi32(_mm_set1_epi32(n), _mm_setr_epi32(0, 1, 2, 3));
    const __m128i count =
        _mm_blendv_epi8(_mm_set1_epi32(1), _mm_maskload_epi32(lanes.count + first, used_ints), used_ints);
    const __m256d counts = _mm256_cvtepi32_pd(count);
    const __m256d step = _mm256_div_pd(_mm256_set1_pd(1.0), counts);
    const __m256d span = _mm256_mul_pd(_mm256_sub_pd(counts, _mm256_set1_pd(1.0)), step);
    bool two_levels = false;
    for (int j = 0; j < n; ++j) two_levels |= lanes.coarser[first + j] != nullptr;
    FourLines lines[2];
    for (int k = 0; k < (two_levels ? 2 : 1); ++k) {
        const auto level = [&](int j) -> const TextureLevel* {
            if (j >= n) return nullptr;
            return k == 1 && lanes.coarser[first + j] ? lanes.coarser[first + j] : lanes.finer[first + j];
        };
        const TextureLevel* four[4] = {level(0), level(1), level(2), level(3)};
        const auto size = [&](int TextureLevel::*dimension) {
            const auto of = [&](int j) { return four[j] ? four[j]->*dimension : 1; };
            return _mm_setr_epi32(of(0), of(1), of(2), of(3));
        };
        lines[k] = four_lines(_mm256_maskload_pd(lanes.u + first, used), _mm256_maskload_pd(lanes.v + first, used),
                              _mm256_maskload_pd(lanes.du + first, used), _mm256_maskload_pd(lanes.dv + first, used),
                              size(&TextureLevel::width), size(&TextureLevel::height), step, span, s);
    }

    // The lanes the vectors take, and the longest of their lines.
    int vector_lanes = 0, longest = 0;
    for (int j = 0; j < n; ++j) {
        const int i = first + j;
        if (!vectors_reach(lines[0].near >> j & 1, *lanes.finer[i])) continue;
        if (lanes.coarser[i] && !vectors_reach(lines[1].near >> j & 1, *lanes.coarser[i])) continue;
        vector_lanes |= 1 << j;
        longest = std::max(longest, lanes.count[i]);
    }
    // Whether every line the vectors take lies inside its level(s): then only each quad's first
    // texel is placed.
    const bool inside = (lines[0].inside & vector_lanes) == vector_lanes &&
                        (!two_levels || (lines[1].inside & vector_lanes) == vector_lanes);
    LineSum sums[2][4];
    FourProbes probes[2];
    for (int k0 = 0; k0 < longest; k0 += kChunk) {
        const int chunk = std::min(kChunk, longest - k0);
        for (int k = 0; k < (two_levels ? 2 : 1); ++k)
            place_probes(lines[k], inside, step, k0, chunk, s, probes[k]);
        for (int j = 0; j < n; ++j) {
            const int i = first + j, end = std::min(k0 + chunk, lanes.count[i]);
            if (!(vector_lanes >> j & 1) || end <= k0) continue;
            const TextureLevel &finer = *lanes.finer[i], *coarser = lanes.coarser[i];
            if (coarser && inside)
                add_probes<true>(finer.texels.data(), probes[0], finer.width, coarser->texels.data(), probes[1],
                                 coarser->width, j, k0, end, sums[0][j], sums[1][j]);
            else if (coarser)
                add_probes<false>(finer.texels.data(), probes[0], finer.width, coarser->texels.data(), probes[1],
                                  coarser->width, j, k0, end, sums[0][j], sums[1][j]);
            else if (inside)
                add_probes<true>(finer.texels.data(), probes[0], finer.width, j, k0, end, sums[0][j]);
            else
                add_probes<false>(finer.texels.data(), probes[0], finer.width, j, k0, end, sums[0][j]);
        }
    }
    alignas(32) double steps[4];
    _mm256_store_pd(steps, step);
    for (int j = 0; j < n; ++j) {
        const int i = first + j;
        const auto mean = [&](const LineSum& sum) {
            return sum.first + sum.difference * splat(static_cast<float>(steps[j]));
        };
        const auto reference = [&](const TextureLevel& level) {
            return anisotropic_line(level, s, lanes.u[i], lanes.v[i], lanes.du[i], lanes.dv[i], lanes.count[i]);
        };
        const bool vectors = vector_lanes >> j & 1;
        mean_finer[i] = vectors ? mean(sums[0][j]) : reference(*lanes.finer[i]);
        if (lanes.coarser[i]) mean_coarser[i] = vectors ? mean(sums[1][j]) : reference(*lanes.coarser[i]);
    }
}

}  // namespace

[[gnu::target("avx2")]] void anisotropic_line_means_avx2(const LineLanes& lanes, const Sampler& s, Texel* mean_finer,
                                                         Texel* mean_coarser) {
    for (int first = 0; first < lanes.n; first += 4)
        four_lanes(lanes, first, std::min(4, lanes.n - first), s, mean_finer, mean_coarser);
}

#else  // (other CPUs never call it: BatchSampler uses it only where AVX2 is)

void anisotropic_line_means_avx2(const LineLanes& lanes, const Sampler& s, Texel* mean_finer, Texel* mean_coarser) {
    anisotropic_line_means(lanes, s, mean_finer, mean_coarser);
}

#endif

}  // namespace mipraster
