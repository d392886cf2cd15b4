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
// Lines of more than kMostVectorProbes probes (a max_anisotropy above 16) take the reference: a
// whole line's probes are placed at once, and each lane's sum stays in registers.
#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "anisotropic_line.hpp"
#include "mipraster/texture/texture.hpp"

namespace mipraster {

using namespace texel;

#if defined(__x86_64__)

namespace {

constexpr int kMostVectorProbes = 16;  // the longest line the vectors take

// A level's texels' positions in floats fit an int32 (the vectors' are).
static_assert(kMaxTextureBytes / sizeof(float) <= std::uint64_t{1} << 31, "a level's floats outgrow an int32 index");

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

// Probe c of four lines on each of two levels: its quads' texels (where they start, in floats from
// each line's level's first: four per texel, so that a load needs no shift; only corner 0 where the
// lines lie inside their levels), [level][corner][line], and fractions, [level][line]: a line's
// two levels' fractions lie in one 32-byte row, so that one permute spreads them over the halves
// of a register (see quads).
struct ProbeSlot {
    std::int32_t texel_float[2][4][4];
    float fx[2][4], fy[2][4];
};
// Probes 0 … n − 1 of four lines (lines shorter than n get probes past their end, unread).
struct FourProbes {
    ProbeSlot at[kMostVectorProbes];
};

// Probe numbers as doubles, for t = c·step without a conversion.
constexpr double kProbeNumbers[kMostVectorProbes] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};

// kInside: the lines whose probes are read all lie inside their levels; then only a quad's first
// texel is placed, ⌊y⌋·width + ⌊x⌋ in double (exact: below the level's texel count, which fits an
// int); else all four, their indices wrapped.
template <bool kInside>
[[gnu::target("avx2")]] void place_probes(const FourLines& f, __m256d step, int n, const Sampler& s, int level,
                                          FourProbes& p) {
    const __m256d width = _mm256_cvtepi32_pd(f.width);
    const __m128i one = _mm_set1_epi32(1);
    for (int c = 0; c < n; ++c) {
        ProbeSlot& at = p.at[c];
        const __m256d t = _mm256_mul_pd(_mm256_broadcast_sd(&kProbeNumbers[c]), step);
        const __m256d x = _mm256_add_pd(f.x0, _mm256_mul_pd(t, f.sx));
        const __m256d y = _mm256_add_pd(f.y0, _mm256_mul_pd(t, f.sy));
        const __m256d fx = _mm256_floor_pd(x), fy = _mm256_floor_pd(y);
        _mm_storeu_ps(at.fx[level], _mm256_cvtpd_ps(_mm256_sub_pd(x, fx)));
        _mm_storeu_ps(at.fy[level], _mm256_cvtpd_ps(_mm256_sub_pd(y, fy)));
        // Past a line's end, or on a line the reference takes, a value may exceed the int range:
        // the conversion gives INT_MIN there (and the shifts and sums below wrap around, defined;
        // unread).
        if constexpr (kInside) {  // (the other corners follow from the first: see quad)
            const __m128i texel = _mm256_cvttpd_epi32(_mm256_add_pd(_mm256_mul_pd(fy, width), fx));
            _mm_storeu_si128(reinterpret_cast<__m128i*>(at.texel_float[level][0]), _mm_slli_epi32(texel, 2));
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
            _mm_storeu_si128(reinterpret_cast<__m128i*>(at.texel_float[level][corner]),
                             _mm_slli_epi32(texel[corner], 2));
    }
}

// The bilinear quad of probe `at` on line j of the finer level, whose texels' floats start at t and
// whose rows are `row` floats long. kInside: the group's lines lie inside their levels, and only
// each quad's first texel was placed; the others are the next one and the two below them.
template <bool kInside>
[[gnu::target("avx2")]] inline Texel quad(const float* t, const ProbeSlot& at, int j, std::ptrdiff_t row) {
    const auto& texel = at.texel_float[0];
    if constexpr (kInside) {
        const float* a = t + texel[0][j];
        return lerp_quad(load(a), load(a + 4), load(a + row), load(a + row + 4), at.fx[0][j], at.fy[0][j]);
    }
    return lerp_quad(load(t + texel[0][j]), load(t + texel[1][j]), load(t + texel[2][j]), load(t + texel[3][j]),
                     at.fx[0][j], at.fy[0][j]);
}

// The mean of line j's probes 0 … count − 1 on the finer level (floats t, rows `row` floats long),
// as the reference adds them: the first quad plus the mean difference of the others from it (so
// that a constant texture gives back its value exactly).
template <bool kInside>
[[gnu::target("avx2")]] inline Texel line_mean(const float* t, const FourProbes& p, std::ptrdiff_t row, int j,
                                               int count, float step) {
    const Texel first = quad<kInside>(t, p.at[0], j, row);
    Texel difference = splat(0.0f);
    for (int k = 1; k < count; ++k) difference += quad<kInside>(t, p.at[k], j, row) - first;
    return first + difference * splat(step);
}

// A texel of each of two levels in one register (the finer level's in the low half), and the
// blends of texel.hpp on both halves at once: per half the same operations as lerp.
[[gnu::target("avx2")]] inline __m256 pair(const float* finer, const float* coarser) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(finer)), _mm_loadu_ps(coarser), 1);
}
[[gnu::target("avx2")]] inline __m256 lerp_pair(__m256 a, __m256 b, __m256 t) {
    return _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
}
// Line j's fraction of both levels, fraction[0][j] and fraction[1][j], each over its half of a
// register: `spread` is (j, j, j, j, j + 4, j + 4, j + 4, j + 4).
[[gnu::target("avx2")]] inline __m256 halves(const float (&fraction)[2][4], __m256i spread) {
    return _mm256_permutevar8x32_ps(_mm256_loadu_ps(fraction[0]), spread);
}

// The quads of probe `at` on line j of two levels (finer level ta, coarser tb) at once, as
// quad<kInside> on each.
template <bool kInside>
[[gnu::target("avx2")]] inline __m256 quads(const float* ta, std::ptrdiff_t ra, const float* tb, std::ptrdiff_t rb,
                                            const ProbeSlot& at, int j, __m256i spread) {
    const auto &finer = at.texel_float[0], &coarser = at.texel_float[1];
    __m256 corner[4];
    if constexpr (kInside) {
        const float *a = ta + finer[0][j], *b = tb + coarser[0][j];
        corner[0] = pair(a, b), corner[1] = pair(a + 4, b + 4);
        corner[2] = pair(a + ra, b + rb), corner[3] = pair(a + ra + 4, b + rb + 4);
    } else {
        for (int k = 0; k < 4; ++k) corner[k] = pair(ta + finer[k][j], tb + coarser[k][j]);
    }
    const __m256 fx = halves(at.fx, spread);
    return lerp_pair(lerp_pair(corner[0], corner[1], fx), lerp_pair(corner[2], corner[3], fx), halves(at.fy, spread));
}

// line_mean on two levels at once, each level's sum in its own half of a register (the same bits
// as one level at a time, half the instructions): the finer level's mean in the low half.
template <bool kInside>
[[gnu::target("avx2")]] inline __m256 line_means(const float* ta, std::ptrdiff_t ra, const float* tb, std::ptrdiff_t rb,
                                                 const FourProbes& p, int j, int count, float step) {
    const __m256i spread = _mm256_add_epi32(_mm256_set1_epi32(j), _mm256_setr_epi32(0, 0, 0, 0, 4, 4, 4, 4));
    const __m256 first = quads<kInside>(ta, ra, tb, rb, p.at[0], j, spread);
    __m256 difference = _mm256_setzero_ps();
    for (int k = 1; k < count; ++k) {
        const __m256 probe = quads<kInside>(ta, ra, tb, rb, p.at[k], j, spread);
        difference = _mm256_add_ps(difference, _mm256_sub_ps(probe, first));
    }
    return _mm256_add_ps(first, _mm256_mul_ps(difference, _mm256_set1_ps(step)));
}

// Lanes first … first + n − 1 (n ≤ 4) of `lanes`.
[[gnu::target("avx2")]] void four_lanes(const LineLanes& lanes, int first, int n, const Sampler& s, glm::vec4* out) {
    // The inputs straight from the caller's arrays (lanes past n as zeros; their counts as 1): a
    // vector loaded from scalars just stored waits for them to reach the cache.
    const __m256i used = _mm256_cmpgt_epi64(_mm256_set1_epi64x(n), _mm256_setr_epi64x(0, 1, 2, 3));
    const __m128i used_ints = _mm_cmpgt_epi32(_mm_set1_epi32(n), _mm_setr_epi32(0, 1, 2, 3));
    const __m128i count =
        _mm_blendv_epi8(_mm_set1_epi32(1), _mm_maskload_epi32(lanes.count + first, used_ints), used_ints);
    const __m256d counts = _mm256_cvtepi32_pd(count);
    const __m256d step = _mm256_div_pd(_mm256_set1_pd(1.0), counts);
    const __m256d span = _mm256_mul_pd(_mm256_sub_pd(counts, _mm256_set1_pd(1.0)), step);
    // Each lane's level(s): lanes past n take lane 0's, and a lane of one level its finer level
    // for the coarser too (placed and summed, never read), so that no lane needs a test below.
    const TextureLevel* level[2][4];
    bool two_levels = false;
    for (int j = 0; j < 4; ++j) {
        const int i = first + (j < n ? j : 0);
        level[0][j] = lanes.finer[i];
        level[1][j] = lanes.coarser[i] ? lanes.coarser[i] : lanes.finer[i];
        two_levels |= lanes.coarser[i] != nullptr;
    }
    const __m256d u = _mm256_maskload_pd(lanes.u + first, used), v = _mm256_maskload_pd(lanes.v + first, used);
    const __m256d du = _mm256_maskload_pd(lanes.du + first, used), dv = _mm256_maskload_pd(lanes.dv + first, used);
    FourLines lines[2];
    for (int k = 0; k < (two_levels ? 2 : 1); ++k) {
        const TextureLevel* const* four = level[k];
        const __m128i width = _mm_setr_epi32(four[0]->width, four[1]->width, four[2]->width, four[3]->width);
        const __m128i height = _mm_setr_epi32(four[0]->height, four[1]->height, four[2]->height, four[3]->height);
        lines[k] = four_lines(u, v, du, dv, width, height, step, span, s);
    }

    // The lanes the vectors take (lines short enough, within reach of int indices), the longest of
    // their lines, and whether all of those lie inside their levels: then only each quad's first
    // texel is placed.
    const int short_lines =
        _mm_movemask_ps(_mm_castsi128_ps(_mm_cmplt_epi32(count, _mm_set1_epi32(kMostVectorProbes + 1))));
    const int vector_lanes = ((1 << n) - 1) & short_lines & lines[0].near & (two_levels ? lines[1].near : 15);
    const int inside_lanes = lines[0].inside & (two_levels ? lines[1].inside : 15);
    const bool inside = (inside_lanes & vector_lanes) == vector_lanes;
    int longest = 0;
    for (int j = 0; j < n; ++j)
        if (vector_lanes >> j & 1) longest = std::max(longest, lanes.count[first + j]);
    FourProbes probes;
    for (int k = 0; k < (two_levels ? 2 : 1); ++k)
        (inside ? place_probes<true> : place_probes<false>)(lines[k], step, longest, s, k, probes);

    alignas(32) double steps[4];
    _mm256_store_pd(steps, step);
    for (int j = 0; j < n; ++j) {
        const int i = first + j, probes_j = lanes.count[i];
        if (!(vector_lanes >> j & 1)) {
            out[lanes.out[i]] = anisotropic_lines_lookup(lanes, i, s);
            continue;
        }
        const float step_j = static_cast<float>(steps[j]);
        const float* finer = &level[0][j]->texels.data()->x;
        const std::ptrdiff_t finer_row = std::ptrdiff_t{4} * level[0][j]->width;
        if (two_levels) {
            const float* coarser = &level[1][j]->texels.data()->x;
            const std::ptrdiff_t coarser_row = std::ptrdiff_t{4} * level[1][j]->width;
            const __m256 means =
                inside ? line_means<true>(finer, finer_row, coarser, coarser_row, probes, j, probes_j, step_j)
                       : line_means<false>(finer, finer_row, coarser, coarser_row, probes, j, probes_j, step_j);
            const Texel finer_mean = Texel(_mm256_castps256_ps128(means));
            out[lanes.out[i]] = to_vec4(lanes.coarser[i] ? lerp(finer_mean, Texel(_mm256_extractf128_ps(means, 1)),
                                                                lanes.weight[i])
                                                         : finer_mean);
        } else {
            out[lanes.out[i]] = to_vec4(inside ? line_mean<true>(finer, probes, finer_row, j, probes_j, step_j)
                                               : line_mean<false>(finer, probes, finer_row, j, probes_j, step_j));
        }
    }
}

}  // namespace

[[gnu::target("avx2")]] void anisotropic_lines_avx2(const LineLanes& lanes, const Sampler& s, glm::vec4* out) {
    for (int first = 0; first < lanes.n; first += 4) four_lanes(lanes, first, std::min(4, lanes.n - first), s, out);
}

#else  // (other CPUs never call it: BatchSampler uses it only where AVX2 is)

void anisotropic_lines_avx2(const LineLanes& lanes, const Sampler& s, glm::vec4* out) {
    anisotropic_lines(lanes, s, out);
}

#endif

}  // namespace mipraster
