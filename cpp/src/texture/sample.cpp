#include "mipraster/texture/sample.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "anisotropic_line.hpp"
#include "texel.hpp"

namespace mipraster {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// λ within this of an integer is taken as that integer (float derivatives carry ~1e-7 relative
// error; log2 turns that into ~1e-7 absolute).
constexpr double kLodSnap = 1e-6;

using namespace texel;

// ⌊x⌋ and ⌈x⌉ of a finite x well inside the int range (callers bound x first): a truncation and a
// compare, where std::floor is a library call on the x86-64 baseline.
inline int floor_int(double x) {
    const int i = static_cast<int>(x);
    return i - (x < i);
}
inline int ceil_int(double x) {
    const int i = static_cast<int>(x);
    return i + (x > i);
}
// std::floor of a finite x without the library call: from 2^52 on every double is an integer.
inline double floor_double(double x) {
    if (!(std::abs(x) < 0x1p52)) return x;
    const double t = static_cast<double>(static_cast<std::int64_t>(x));
    return t - (x < t);
}

// A texel-space coordinate moved by whole periods (repeat, mirror) or clamped just past the
// edges (clamp, border), so that its floor and the indices next to it fit an int. No float
// reaches an int conversion before this (DESIGN.md §2.6).
[[gnu::noinline]] double reduce_outside(double x, int n, WrapMode mode) {
    switch (mode) {
        case WrapMode::repeat: return x - n * floor_double(x / n);
        case WrapMode::mirror: return x - 2.0 * n * floor_double(x / (2.0 * n));
        default: return std::clamp(x, -2.0, n + 2.0);
    }
}

inline double reduce(double x, int n, WrapMode mode) {
    if (x >= 0.0 && x < n) return x;  // inside the texture: every mode leaves it (and skips a division)
    return reduce_outside(x, n, mode);
}

// The centre of a footprint with half extent `extent` (texels), moved like reduce() but, for
// clamp and border, only so far that the footprint stays as far outside the texture as it was:
// there every texel it covers is the same edge texel or border colour, wherever it is. The move
// keeps the fractional part (whole texels), so EWA's discrete weights, which depend on the
// centre's phase against the texel grid, are the same as at the unmoved centre.
double centre(double x, int n, double extent, WrapMode mode) {
    if (mode == WrapMode::repeat || mode == WrapMode::mirror) return reduce(x, n, mode);
    const double lo = -extent - 2.0, hi = n + extent + 2.0;
    if (x < lo) return std::floor(lo) - 1.0 + (x - std::floor(x));
    if (x > hi) return std::ceil(hi) + 1.0 + (x - std::floor(x));
    return x;
}

// Index along one axis after wrapping; −1 for the border. |i| stays within a few periods.
int wrap_index(int i, int n, WrapMode mode) {
    if (static_cast<unsigned>(i) < static_cast<unsigned>(n)) return i;  // inside: every mode agrees
    switch (mode) {
        case WrapMode::repeat: i %= n; return i < 0 ? i + n : i;
        case WrapMode::mirror: {
            i %= 2 * n;
            if (i < 0) i += 2 * n;
            return i < n ? i : 2 * n - 1 - i;
        }
        case WrapMode::clamp: return std::clamp(i, 0, n - 1);
        case WrapMode::border: return i < 0 || i >= n ? -1 : i;
    }
    return -1;
}

Texel fetch(const TextureLevel& level, int i, int j, const Sampler& s) {
    i = wrap_index(i, level.width, s.wrap_u);
    j = wrap_index(j, level.height, s.wrap_v);
    if (i < 0 || j < 0) return load(s.border_color);
    return load(level.at(i, j));
}

// The seeds' nearest rule: the texel whose cell holds the point, i = ⌊u·w⌋.
Texel nearest(const TextureLevel& level, double u, double v, const Sampler& s) {
    const double x = reduce(u * level.width, level.width, s.wrap_u);
    const double y = reduce(v * level.height, level.height, s.wrap_v);
    return fetch(level, floor_int(x), floor_int(y), s);
}

// The quad at (i, j) when part of it lies outside the texture: each texel wrapped on its own.
// Out of line, so the in-range path below stays small enough to inline into the filter loops.
[[gnu::noinline]] Texel bilinear_wrapped(const TextureLevel& level, int i, int j, float ax, float ay,
                                         const Sampler& s) {
    return lerp_quad(fetch(level, i, j, s), fetch(level, i + 1, j, s), fetch(level, i, j + 1, s),
                     fetch(level, i + 1, j + 1, s), ax, ay);
}

// The quad at (i, j) when it lies inside the level (i + 1 < width, j + 1 < height).
inline Texel inside_quad(const TextureLevel& level, int i, int j, float ax, float ay) {
    const std::size_t w = level.width;
    const glm::vec4* q = level.texels.data() + static_cast<std::size_t>(j) * w + i;
    return lerp_quad(load(q[0]), load(q[1]), load(q[w]), load(q[w + 1]), ax, ay);
}

// Bilinear between the four nearest texel centres, i = ⌊u·w − ½⌋. Positions and fractions are
// found in double (so large textures and far repeats keep their sub-texel phase); the texels
// are blended in float.
inline Texel bilinear(const TextureLevel& level, double u, double v, const Sampler& s) {
    const double x = reduce(u * level.width, level.width, s.wrap_u) - 0.5;
    const double y = reduce(v * level.height, level.height, s.wrap_v) - 0.5;
    if (x >= 0.0 && y >= 0.0) {  // truncation is the floor: one dependent step less than floor_int
        const int i = static_cast<int>(x), j = static_cast<int>(y);
        if (i + 1 < level.width && j + 1 < level.height)  // no wrapping: most lookups
            return inside_quad(level, i, j, static_cast<float>(x - i), static_cast<float>(y - j));
    }
    const int i = floor_int(x), j = floor_int(y);
    return bilinear_wrapped(level, i, j, static_cast<float>(x - i), static_cast<float>(y - j), s);
}

template <TexelFilter kFilter>
inline Texel texel_filter(const TextureLevel& level, double u, double v, const Sampler& s) {
    if constexpr (kFilter == TexelFilter::nearest) return nearest(level, u, v, s);
    else return bilinear(level, u, v, s);
}

Texel texel_filter(const TextureLevel& level, double u, double v, TexelFilter filter, const Sampler& s) {
    return filter == TexelFilter::nearest ? nearest(level, u, v, s) : bilinear(level, u, v, s);
}

// The derivative vectors in texels of level 0.
struct Footprint {
    double ux, vx, uy, vy;  // ∂(u·w, v·h)/∂x and /∂y
    bool finite() const { return std::isfinite(ux) && std::isfinite(vx) && std::isfinite(uy) && std::isfinite(vy); }
    // Squared lengths: from float derivatives (< 2^128 · 2^16 texels) they stay finite in double.
    double length2_x() const { return ux * ux + vx * vx; }
    double length2_y() const { return uy * uy + vy * vy; }
};

Footprint texel_footprint(const TextureView& t, glm::vec2 dx, glm::vec2 dy) {
    return {double(dx.x) * t.width(), double(dx.y) * t.height(), double(dy.x) * t.width(), double(dy.y) * t.height()};
}

// log2 ρ from ρ²; a non-finite ρ² gives +∞ (the coarsest level).
double log2_size(double rho2) { return rho2 < kInf ? 0.5 * std::log2(rho2) : kInf; }  // log2(0) = −inf

// λ from log2 ρ: + bias, snapped to an integer within kLodSnap, clamped to [min_lod, max_lod]
// and [0, levels − 1].
double lod_from_log2_size(double log2_rho, const Sampler& s, int levels) {
    // Bounded first (the snap converts to int); outside [−1, levels] the clamps below decide alone.
    double lambda = std::clamp(log2_rho + s.lod_bias, -1.0, double(levels));
    // Derivatives arrive as floats: a footprint of exactly 2^k texels comes out a few ulps short.
    // Snap such λ to the integer, so it reads one level, not two (the other at weight ~1e-8).
    const int k = floor_int(lambda + 0.5);
    if (std::abs(lambda - k) < kLodSnap) lambda = k;
    lambda = std::clamp(lambda, double(s.min_lod), double(s.max_lod));
    return std::clamp(lambda, 0.0, double(levels - 1));  // [0, levels − 1] even for a negative min_lod
}

// True when ρ² ≤ 1 is sure to magnify without a log2: no bias and no positive min_lod.
bool plainly_magnifies(double rho2, const Sampler& s) {
    return rho2 <= 1.0 && s.lod_bias == 0.0f && s.min_lod <= 0.0f;
}

double isotropic_lod(const Footprint& f, const Sampler& s, int levels) {
    const double lx = f.length2_x(), ly = f.length2_y();
    if (!(lx < kInf && ly < kInf)) return lod_from_log2_size(kInf, s, levels);  // some derivative not finite
    const double rho2 = std::max(lx, ly);
    if (plainly_magnifies(rho2, s)) return 0.0;
    return lod_from_log2_size(log2_size(rho2), s, levels);
}

// Minification within the mip chain at λ > 0 with the sampler's mip filter and min filter kFilter
// (a template argument, so that trilinear's two quads inline).
template <TexelFilter kFilter>
[[gnu::noinline]] Texel mip_filter(const TextureView& t, double u, double v, double lambda, const Sampler& s) {
    switch (s.mip_filter) {
        case MipFilter::none: return texel_filter<kFilter>(t.level(0), u, v, s);
        case MipFilter::nearest: {
            // GL's choice: level ⌈λ + ½⌉ − 1, so λ ≤ ½ stays on level 0.
            const int k = std::clamp(ceil_int(lambda + 0.5) - 1, 0, t.level_count() - 1);
            return texel_filter<kFilter>(t.level(k), u, v, s);
        }
        case MipFilter::linear: {
            const int k = std::min(static_cast<int>(lambda), t.level_count() - 1);
            const double f = lambda - k;
            const Texel a = texel_filter<kFilter>(t.level(k), u, v, s);
            if (f <= 0.0 || k + 1 >= t.level_count()) return a;
            return lerp(a, texel_filter<kFilter>(t.level(k + 1), u, v, s), static_cast<float>(f));
        }
    }
    return splat(0.0f);
}

// Isotropic: one mip lookup at λ, or the magnification filter when λ ≤ 0.
Texel isotropic(const TextureView& t, double u, double v, double lambda, const Sampler& s) {
    if (lambda <= 0.0) return texel_filter(t.level(0), u, v, s.mag_filter, s);
    if (s.min_filter == TexelFilter::linear) return mip_filter<TexelFilter::linear>(t, u, v, lambda, s);
    return mip_filter<TexelFilter::nearest>(t, u, v, lambda, s);
}

// EXT_texture_filter_anisotropic: N = min(⌈Pmax/Pmin⌉, max anisotropy) probes spaced evenly
// along the major derivative over the pixel, each a mip lookup at λ = log2(Pmax/N).
struct AnisoProbes {
    bool magnifies = false;     // isotropic λ ≤ 0: one magnification lookup instead
    int count = 1;
    double lambda = 0.0;
    double du = 0.0, dv = 0.0;  // the major derivative in uv
};

constexpr int kMostProbes = 1024;
// log2 N for every probe count N (one log2 call saved per lookup).
const std::array<double, kMostProbes + 1> kLog2Count = [] {
    std::array<double, kMostProbes + 1> table{};
    for (int n = 1; n <= kMostProbes; ++n) table[n] = std::log2(double(n));
    return table;
}();
// 1/N for every probe count N: the same division, out of each lookup's chain of dependent steps.
const std::array<double, kMostProbes + 1> kInverseCount = [] {
    std::array<double, kMostProbes + 1> table{};
    for (int n = 1; n <= kMostProbes; ++n) table[n] = 1.0 / n;
    return table;
}();

}  // namespace

bool lod_is_plain(const Sampler& s, int levels) {
    return s.lod_bias == 0.0f && s.min_lod <= 0.0f && s.max_lod > 0.0f && levels > 1;
}

bool anisotropic_magnifies(double pmax2, const Sampler& s, int levels, double* log2_pmax) {
    if (plainly_magnifies(pmax2, s)) return true;
    if (!log2_pmax && lod_is_plain(s, levels) && pmax2 > kSurelyMinifying2) return false;
    const double log2_rho = log2_size(pmax2);
    if (log2_pmax) *log2_pmax = log2_rho;
    // Surely minifying (λ > 0 after snapping and clamping) without working λ out; else ask.
    const bool minifies = log2_rho + s.lod_bias > kLodSnap && s.max_lod > 0.0f && levels > 1;
    return !minifies && lod_from_log2_size(log2_rho, s, levels) <= 0.0;
}

namespace {

AnisoProbes aniso_probes(const Footprint& f, glm::vec2 dx, glm::vec2 dy, const Sampler& s, int levels) {
    AnisoProbes p;
    const double px2 = f.length2_x(), py2 = f.length2_y();
    if (!(px2 < kInf && py2 < kInf)) {  // some derivative not finite
        p.lambda = lod_from_log2_size(kInf, s, levels);
        p.magnifies = p.lambda <= 0.0;
        return p;
    }
    const double pmax2 = std::max(px2, py2);
    double log2_pmax = 0.0;
    if (anisotropic_magnifies(pmax2, s, levels, &log2_pmax)) {  // (also finds log2 Pmax: one log2 for both λs)
        p.magnifies = true;
        return p;
    }
    p.count = anisotropic_probe_count(px2, py2, s.max_anisotropy);
    p.lambda = lod_from_log2_size(p.count == 1 ? log2_pmax : log2_pmax - kLog2Count[p.count], s, levels);
    const glm::vec2 major = px2 >= py2 ? dx : dy;
    p.du = major.x;
    p.dv = major.y;
    return p;
}

}  // namespace

ProbeLine probe_line(const TextureLevel& level, const Sampler& s, double u, double v, double du, double dv, int count) {
    // Bilinear quads at x = u·w − ½ + o·du·w, stepping along the line. Repeat and mirror first
    // move the centre by whole periods (each probe would be moved alike); clamp and border do
    // not move it. When both end quads lie inside the level (so do all between: rounding is
    // monotonic), no probe wraps; otherwise the quads that reach outside wrap texel by texel.
    const auto periodic = [](WrapMode mode) { return mode == WrapMode::repeat || mode == WrapMode::mirror; };
    const double cx = periodic(s.wrap_u) ? reduce(u * level.width, level.width, s.wrap_u) : u * level.width;
    const double cy = periodic(s.wrap_v) ? reduce(v * level.height, level.height, s.wrap_v) : v * level.height;
    ProbeLine line;
    line.step = count >= 1 && count <= kMostProbes ? kInverseCount[static_cast<std::size_t>(count)] : 1.0 / count;
    line.sx = du * level.width, line.sy = dv * level.height;
    line.x0 = cx - 0.5 + (0.5 * line.step - 0.5) * line.sx, line.y0 = cy - 0.5 + (0.5 * line.step - 0.5) * line.sy;
    const double x1 = line.x0 + (count - 1) * line.step * line.sx, y1 = line.y0 + (count - 1) * line.step * line.sy;
    const double last_x = level.width - 1, last_y = level.height - 1;
    line.inside = std::min(line.x0, x1) >= 0.0 && std::max(line.x0, x1) < last_x && std::min(line.y0, y1) >= 0.0 &&
                  std::max(line.y0, y1) < last_y;
    line.near = std::min(line.x0, x1) > -kProbeReach && std::max(line.x0, x1) < kProbeReach &&
                std::min(line.y0, y1) > -kProbeReach && std::max(line.y0, y1) < kProbeReach;  // (false for NaN)
    return line;
}

namespace {

// Texel indices and fractions of probes k0 … k0 + n − 1 (n ≤ 16) on a line within ±kProbeReach
// texels: x = x0 + k·step·sx (likewise y), i = ⌊x⌋. Two probes per SSE2 vector: element by element
// the arithmetic of one probe at a time, so the bits are the same.
struct ProbePositions {
    std::int32_t i[16], j[16];
    float fx[16], fy[16];

    void fill(int k0, int n, double step, double x0, double sx, double y0, double sy) {
        typedef double Doubles __attribute__((vector_size(16)));
        typedef std::int32_t Ints __attribute__((vector_size(8)));
        typedef std::int64_t Masks __attribute__((vector_size(16)));
        typedef float Floats __attribute__((vector_size(8)));
        const auto axis = [&](Doubles t, double origin, double slope, std::int32_t* index, float* fraction, int c) {
            const Doubles x = origin + t * slope;
            const Ints truncated = __builtin_convertvector(x, Ints);
            const Masks below = x < __builtin_convertvector(truncated, Doubles);  // −1 where x < 0 is not whole
            const Ints whole = truncated + __builtin_convertvector(below, Ints);
            const Floats f = __builtin_convertvector(x - __builtin_convertvector(whole, Doubles), Floats);
            std::memcpy(index + c, &whole, sizeof whole);
            std::memcpy(fraction + c, &f, sizeof f);
        };
        for (int c = 0; c < n; c += 2) {  // (an odd n also places probe k0 + n, one step past the end: unread)
            const Doubles k = {double(k0 + c), double(k0 + c + 1)};
            const Doubles t = k * step;
            axis(t, x0, sx, i, fx, c);
            axis(t, y0, sy, j, fy, c);
        }
    }
};

// The mean of the p.count probes on one level, u + ((i + ½)/N − ½)·(du, dv) for i < N. Kept as the
// first probe plus the mean difference from it, so a constant texture gives back its value
// exactly. The filter is a template argument so that it inlines into the loops: they are most of
// an anisotropic lookup's time.
template <TexelFilter kFilter>
[[gnu::noinline]] Texel probe_mean(const AnisoProbes& p, double u, double v, const TextureLevel& level, const Sampler& s) {
    if constexpr (kFilter == TexelFilter::linear) {
        const ProbeLine line = probe_line(level, s, u, v, p.du, p.dv, p.count);
        if (line.near) {
            // Positions a chunk at a time, two probes per vector (the same double arithmetic as
            // one at a time), then the blends in probe order.
            constexpr int kChunk = 16;
            const unsigned quads_x = level.width - 1, quads_y = level.height - 1;  // quads with no wrapping
            ProbePositions at;
            const auto quad = [&](int c) {
                const int i = at.i[c], j = at.j[c];
                if (!line.inside && !(static_cast<unsigned>(i) < quads_x && static_cast<unsigned>(j) < quads_y))
                    return bilinear_wrapped(level, i, j, at.fx[c], at.fy[c], s);
                return inside_quad(level, i, j, at.fx[c], at.fy[c]);
            };
            Texel first = splat(0.0f), difference = splat(0.0f);
            for (int k0 = 0; k0 < p.count; k0 += kChunk) {
                const int n = std::min(kChunk, p.count - k0);
                at.fill(k0, n, line.step, line.x0, line.sx, line.y0, line.sy);
                int c = 0;
                if (k0 == 0) first = quad(c++);
                for (; c < n; ++c) difference += quad(c) - first;
            }
            return first + difference * splat(static_cast<float>(line.step));
        }
    }
    const double step = 1.0 / p.count;
    const auto probe = [&](int k) {
        const double o = (k + 0.5) * step - 0.5;
        const double pu = u + o * p.du, pv = v + o * p.dv;
        if constexpr (kFilter == TexelFilter::linear) return bilinear(level, pu, pv, s);
        else return nearest(level, pu, pv, s);
    };
    const Texel first = probe(0);
    Texel difference = splat(0.0f);
    for (int k = 1; k < p.count; ++k) difference += probe(k) - first;
    return first + difference * splat(static_cast<float>(step));
}

}  // namespace

Texel anisotropic_line(const TextureLevel& level, const Sampler& s, double u, double v, double du, double dv, int count) {
    AnisoProbes p;
    p.count = count;
    p.du = du;
    p.dv = dv;
    return probe_mean<TexelFilter::linear>(p, u, v, level, s);
}

glm::vec4 anisotropic_lines_lookup(const LineLanes& lanes, int i, const Sampler& s) {
    const auto line = [&](const TextureLevel& level) {
        return anisotropic_line(level, s, lanes.u[i], lanes.v[i], lanes.du[i], lanes.dv[i], lanes.count[i]);
    };
    const Texel finer = line(*lanes.finer[i]);
    return to_vec4(lanes.coarser[i] ? lerp(finer, line(*lanes.coarser[i]), lanes.weight[i]) : finer);
}

void anisotropic_lines(const LineLanes& lanes, const Sampler& s, glm::vec4* out) {
    for (int i = 0; i < lanes.n; ++i) out[lanes.out[i]] = anisotropic_lines_lookup(lanes, i, s);
}

namespace {

Texel anisotropic(const TextureView& t, double u, double v, const Footprint& f, glm::vec2 dx, glm::vec2 dy,
                  const Sampler& s) {
    const AnisoProbes p = aniso_probes(f, dx, dy, s, t.level_count());
    if (p.magnifies) return texel_filter(t.level(0), u, v, s.mag_filter, s);
    if (p.count == 1) return isotropic(t, u, v, p.lambda, s);
    const auto mean = [&](int k) {
        if (s.min_filter == TexelFilter::linear) return probe_mean<TexelFilter::linear>(p, u, v, t.level(k), s);
        return probe_mean<TexelFilter::nearest>(p, u, v, t.level(k), s);
    };
    // The levels and the blend weight are the same for every probe (what mip_filter would pick).
    if (p.lambda <= 0.0 || s.mip_filter == MipFilter::none) return mean(0);
    if (s.mip_filter == MipFilter::nearest) return mean(std::clamp(ceil_int(p.lambda + 0.5) - 1, 0, t.level_count() - 1));
    const int k = std::min(static_cast<int>(p.lambda), t.level_count() - 1);
    const Texel fine = mean(k);
    if (!(p.lambda > k) || k + 1 >= t.level_count()) return fine;
    return lerp(fine, mean(k + 1), static_cast<float>(p.lambda - k));
}

// exp(−α·q) for q = r² in [0, 1], tabulated (linear interpolation between entries).
struct GaussianTable {
    static constexpr int kSize = 256;
    std::array<double, kSize + 2> w;
    GaussianTable() {
        for (int i = 0; i <= kSize + 1; ++i) w[i] = std::exp(-kEwaAlpha * i / kSize);
    }
    double operator()(double q) const {
        const double x = q * kSize;
        const int i = static_cast<int>(x);
        return w[i] + (x - i) * (w[i + 1] - w[i]);
    }
};
const GaussianTable kGaussian;

// Heckbert's EWA: the pixel's footprint ellipse (covariance J·Jᵀ of the screen → texel map,
// the minor axis widened to 1/max_anisotropy of the major and to one texel of the chosen
// level), weighted by a Gaussian of the screen distance, summed over the texels inside.
[[gnu::noinline]] Texel ewa(const TextureView& t, double u, double v, const Footprint& f, const Sampler& s) {
    const int levels = t.level_count();
    if (isotropic_lod(f, s, levels) <= 0.0) return texel_filter(t.level(0), u, v, s.mag_filter, s);
    if (!f.finite()) return bilinear(t.level(levels - 1), u, v, s);
    const double scale = std::exp2(double(s.lod_bias));
    // Covariance of the footprint in level-0 texels and its eigen-decomposition.
    double sxx = (f.ux * f.ux + f.uy * f.uy) * scale * scale;
    double syy = (f.vx * f.vx + f.vy * f.vy) * scale * scale;
    double sxy = (f.ux * f.vx + f.uy * f.vy) * scale * scale;
    // Derivatives near the float range overflow the squares: as large as an infinite footprint.
    if (!std::isfinite(sxx + syy + sxy)) return bilinear(t.level(levels - 1), u, v, s);
    const double mean = 0.5 * (sxx + syy), diff = 0.5 * (sxx - syy);
    const double radius = std::hypot(diff, sxy);
    const double major2 = mean + radius;
    double minor2 = std::max(mean - radius, 0.0);
    // Eigenvector of the major axis (cos θ, sin θ).
    const double theta = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
    const double c = std::cos(theta), sn = std::sin(theta);
    const double max_aniso = s.max_anisotropy;
    minor2 = std::max(minor2, major2 / (max_aniso * max_aniso));
    // The finest level where the minor semi-axis spans kEwaMinAxisTexels.
    int k = 0;
    const double minor = std::sqrt(minor2);
    if (minor > kEwaMinAxisTexels) k = static_cast<int>(std::floor(std::log2(minor / kEwaMinAxisTexels) + kLodSnap));
    // min_lod and max_lod are any finite floats: clamp before the int conversion (UB beyond 2³¹).
    k = std::max(k, static_cast<int>(std::ceil(std::clamp(double(s.min_lod), 0.0, double(levels)))));
    k = std::min(k, static_cast<int>(std::floor(std::clamp(double(s.max_lod), 0.0, double(levels)))));
    k = std::clamp(k, 0, levels - 1);
    const TextureLevel& level = t.level(k);
    const double kx = double(level.width) / t.width(), ky = double(level.height) / t.height();
    // Axes at level k, each at least one texel: the reconstruction filter of Heckbert's formulation.
    const double a2 = std::max(major2 * std::min(kx, ky) * std::min(kx, ky), 1.0);
    const double b2 = std::max(minor2 * std::min(kx, ky) * std::min(kx, ky), 1.0);
    // Σ = R·diag(a², b²)·Rᵀ at level k; Q(d) = dᵀΣ⁻¹d is r² in pixels.
    sxx = a2 * c * c + b2 * sn * sn;
    syy = a2 * sn * sn + b2 * c * c;
    sxy = (a2 - b2) * c * sn;
    // A footprint much larger than level k (k clamped to the coarsest level or to max_lod) would
    // visit ~π·a·b texels, and past 2³¹ texels its row and column bounds do not fit an int: beyond
    // kMaxExtent texels per axis one bilinear lookup on level k stands in (on the 1×1 level with
    // repeat, mirror or clamp that is the exact weighted mean).
    constexpr double kMaxExtent = 128.0;
    if (!(sxx <= kMaxExtent * kMaxExtent && syy <= kMaxExtent * kMaxExtent)) return bilinear(level, u, v, s);
    const double det = sxx * syy - sxy * sxy;
    const double qa = syy / det, qb = -2.0 * sxy / det, qc = sxx / det;
    const double cx = centre(u * level.width, level.width, std::sqrt(sxx), s.wrap_u);
    const double cy = centre(v * level.height, level.height, std::sqrt(syy), s.wrap_v);
    const double ey = std::sqrt(syy);
    const int j0 = ceil_int(cy - ey - 0.5), j1 = floor_int(cy + ey - 0.5);
    // The sum is kept relative to the texel at the centre, so a constant texture gives back its
    // value exactly.
    const Texel origin = fetch(level, floor_int(cx), floor_int(cy), s);
    Texel sum = splat(0.0f);
    double weight = 0.0;
    for (int j = j0; j <= j1; ++j) {
        const double dy = j + 0.5 - cy;
        // Row span where Q ≤ 1: qa·dx² + qb·dy·dx + qc·dy² − 1 ≤ 0.
        const double b = qb * dy, cc = qc * dy * dy - 1.0;
        const double disc = b * b - 4.0 * qa * cc;
        if (disc < 0.0) continue;
        const double root = std::sqrt(disc);
        const double x_lo = cx + (-b - root) / (2.0 * qa), x_hi = cx + (-b + root) / (2.0 * qa);
        const int i0 = ceil_int(x_lo - 0.5), i1 = floor_int(x_hi - 0.5);
        // A row inside the texture is read directly; others texel by texel through the wrap modes.
        const bool inside = j >= 0 && j < level.height && i0 >= 0 && i1 < level.width;
        const glm::vec4* row = inside ? &level.at(0, j) : nullptr;
        for (int i = i0; i <= i1; ++i) {
            const double dx = i + 0.5 - cx;
            const double q = qa * dx * dx + qb * dx * dy + qc * dy * dy;
            if (q > 1.0) continue;
            const double w = kGaussian(std::max(q, 0.0));
            const Texel texel = inside ? load(row[i]) : fetch(level, i, j, s);
            sum += splat(static_cast<float>(w)) * (texel - origin);
            weight += w;
        }
    }
    if (!(weight > 0.0)) return bilinear(level, u, v, s);
    return origin + sum * splat(static_cast<float>(1.0 / weight));
}

// The notes' summed-area table: the exact mean over the bounding box of the pixel's footprint
// parallelogram (the texture taken piecewise constant), on the table's level.
[[gnu::noinline]] Texel summed_area(const TextureView& t, double u, double v, const Footprint& f, const Sampler& s) {
    const int levels = t.level_count();
    const double lambda = isotropic_lod(f, s, levels);
    if (lambda <= 0.0) return texel_filter(t.level(0), u, v, s.mag_filter, s);
    const double scale = std::exp2(double(s.lod_bias));
    const int k = t.summed_area_table_level();
    const TextureLevel& level = t.level(k);
    const double kx = double(level.width) / t.width(), ky = double(level.height) / t.height();
    // Half extents of the footprint's bounding box at level k, at least half a texel.
    const double hx = std::max(0.5, 0.5 * (std::abs(f.ux) + std::abs(f.uy)) * scale * kx);
    const double hy = std::max(0.5, 0.5 * (std::abs(f.vx) + std::abs(f.vy)) * scale * ky);
    // Beyond ~10⁷ texels the table's sums lose their meaning: the texture's mean (coarsest level).
    constexpr double kLargest = 1e7;
    if (!f.finite() || !(hx < kLargest && hy < kLargest)) return bilinear(t.level(levels - 1), u, v, s);
    const SummedAreaTable& table = t.summed_area_table();
    const double cx = centre(u * level.width, level.width, hx, s.wrap_u);
    const double cy = centre(v * level.height, level.height, hy, s.wrap_v);
    return load(glm::vec4(table.box_mean(cx - hx, cy - hy, cx + hx, cy + hy, s)));
}

}  // namespace

int most_probes(float max_anisotropy) {
    // max_anisotropy is any finite float ≥ 1: bound it before the int conversion (UB beyond 2³¹).
    return static_cast<int>(std::clamp(double(max_anisotropy), 1.0, double(kMostProbes)));
}

int anisotropic_probe_count(double px2, double py2, float max_anisotropy) {
    const double pmax2 = std::max(px2, py2), pmin2 = std::min(px2, py2);
    const int max_n = most_probes(max_anisotropy);
    // ⌈Pmax/Pmin⌉ from the squares; Pmin = 0 gives ∞ or NaN, both max_n.
    if (pmax2 == pmin2 && pmin2 > 0.0) return 1;  // isotropic: neither the division nor the root
    const double ratio2 = pmax2 / pmin2;
    return ratio2 < double(max_n) * max_n ? std::max(1, ceil_int(std::sqrt(ratio2))) : max_n;
}

double texture_lod(const TextureView& t, const Sampler& s, glm::vec2 dx, glm::vec2 dy) {
    const Footprint f = texel_footprint(t, dx, dy);
    if (s.footprint != FootprintFilter::anisotropic) return isotropic_lod(f, s, t.level_count());
    // Anisotropic minification reads its probes at log2(Pmax/N); magnification is the same for all.
    const AnisoProbes p = aniso_probes(f, dx, dy, s, t.level_count());
    return p.magnifies ? 0.0 : p.lambda;
}

// The heavier paths (mip_filter, probe_mean, ewa, summed_area) are out of line, so that this
// function keeps a small stack frame for the common lookups (measured: −20 to −40 instructions).
glm::vec4 sample_texture(const TextureView& t, const Sampler& s, glm::vec2 uv, glm::vec2 dx, glm::vec2 dy) {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return s.border_color;
    const double u = uv.x, v = uv.y;
    // One filter on level 0 whatever λ is: no need to compute it.
    if (!s.needs_derivatives()) return to_vec4(texel_filter(t.level(0), u, v, s.mag_filter, s));
    const Footprint f = texel_footprint(t, dx, dy);
    // Plain magnification reads level 0 with the magnification filter for every footprint filter
    // (what each of them decides on its own below): checked once here, it skips their setup.
    // Both lengths are tested, so a NaN in either is not taken for magnification.
    if (f.length2_y() <= 1.0 && plainly_magnifies(f.length2_x(), s))
        return to_vec4(texel_filter(t.level(0), u, v, s.mag_filter, s));
    switch (s.footprint) {
        case FootprintFilter::isotropic: return to_vec4(isotropic(t, u, v, isotropic_lod(f, s, t.level_count()), s));
        case FootprintFilter::anisotropic: return to_vec4(anisotropic(t, u, v, f, dx, dy, s));
        case FootprintFilter::ewa: return to_vec4(ewa(t, u, v, f, s));
        case FootprintFilter::sat: return to_vec4(summed_area(t, u, v, f, s));
    }
    return s.border_color;
}

}  // namespace mipraster
