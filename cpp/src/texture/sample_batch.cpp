#include "mipraster/texture/sample_batch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "mipraster/texture/sample.hpp"
#include "anisotropic_line.hpp"
#include "texel.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace mipraster {

namespace {

using namespace texel;

// Lanes in GCC/Clang vector types: four in one SSE2 register on the x86-64 baseline, eight in an
// AVX2 register where the CPU has it. Element by element the same IEEE arithmetic either way
// (no fused multiply-add: -ffp-contract=off, and AVX2 does not enable FMA), so the result does
// not depend on the CPU (DESIGN.md §2.8). The helpers are always inlined into the one function
// of each width, so the ABI note about 32-byte vectors on the baseline does not concern them.
#pragma GCC diagnostic ignored "-Wpsabi"
template <int W>
struct Lanes {
    typedef float Floats __attribute__((vector_size(4 * W)));
    typedef std::int32_t Ints __attribute__((vector_size(4 * W)));
};
#define MIPRASTER_LANES(W)                       \
    using Floats = typename Lanes<W>::Floats;    \
    using Ints = typename Lanes<W>::Ints

template <typename V>
[[gnu::always_inline]] inline V splat(float x) {
    return V{} + x;
}
template <typename V>
[[gnu::always_inline]] inline V min_v(V a, V b) {
    return a < b ? a : b;
}
template <typename V>
[[gnu::always_inline]] inline V max_v(V a, V b) {
    return a > b ? a : b;
}
template <typename V>
[[gnu::always_inline]] inline V clamp_v(V x, V lo, V hi) {
    return min_v(max_v(x, lo), hi);
}
template <typename To, typename From>
[[gnu::always_inline]] inline To convert(From x) {  // float → int truncates
    return __builtin_convertvector(x, To);
}
// ⌊x⌋ of |x| < 2³¹ (callers bound x first), as a float: eight lanes by AVX's rounding
// instruction (exact), four by truncating, then stepping down where that rounded up. The same
// value either way. Assembly, because in a baseline build these always-inline helpers are not
// compiled for AVX (only the function they end up in is), and the intrinsic would be refused.
template <typename Ints, typename Floats>
[[gnu::always_inline]] inline Floats floor_v(Floats x) {
#if defined(__x86_64__)
    if constexpr (sizeof(Floats) == 32) {
        Floats whole;
        asm("vroundps $9, %1, %0" : "=x"(whole) : "x"(x));  // 9: towards −∞, no inexact exception
        return whole;
    }
#endif
    const Ints i = convert<Ints>(x);
    return convert<Floats>(i + (convert<Floats>(i) > x));  // a true compare is −1
}
template <typename To, typename From>
[[gnu::always_inline]] inline To bits_as(From x) {
    static_assert(sizeof(To) == sizeof(From));
    To r;
    std::memcpy(&r, &x, sizeof r);
    return r;
}
template <typename Ints>
[[gnu::always_inline]] inline bool any(Ints mask) {
#if defined(__x86_64__)
    if constexpr (sizeof(Ints) == 32) {  // one test instruction (assembly, as in floor_v)
        bool some;
        asm("vptest %1, %1" : "=@ccnz"(some) : "x"(mask));
        return some;
    }
#endif
    std::int64_t words[sizeof(Ints) / 8];
    std::memcpy(words, &mask, sizeof words);
    std::int64_t all = 0;
    for (std::int64_t w : words) all |= w;
    return all != 0;
}
template <typename V>
[[gnu::always_inline]] inline V load_v(const float* p) {
    V r;
    std::memcpy(&r, p, sizeof r);
    return r;
}
template <typename T, typename V>
[[gnu::always_inline]] inline void store_v(T* p, V x) {
    std::memcpy(p, &x, sizeof x);
}

static_assert(kMaxTextureBytes / sizeof(float) <= std::uint64_t{1} << 31, "a level's floats outgrow an int32 index");

// Per lane, what the blend needs: which level(s), the weight of the finer one's neighbour,
// where the texels of the bilinear quads lie and their fractions.
struct LanePlan {
    std::int32_t level[kLookupBatch];
    float level_weight[kLookupBatch];  // > 0: blend towards level + 1
    // Per level: where the quad's texels a b / c d start, in floats from the level's first (four
    // per texel, so the loads need no shift; a level of at most kMaxTextureBytes keeps it an int32).
    std::int32_t texel_float[2][4][kLookupBatch];
    float fx[2][kLookupBatch], fy[2][kLookupBatch];
    std::int32_t finite[kLookupBatch];  // 0: the lane is sample_texture's (−1: all inputs finite)
};

// log2 x of a positive normal x: the exponent plus log2 of the mantissa m ∈ [√½, √2) from the
// series 2·atanh(s)/ln 2, s = (m − 1)/(m + 1), |s| ≤ 0.172, to s⁹ (the next term is < 4·10⁻¹⁰).
// Exact at powers of two, so a 2^k footprint gives λ = k as the double path does.
template <int W>
[[gnu::always_inline]] inline typename Lanes<W>::Floats log2_v(typename Lanes<W>::Floats x) {
    MIPRASTER_LANES(W);
    const Ints bits = bits_as<Ints>(x);
    Ints e = ((bits >> 23) & 0xff) - 127;
    const Ints mantissa_bits = (bits & 0x7fffff) | 0x3f800000;
    Floats m = bits_as<Floats>(mantissa_bits);
    const Ints high = m > splat<Floats>(1.41421356f);
    m = high ? m * 0.5f : m;
    e -= high;  // (−1 where true)
    const Floats s = (m - 1.0f) / (m + 1.0f), s2 = s * s;
    constexpr float k = 2.0f / 0.693147180559945309f;  // 2 / ln 2
    const Floats series = s * (k + s2 * (k / 3 + s2 * (k / 5 + s2 * (k / 7 + s2 * (k / 9)))));
    return convert<Floats>(e) + series;
}

// A coordinate as every level reads it: repeat keeps its fraction (exact; from 2²³ on a float
// holds none, and is kept away from the int conversion), clamp keeps it whole.
template <int W>
[[gnu::always_inline]] inline typename Lanes<W>::Floats reduce(typename Lanes<W>::Floats coordinate, WrapMode mode) {
    MIPRASTER_LANES(W);
    if (mode != WrapMode::repeat) return coordinate;
    const Ints whole_number = (coordinate >= splat<Floats>(0x1p23f)) | (coordinate <= splat<Floats>(-0x1p23f));
    const Floats bounded = whole_number ? splat<Floats>(0.0f) : coordinate;
    return bounded - floor_v<Ints>(bounded);
}

// Texel indices and fractions along one axis at level sizes n (float and int, per lane), for a
// bilinear quad at x = coordinate·n − ½ (the product is exact for a power-of-two size). A
// repeated coordinate in [0, 1] puts ⌊x⌋ in [−1, n − 1]: on power-of-two sizes (kPowerOfTwo)
// the wrap is a mask.
template <int W, bool kPowerOfTwo>
[[gnu::always_inline]] inline void axis(typename Lanes<W>::Floats reduced, typename Lanes<W>::Floats n,
                                        typename Lanes<W>::Ints n_int, WrapMode mode, typename Lanes<W>::Ints& lo,
                                        typename Lanes<W>::Ints& hi, typename Lanes<W>::Floats& fraction) {
    MIPRASTER_LANES(W);
    const Floats x = mode == WrapMode::repeat ? reduced * n - 0.5f : clamp_v(reduced * n, splat<Floats>(-2.0f), n + 2.0f) - 0.5f;
    const Floats whole = floor_v<Ints>(x);
    const Ints i = convert<Ints>(whole);
    fraction = x - whole;
    if (mode == WrapMode::repeat && kPowerOfTwo) {
        lo = i & (n_int - 1);
        hi = (i + 1) & (n_int - 1);
    } else if (mode == WrapMode::repeat) {
        lo = i < 0 ? i + n_int : i;
        hi = i + 1 >= n_int ? i + 1 - n_int : i + 1;
    } else {
        const Ints last = n_int - 1, zero = Ints{};
        lo = min_v(max_v(i, zero), last);
        hi = min_v(max_v(i + 1, zero), last);
    }
}

// What the quads of lanes first … first + W − 1 start from: their wrapped positions and finer level.
template <int W>
struct LaneLevels {
    typename Lanes<W>::Floats u, v;
    typename Lanes<W>::Ints fine;
    bool blends;  // some lane blends two levels
};

// Lanes first … first + W − 1 of the plan, part one: whether they are finite and their level(s).
template <int W>
[[gnu::always_inline]] inline LaneLevels<W> plan_levels(const LookupBatch& b, const float* rho2_scale, int first,
                                                        const Sampler& s, int width_texels, int height_texels,
                                                        int levels, LanePlan& plan) {
    MIPRASTER_LANES(W);
    Floats u = load_v<Floats>(first + b.u), v = load_v<Floats>(first + b.v);
    const Floats width = splat<Floats>(static_cast<float>(width_texels)), height = splat<Floats>(static_cast<float>(height_texels));
    const Floats ux = load_v<Floats>(first + b.dudx) * width, vx = load_v<Floats>(first + b.dvdx) * height;
    const Floats uy = load_v<Floats>(first + b.dudy) * width, vy = load_v<Floats>(first + b.dvdy) * height;
    const Floats px2 = ux * ux + vx * vx, py2 = uy * uy + vy * vy;
    // Lanes for the reference: a non-finite uv, derivative or squared length (NaN fails every
    // compare; an overflow to ∞ fails < max).
    constexpr float kMax = std::numeric_limits<float>::max();
    const Floats finite_check = (u - u) + (v - v) + px2 + py2;  // NaN or ∞ unless all finite
    const Ints finite = (finite_check < splat<Floats>(kMax)) & (finite_check > splat<Floats>(-kMax));
    // Those lanes' positions are not used: zero keeps every conversion below defined.
    u = reduce<W>(finite ? u : splat<Floats>(0.0f), s.wrap_u);
    v = reduce<W>(finite ? v : splat<Floats>(0.0f), s.wrap_v);

    Floats lambda = splat<Floats>(0.0f);
    const Floats rho2 = max_v(px2, py2) * load_v<Floats>(first + rho2_scale);
    // λ = 0 for every lane when all plainly magnify (ρ ≤ 1 texel, no bias, no positive min_lod).
    const bool magnifying = s.lod_bias == 0.0f && s.min_lod <= 0.0f && !any(rho2 > splat<Floats>(1.0f));
    if (s.needs_derivatives() && s.mip_filter == MipFilter::linear && !magnifying) {
        // λ as lod_from_log2_size computes it, in float: log2 ρ + bias, bounded, snapped to an
        // integer within 10⁻⁶, clamped to [min_lod, max_lod] and [0, levels − 1].
        constexpr float kTiny = 0x1p-100f;  // below: log2 ρ = −∞ (what log2 0 gives in double)
        Floats log2_rho = 0.5f * log2_v<W>(max_v(rho2, splat<Floats>(kTiny)));
        log2_rho = rho2 < splat<Floats>(kTiny) ? splat<Floats>(-std::numeric_limits<float>::infinity()) : log2_rho;
        lambda = clamp_v(log2_rho + s.lod_bias, splat<Floats>(-1.0f), splat<Floats>(static_cast<float>(levels)));
        const Floats nearest_integer = floor_v<Ints>(lambda + 0.5f);
        const Floats distance = lambda - nearest_integer;
        lambda = (distance < splat<Floats>(1e-6f)) & (distance > splat<Floats>(-1e-6f)) ? nearest_integer : lambda;
        lambda = clamp_v(lambda, splat<Floats>(s.min_lod), splat<Floats>(s.max_lod));
        lambda = clamp_v(lambda, splat<Floats>(0.0f), splat<Floats>(static_cast<float>(levels - 1)));
    }
    const Ints fine = convert<Ints>(lambda);  // λ ∈ [0, levels − 1]: truncation is the floor
    Floats weight = lambda - convert<Floats>(fine);
    weight = fine + 1 < levels ? weight : splat<Floats>(0.0f);
    std::memcpy(plan.level + first, &fine, sizeof fine);
    std::memcpy(plan.level_weight + first, &weight, sizeof weight);
    std::memcpy(plan.finite + first, &finite, sizeof finite);
    return {u, v, fine, s.needs_derivatives() && s.mip_filter == MipFilter::linear && any(weight > 0.0f)};
}

// Part two: the bilinear quads on level k and k + 1 (sizes max(1, ⌊w/2^k⌋), exact in float); only
// on level k where no lane blends (λ an integer: an exact 2^k footprint, or magnification).
// kPowerOfTwo: both of the texture's sizes are powers of two (so are its levels').
template <int W, bool kPowerOfTwo>
[[gnu::always_inline]] inline void plan_quads(const LaneLevels<W>& lanes, int first, const Sampler& s, int width_texels,
                                              int height_texels, int levels, LanePlan& plan) {
    MIPRASTER_LANES(W);
    const Ints fine = lanes.fine;
    const Floats u = lanes.u, v = lanes.v;
    for (int step = 0; step < (lanes.blends ? 2 : 1); ++step) {
        const Ints k = min_v(fine + step, Ints{} + (levels - 1));
        Ints wk_int, hk_int;
        if constexpr (W == 8) {  // AVX2 shifts each lane by its own count
            wk_int = max_v((Ints{} + width_texels) >> k, Ints{} + 1);
            hk_int = max_v((Ints{} + height_texels) >> k, Ints{} + 1);
        } else {
            const Floats scale = bits_as<Floats>((127 - k) << 23);  // 2^−k
            wk_int = max_v(convert<Ints>(static_cast<float>(width_texels) * scale), Ints{} + 1);
            hk_int = max_v(convert<Ints>(static_cast<float>(height_texels) * scale), Ints{} + 1);
        }
        const Floats wk = convert<Floats>(wk_int), hk = convert<Floats>(hk_int);
        Ints i0, i1, j0, j1;
        Floats fx, fy;
        axis<W, kPowerOfTwo>(u, wk, wk_int, s.wrap_u, i0, i1, fx);
        axis<W, kPowerOfTwo>(v, hk, hk_int, s.wrap_v, j0, j1, fy);
        const Ints row_floats = wk_int << 2, row0 = j0 * row_floats, row1 = j1 * row_floats;
        i0 <<= 2, i1 <<= 2;
        // (Four stores, not a loop over an array of vectors: GCC copied such an array through the
        // stack in halves, and the reloads waited on the wide stores.)
        store_v(plan.texel_float[step][0] + first, row0 + i0);
        store_v(plan.texel_float[step][1] + first, row0 + i1);
        store_v(plan.texel_float[step][2] + first, row1 + i0);
        store_v(plan.texel_float[step][3] + first, row1 + i1);
        store_v(plan.fx[step] + first, fx);
        store_v(plan.fy[step] + first, fy);
    }
}

// The plan of lanes 0 … count − 1: four at a time on the baseline, eight with AVX2. Sixteen lanes
// are two (or four) independent chains of arithmetic, which the CPU overlaps: a batch of eight
// left the planner waiting on one chain's latency. With AVX2 both halves' levels come first, so
// that their λ chains (a division and a polynomial) are near enough in the code to overlap.
// Without `quads`, only the levels (a batch whose lanes all take lines of probes).
void plan_sse2(const LookupBatch& b, const float* rho2_scale, int count, bool quads, const Sampler& s, int width,
               int height, int levels, LanePlan& plan) {
    for (int first = 0; first < count; first += 4) {
        const LaneLevels<4> lanes = plan_levels<4>(b, rho2_scale, first, s, width, height, levels, plan);
        if (quads) plan_quads<4, false>(lanes, first, s, width, height, levels, plan);
    }
}
#if defined(__x86_64__)
template <bool kPowerOfTwo>
[[gnu::always_inline]] inline void plan_eight(const LookupBatch& b, const float* rho2_scale, bool quads,
                                              const Sampler& s, int width, int height, int levels, LanePlan& plan) {
    const LaneLevels<8> low = plan_levels<8>(b, rho2_scale, 0, s, width, height, levels, plan);
    const LaneLevels<8> high = plan_levels<8>(b, rho2_scale, 8, s, width, height, levels, plan);
    if (!quads) return;
    plan_quads<8, kPowerOfTwo>(low, 0, s, width, height, levels, plan);
    plan_quads<8, kPowerOfTwo>(high, 8, s, width, height, levels, plan);
}
[[gnu::target("avx2")]] void plan_avx2(const LookupBatch& b, const float* rho2_scale, int, bool quads, const Sampler& s,
                                      int width, int height, int levels, LanePlan& plan) {
    const bool powers_of_two = (width & (width - 1)) == 0 && (height & (height - 1)) == 0;
    if (powers_of_two) plan_eight<true>(b, rho2_scale, quads, s, width, height, levels, plan);
    else plan_eight<false>(b, rho2_scale, quads, s, width, height, levels, plan);
}
#else  // (other CPUs: the four-lane path; never called)
void plan_avx2(const LookupBatch& b, const float* rho2_scale, int count, bool quads, const Sampler& s, int width,
               int height, int levels, LanePlan& plan) {
    plan_sse2(b, rho2_scale, count, quads, s, width, height, levels, plan);
}
#endif

// Whether lanes 0 … n − 1 of the plan are all finite, on level `level`, and blend with the next
// level or not as `blends` says: four lanes at a time (a loop per lane did not vectorize; the
// lanes up to the next multiple of four are planned too, and left out by their index).
bool same_levels(const LanePlan& plan, int n, std::int32_t level, bool blends) {
    using Ints = Lanes<4>::Ints;
    using Floats = Lanes<4>::Floats;
    Ints all = Ints{} - 1;
    for (int l = 0; l < n; l += 4) {
        Ints levels, finite;
        std::memcpy(&levels, plan.level + l, sizeof levels);
        std::memcpy(&finite, plan.finite + l, sizeof finite);
        const Ints blending = load_v<Floats>(plan.level_weight + l) > splat<Floats>(0.0f);
        const Ints beyond = Ints{0, 1, 2, 3} + l >= n;
        all &= beyond | (finite & (levels == level) & (blending == (blends ? -1 : 0)));
    }
    return (all[0] & all[1] & all[2] & all[3]) != 0;
}

// Per lane of an anisotropic batch, the line of probes sample_texture would take (decided in
// double as it decides): how many probes, along which derivative, and the factor 1/N² that makes
// the plan's λ log2(Pmax/N). One probe (count 1, factor 1) for isotropic footprints,
// magnification and lanes that are not finite (the plan sends those to the reference).
struct ProbeLines {
    std::int32_t count[kLookupBatch];
    std::int32_t along_x[kLookupBatch];  // −1: along the x derivative, 0: the y one
    float rho2_scale[kLookupBatch];
};

// Fills `lines` for lanes 0 … n − 1 (rho2_scale arrives filled with 1); gives how many lanes take
// more than one probe.
int probe_lines(const LookupBatch& b, int n, int width, int height, int levels, const Sampler& s, ProbeLines& lines) {
    typedef double Doubles __attribute__((vector_size(16)));
    typedef float Pair __attribute__((vector_size(8)));
    int taking = 0;
    for (int l = 0; l < n; l += 2) {  // (an odd count reads one unused lane)
        const auto widen = [&](const float* p) {
            Pair x;
            std::memcpy(&x, p + l, sizeof x);
            return __builtin_convertvector(x, Doubles);
        };
        const Doubles ux = widen(b.dudx) * double(width), vx = widen(b.dvdx) * double(height);
        const Doubles uy = widen(b.dudy) * double(width), vy = widen(b.dvdy) * double(height);
        const Doubles px2 = ux * ux + vx * vx, py2 = uy * uy + vy * vy;
        for (int k = l; k < l + 2 && k < n; ++k) {
            const double x = px2[k - l], y = py2[k - l];
            lines.count[k] = 1;
            lines.along_x[k] = x >= y ? -1 : 0;
            if (x == y && y > 0.0) continue;  // one probe
            if (!(std::isfinite(x) && std::isfinite(y))) continue;
            const int count = anisotropic_probe_count(x, y, s.max_anisotropy);
            if (count == 1 || anisotropic_magnifies(std::max(x, y), s, levels)) continue;
            lines.count[k] = count;
            lines.rho2_scale[k] = 1.0f / static_cast<float>(count * count);
            ++taking;
        }
    }
    return taking;
}

#if defined(__x86_64__)
// probe_lines with AVX2, four lanes per vector: per lane the same double operations (a division, a
// square root and ⌈⌉ are exact-rounded in vectors too), so the same counts and factors. A lane
// whose line anisotropic_magnifies' first test (kSurelyMinifying2) cannot settle asks it. (One
// lane at a time, the division and the root were a tenth of a 16× anisotropic frame.)
[[gnu::target("avx2")]] int probe_lines_avx2(const LookupBatch& b, int n, int width, int height, int levels,
                                             const Sampler& s, ProbeLines& lines) {
    const int max_n = most_probes(s.max_anisotropy);
    const __m256d most = _mm256_set1_pd(max_n), most2 = _mm256_set1_pd(double(max_n) * max_n);
    const __m256d w = _mm256_set1_pd(width), h = _mm256_set1_pd(height);
    const __m256d infinity = _mm256_set1_pd(std::numeric_limits<double>::infinity());
    const bool plain = lod_is_plain(s, levels);
    int taking = 0;
    for (int l = 0; l < n; l += 4) {
        const __m128i used = _mm_cmpgt_epi32(_mm_set1_epi32(n - l), _mm_setr_epi32(0, 1, 2, 3));
        const auto widen = [&](const float* p) __attribute__((target("avx2"))) {
            return _mm256_cvtps_pd(_mm_maskload_ps(p + l, used));
        };
        const __m256d ux = _mm256_mul_pd(widen(b.dudx), w), vx = _mm256_mul_pd(widen(b.dvdx), h);
        const __m256d uy = _mm256_mul_pd(widen(b.dudy), w), vy = _mm256_mul_pd(widen(b.dvdy), h);
        const __m256d x = _mm256_add_pd(_mm256_mul_pd(ux, ux), _mm256_mul_pd(vx, vx));
        const __m256d y = _mm256_add_pd(_mm256_mul_pd(uy, uy), _mm256_mul_pd(vy, vy));
        const __m256d pmax = _mm256_max_pd(x, y), ratio2 = _mm256_div_pd(pmax, _mm256_min_pd(x, y));
        // ⌈Pmax/Pmin⌉ below max_n (an isotropic footprint: 1), else max_n (also for Pmin = 0).
        const __m256d root_up = _mm256_round_pd(_mm256_sqrt_pd(ratio2), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
        const __m256d count = _mm256_blendv_pd(most, root_up, _mm256_cmp_pd(ratio2, most2, _CMP_LT_OQ));
        const __m256d finite = _mm256_and_pd(_mm256_cmp_pd(x, infinity, _CMP_LT_OQ),
                                             _mm256_cmp_pd(y, infinity, _CMP_LT_OQ));
        const __m256d lines_of_probes = _mm256_and_pd(finite, _mm256_cmp_pd(count, _mm256_set1_pd(1.0), _CMP_GT_OQ));
        const __m256d minifies = _mm256_cmp_pd(pmax, _mm256_set1_pd(kSurelyMinifying2), _CMP_GT_OQ);
        alignas(32) double pmaxes[4];
        _mm256_store_pd(pmaxes, pmax);
        const int lanes_used = (1 << std::min(4, n - l)) - 1;
        int take = plain ? _mm256_movemask_pd(_mm256_and_pd(lines_of_probes, minifies)) & lanes_used : 0;
        const int ask = _mm256_movemask_pd(lines_of_probes) & lanes_used & ~take;
        for (int k = 0; k < 4; ++k)
            if ((ask >> k & 1) && !anisotropic_magnifies(pmaxes[k], s, levels)) take |= 1 << k;
        const __m128i taken = _mm_cmpgt_epi32(_mm_and_si128(_mm_set1_epi32(take), _mm_setr_epi32(1, 2, 4, 8)),
                                              _mm_setzero_si128());
        const __m128i counts = _mm_blendv_epi8(_mm_set1_epi32(1), _mm256_cvttpd_epi32(count), taken);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(lines.count + l), counts);
        _mm_storeu_ps(lines.rho2_scale + l,
                      _mm_div_ps(_mm_set1_ps(1.0f), _mm_cvtepi32_ps(_mm_mullo_epi32(counts, counts))));
        const __m256 along_x = _mm256_castpd_ps(_mm256_cmp_pd(x, y, _CMP_GE_OQ));  // (each mask's low half)
        const __m256 low_halves = _mm256_permutevar8x32_ps(along_x, _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(lines.along_x + l),
                         _mm_castps_si128(_mm256_castps256_ps128(low_halves)));
        taking += __builtin_popcount(take);
    }
    return taking;
}
#else  // (other CPUs: the scalar lanes; never called)
int probe_lines_avx2(const LookupBatch& b, int n, int width, int height, int levels, const Sampler& s,
                     ProbeLines& lines) {
    return probe_lines(b, n, width, height, levels, s, lines);
}
#endif

}  // namespace

BatchSampler::BatchSampler(const TextureView& texture, const Sampler& sampler, int vector_width)
    : texture_(texture), sampler_(sampler), covered_(covers(sampler)),
      vector_width_(vector_width == 0 ? widest_vector() : vector_width) {
    if (vector_width_ != 4 && vector_width_ != 8)
        throw std::invalid_argument("BatchSampler: vector width " + std::to_string(vector_width) + "; expected 0, 4 or 8");
    if (vector_width_ > widest_vector())
        throw std::invalid_argument("BatchSampler: vector width 8 needs AVX2, which this CPU does not have");
}

int BatchSampler::widest_vector() {
#if defined(__x86_64__)
    static const int widest = __builtin_cpu_supports("avx2") ? 8 : 4;
#else
    static const int widest = 4;
#endif
    return widest;
}

bool BatchSampler::covers(const Sampler& s) {
    const auto wrap = [](WrapMode m) { return m == WrapMode::repeat || m == WrapMode::clamp; };
    return s.mag_filter == TexelFilter::linear && s.min_filter == TexelFilter::linear &&
           (s.mip_filter == MipFilter::linear || s.mip_filter == MipFilter::none) &&
           (s.footprint == FootprintFilter::isotropic || s.footprint == FootprintFilter::anisotropic) &&
           wrap(s.wrap_u) && wrap(s.wrap_v);
}

const TextureLevel* BatchSampler::first_record_use(int k) { return level_records_[k] = &texture_.level(k); }

namespace {

// Texel indices first … last (first ≤ last) along an axis of n texels, as the wrap mode maps
// them: one range, or two where a repeated range crosses the edge.
int wrapped_ranges(long first, long last, int n, WrapMode mode, int (&from)[2], int (&to)[2]) {
    if (mode != WrapMode::repeat) {
        from[0] = static_cast<int>(std::clamp<long>(first, 0, n - 1));
        to[0] = static_cast<int>(std::clamp<long>(last, 0, n - 1));
        return 1;
    }
    if (last - first + 1 >= n) {
        from[0] = 0, to[0] = n - 1;
        return 1;
    }
    const int a = static_cast<int>((first % n + n) % n), b = static_cast<int>((last % n + n) % n);
    from[0] = a, to[0] = a <= b ? b : n - 1;
    if (a <= b) return 1;
    from[1] = 0, to[1] = b;
    return 2;
}

}  // namespace

TexelArea texel_area(int w, int h, glm::dvec2 lo, glm::dvec2 hi, WrapMode wrap_u, WrapMode wrap_v) {
    TexelArea a;
    constexpr double kLimit = 0x1p20;
    // (Written so that NaN fails: every comparison with it is false.)
    if (!(lo.x <= hi.x && lo.y <= hi.y && lo.x >= -kLimit && lo.y >= -kLimit && hi.x <= kLimit && hi.y <= kLimit))
        return a;
    // A lookup at x = u·w − ½ reads texels ⌊x⌋ and ⌊x⌋ + 1 (the float path rounds u·w; the spare
    // texel on each side covers that).
    a.columns = wrapped_ranges(static_cast<long>(std::floor(lo.x * w - 0.5)) - 1,
                               static_cast<long>(std::floor(hi.x * w - 0.5)) + 2, w, wrap_u, a.x_from, a.x_to);
    a.rows = wrapped_ranges(static_cast<long>(std::floor(lo.y * h - 0.5)) - 1,
                            static_cast<long>(std::floor(hi.y * h - 0.5)) + 2, h, wrap_v, a.y_from, a.y_to);
    return a;
}

void BatchSampler::prefetch(glm::dvec2 lo, glm::dvec2 hi, double lambda) {
    if (!covered_ || !(lambda == lambda)) return;
    const int levels = texture_.level_count();
    const bool mipmapped = sampler_.mip_filter == MipFilter::linear;
    const int finer = !mipmapped || lambda <= 0.0 ? 0 : lambda < levels - 1 ? static_cast<int>(lambda) : levels - 1;
    const int coarser = mipmapped && finer + 1 < levels && lambda > finer ? finer + 1 : finer;
    for (int k = finer; k <= coarser; ++k) {
        // A level no lookup has needed yet is not built for a hint (DESIGN.md §3).
        const TextureLevel* built = texture_.built_level(k);
        if (!built) return;
        const int w = built->width;
        const TexelArea a = texel_area(w, built->height, lo, hi, sampler_.wrap_u, sampler_.wrap_v);
        long rows = 0, columns = 0;
        for (int i = 0; i < a.rows; ++i) rows += a.y_to[i] - a.y_from[i] + 1;
        for (int i = 0; i < a.columns; ++i) columns += a.x_to[i] - a.x_from[i] + 1;
        if (rows * (columns / 4 + 2) > kMaxPrefetchLines) return;
        // Into the second-level cache: a tile's area can hold more lines than the first-level
        // cache, where they evicted each other before use (no gain measured from prefetcht0).
        const glm::vec4* texels = built->texels.data();
        for (int r = 0; r < a.rows; ++r)
            for (int y = a.y_from[r]; y <= a.y_to[r]; ++y)
                for (int c = 0; c < a.columns; ++c) {
                    const glm::vec4* row = texels + static_cast<std::size_t>(y) * w;
                    const auto first = reinterpret_cast<std::uintptr_t>(row + a.x_from[c]) & ~std::uintptr_t{63};
                    const auto end = reinterpret_cast<std::uintptr_t>(row + a.x_to[c] + 1);
                    for (std::uintptr_t line = first; line < end; line += 64)
                        __builtin_prefetch(reinterpret_cast<const void*>(line), 0, 2);
                }
    }
}

void BatchSampler::sample(const LookupBatch& batch, glm::vec4* out) {
    const int n = batch.count;
    if (n < 0 || n > kLookupBatch)
        throw std::invalid_argument("BatchSampler: batch count " + std::to_string(n) + "; expected 0 to " +
                                    std::to_string(kLookupBatch));
    if (!covered_) {
        for (int l = 0; l < n; ++l)
            out[l] = sample_texture(texture_, sampler_, {batch.u[l], batch.v[l]}, {batch.dudx[l], batch.dvdx[l]},
                                    {batch.dudy[l], batch.dvdy[l]});
        return;
    }
    const LookupBatch& b = batch;

    const Sampler& s = sampler_;
    const int levels = texture_.level_count();
    ProbeLines lines;
    std::fill(lines.rho2_scale, lines.rho2_scale + kLookupBatch, 1.0f);
    const int line_count = s.footprint != FootprintFilter::anisotropic ? 0
                           : (vector_width_ == 8 ? probe_lines_avx2 : probe_lines)(b, n, texture_.width(),
                                                                                   texture_.height(), levels, s, lines);
    const bool some_lines = line_count > 0;
    // A batch whose lanes all take lines (a surface at a grazing angle) reads no quad of the plan.
    const bool only_lines = line_count == n;
    LanePlan plan;
    (vector_width_ == 8 ? plan_avx2 : plan_sse2)(b, lines.rho2_scale, n, !only_lines, s, texture_.width(),
                                                 texture_.height(), levels, plan);
    // Lanes spread over more than one row of texels (a surface whose texture runs across the
    // screen's rows) read texels the hardware prefetcher cannot foresee: the rows of all quads on
    // the finer level are asked for first, so that the misses overlap instead of each lane
    // waiting for its own. (The coarser level has a quarter of the lines, mostly in cache; asking
    // for them too, or on four rows' spread only, saved less in the cube.)
    if (!only_lines && n > 1 && std::abs(std::int64_t{plan.texel_float[0][0][n - 1]} - plan.texel_float[0][0][0]) >
                     4 * std::max(1, texture_.width() >> plan.level[0])) {
        for (int l = 0; l < n; ++l) {
            if (!plan.finite[l] || (some_lines && lines.count[l] > 1)) continue;
            const float* t = level_floats(plan.level[l]);
            __builtin_prefetch(t + plan.texel_float[0][0][l]);
            __builtin_prefetch(t + plan.texel_float[0][2][l]);
        }
    }
    // The lines of all the batch's lanes that take them, at once: the reference's lines of probes,
    // on the plan's level(s).
    if (some_lines) {
        LineLanes line_lanes;
        std::int32_t every_lane_finite = -1;
        for (int l = 0; l < n; ++l) every_lane_finite &= plan.finite[l];
        if (only_lines && every_lane_finite) {  // lane l's line is line l: field by field (loops that vectorize)
            line_lanes.n = n;
            for (int l = 0; l < n; ++l) line_lanes.out[l] = l, line_lanes.count[l] = lines.count[l];
            for (int l = 0; l < n; ++l) line_lanes.u[l] = b.u[l], line_lanes.v[l] = b.v[l];
            for (int l = 0; l < n; ++l) line_lanes.du[l] = lines.along_x[l] ? b.dudx[l] : b.dudy[l];
            for (int l = 0; l < n; ++l) line_lanes.dv[l] = lines.along_x[l] ? b.dvdx[l] : b.dvdy[l];
            std::memcpy(line_lanes.weight, plan.level_weight, sizeof plan.level_weight);
        } else {
            for (int l = 0; l < n; ++l) {
                if (!plan.finite[l] || lines.count[l] == 1) continue;
                const int i = line_lanes.n++;
                line_lanes.out[i] = l, line_lanes.count[i] = lines.count[l];
                line_lanes.u[i] = b.u[l], line_lanes.v[i] = b.v[l];
                line_lanes.du[i] = lines.along_x[l] ? b.dudx[l] : b.dudy[l];
                line_lanes.dv[i] = lines.along_x[l] ? b.dvdx[l] : b.dvdy[l];
                line_lanes.weight[i] = plan.level_weight[l];
            }
        }
        for (int i = 0; i < line_lanes.n; ++i) {
            const int l = line_lanes.out[i];
            line_lanes.finer[i] = level_record(plan.level[l]);
            line_lanes.coarser[i] = plan.level_weight[l] > 0.0f ? level_record(plan.level[l] + 1) : nullptr;
        }
        (vector_width_ == 8 ? anisotropic_lines_avx2 : anisotropic_lines)(line_lanes, s, out);
        if (line_lanes.n == n) return;  // (every lane's)
    }
    // One lane's bilinear blend of its quad on level t (step 0: the finer, 1: the coarser), and its
    // trilinear blend of both at finer / coarser.
    const auto bilinear = [&](int l, const float* t, int step) {
        const std::int32_t(&q)[4][kLookupBatch] = plan.texel_float[step];
        return lerp_quad(load(t + q[0][l]), load(t + q[1][l]), load(t + q[2][l]), load(t + q[3][l]),
                         plan.fx[step][l], plan.fy[step][l]);
    };
    const auto trilinear = [&](int l, const float* finer, const float* coarser) {
#if defined(__AVX__)  // both levels' quads side by side: the same operations per half
        const auto corner = [&](int k) {
            return load_pair(finer + plan.texel_float[0][k][l], coarser + plan.texel_float[1][k][l]);
        };
        const TexelPair top = lerp_pair(corner(0), corner(1), plan.fx[0][l], plan.fx[1][l]);
        const TexelPair bottom = lerp_pair(corner(2), corner(3), plan.fx[0][l], plan.fx[1][l]);
        const TexelPair both = lerp_pair(top, bottom, plan.fy[0][l], plan.fy[1][l]);
        return lerp(finer_half(both), coarser_half(both), plan.level_weight[l]);
#else
        return lerp(bilinear(l, finer, 0), bilinear(l, coarser, 1), plan.level_weight[l]);
#endif
    };
    // Finite lanes that all read the same level(s) (96 % of a textured plane's batches: λ changes
    // slowly across a batch's pixels) need no per-lane tests or level lookups.
    if (!some_lines) {
        const std::int32_t level = plan.level[0];
        const bool blends = plan.level_weight[0] > 0.0f;
        if (same_levels(plan, n, level, blends)) {
            const float* finer = level_floats(level);
            if (blends) {
                const float* coarser = level_floats(level + 1);
                for (int l = 0; l < n; ++l) out[l] = to_vec4(trilinear(l, finer, coarser));
            } else {
                for (int l = 0; l < n; ++l) out[l] = to_vec4(bilinear(l, finer, 0));
            }
            return;
        }
    }
    for (int l = 0; l < n; ++l) {
        if (!plan.finite[l]) {
            out[l] = sample_texture(texture_, s, {b.u[l], b.v[l]}, {b.dudx[l], b.dvdx[l]}, {b.dudy[l], b.dvdy[l]});
            continue;
        }
        if (some_lines && lines.count[l] > 1) continue;  // (its line's)
        const float* finer = level_floats(plan.level[l]);
        out[l] = to_vec4(plan.level_weight[l] > 0.0f ? trilinear(l, finer, level_floats(plan.level[l] + 1))
                                                     : bilinear(l, finer, 0));
    }
}

}  // namespace mipraster
