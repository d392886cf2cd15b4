#pragma once
// Independent double-precision oracles for the texture tests, written from DESIGN.md §1 and the
// lecture notes (texture-mapping-and-supersampling, texture-filtering-mipmaps-sat-synthesis):
// wrap modes in integer arithmetic, nearest (i = ⌊u·w⌋), bilinear (i = ⌊u·w − ½⌋ and the notes'
// weights), λ = log2 ρ, trilinear, EXT_texture_filter_anisotropic probes, area-weighted
// downsampling with rational weights, and brute-force box integrals. Nothing here calls the
// sampling or level-generation code under test; the only library types used are plain data
// (TextureLevel, Sampler, WrapMode).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture_level.hpp"

namespace tex_oracle {

namespace mr = mipraster;

// ---- Texture construction ---------------------------------------------------------------------

/// A w×h level filled by f(i, j).
inline mr::TextureLevel make_level(int w, int h, const std::function<glm::vec4(int, int)>& f) {
    mr::TextureLevel level(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) level.at(i, j) = f(i, j);
    return level;
}

/// A w×h level of uniform random values in [0, 1) per channel (fixed seed).
inline mr::TextureLevel random_level(int w, int h, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> d(0.0f, 1.0f);
    return make_level(w, h, [&](int, int) { return glm::vec4(d(rng), d(rng), d(rng), d(rng)); });
}

// ---- Wrap modes, in integers ------------------------------------------------------------------

/// Texel index i of an n-texel axis after wrapping, or −1 for the border.
inline long long wrap(long long i, long long n, mr::WrapMode mode) {
    switch (mode) {
        case mr::WrapMode::repeat: {
            const long long r = i % n;
            return r < 0 ? r + n : r;
        }
        case mr::WrapMode::mirror: {  // copies alternate: 0..n−1, n−1..0, 0..n−1, …
            const long long p = 2 * n;
            long long r = i % p;
            if (r < 0) r += p;
            return r < n ? r : p - 1 - r;
        }
        case mr::WrapMode::clamp: return std::clamp(i, 0LL, n - 1);
        case mr::WrapMode::border: return i < 0 || i >= n ? -1 : i;
    }
    return -1;
}

/// Texel (i, j) of a level after wrapping, or the sampler's border colour.
inline glm::dvec4 fetch(const mr::TextureLevel& level, long long i, long long j, const mr::Sampler& s) {
    const long long x = wrap(i, level.width, s.wrap_u), y = wrap(j, level.height, s.wrap_v);
    if (x < 0 || y < 0) return glm::dvec4(s.border_color);
    return glm::dvec4(level.at(static_cast<int>(x), static_cast<int>(y)));
}

// ---- Texel filters (the notes' formulas) ------------------------------------------------------

/// Nearest: the texel whose cell holds the point, i = ⌊u·w⌋, j = ⌊v·h⌋. Needs |u·w| < 2^62.
inline glm::dvec4 nearest(const mr::TextureLevel& level, double u, double v, const mr::Sampler& s) {
    const long long i = static_cast<long long>(std::floor(u * level.width));
    const long long j = static_cast<long long>(std::floor(v * level.height));
    return fetch(level, i, j, s);
}

/// Bilinear as in the notes: i = ⌊U − ½⌋, s = U − (i + ½), c = (1−t)((1−s)f00 + s f10) + t((1−s)f01 + s f11).
inline glm::dvec4 bilinear(const mr::TextureLevel& level, double u, double v, const mr::Sampler& smp) {
    const double x = u * level.width, y = v * level.height;
    const double fi = std::floor(x - 0.5), fj = std::floor(y - 0.5);
    const long long i = static_cast<long long>(fi), j = static_cast<long long>(fj);
    const double s = x - (fi + 0.5), t = y - (fj + 0.5);
    const glm::dvec4 f00 = fetch(level, i, j, smp), f10 = fetch(level, i + 1, j, smp);
    const glm::dvec4 f01 = fetch(level, i, j + 1, smp), f11 = fetch(level, i + 1, j + 1, smp);
    return (1.0 - t) * ((1.0 - s) * f00 + s * f10) + t * ((1.0 - s) * f01 + s * f11);
}

inline glm::dvec4 texel(const mr::TextureLevel& level, double u, double v, mr::TexelFilter f, const mr::Sampler& s) {
    return f == mr::TexelFilter::nearest ? nearest(level, u, v, s) : bilinear(level, u, v, s);
}

// ---- Levels and LOD ---------------------------------------------------------------------------

/// Level count by the definition: level k is max(1, ⌊w/2^k⌋)×max(1, ⌊h/2^k⌋), down to 1×1.
inline int level_count(int w, int h) {
    int k = 0;
    while (std::max(1, w >> k) > 1 || std::max(1, h >> k) > 1) ++k;
    return k + 1;
}

/// λ from a footprint size ρ in texels: log2 ρ + bias, clamped to [min_lod, max_lod] and then to
/// [0, levels − 1]; a non-finite ρ counts as infinitely large (coarsest level, the documented choice).
inline double lod_from_rho(double rho, const mr::Sampler& s, int levels) {
    double lambda = std::isfinite(rho) ? (rho > 0.0 ? std::log2(rho) + s.lod_bias
                                                    : -std::numeric_limits<double>::infinity())
                                       : std::numeric_limits<double>::infinity();
    // The documented snap (sample.hpp): λ within 1e-6 of an integer is that integer.
    if (std::abs(lambda - std::round(lambda)) < 1e-6) lambda = std::round(lambda);
    lambda = std::min(std::max(lambda, double(s.min_lod)), double(s.max_lod));
    return std::min(std::max(lambda, 0.0), double(levels - 1));
}

/// Derivatives in level-0 texels.
struct Jacobian {
    double ux, vx, uy, vy;
    bool finite() const { return std::isfinite(ux) && std::isfinite(vx) && std::isfinite(uy) && std::isfinite(vy); }
    double px() const { return std::sqrt(ux * ux + vx * vx); }
    double py() const { return std::sqrt(uy * uy + vy * vy); }
};

inline Jacobian jacobian(int w, int h, glm::vec2 dx, glm::vec2 dy) {
    return {double(dx.x) * w, double(dx.y) * h, double(dy.x) * w, double(dy.y) * h};
}

/// DESIGN.md §1: ρ = max(‖∂uv/∂x‖, ‖∂uv/∂y‖) in texels, λ = log2 ρ.
inline double isotropic_lod(int w, int h, int levels, const mr::Sampler& s, glm::vec2 dx, glm::vec2 dy) {
    const Jacobian j = jacobian(w, h, dx, dy);
    if (!j.finite()) return lod_from_rho(std::numeric_limits<double>::infinity(), s, levels);
    return lod_from_rho(std::max(j.px(), j.py()), s, levels);
}

using LevelFn = std::function<const mr::TextureLevel&(int)>;

/// One mip lookup at λ: the magnification filter on level 0 for λ ≤ 0; else the min filter on
/// level 0 (mip none), on level ⌈λ + ½⌉ − 1 (mip nearest, GL), or lerp of levels ⌊λ⌋ and
/// ⌊λ⌋ + 1 by λ − ⌊λ⌋ (mip linear: the notes' trilinear).
inline glm::dvec4 mip_lookup(const LevelFn& level, int levels, double u, double v, double lambda,
                             const mr::Sampler& s) {
    if (lambda <= 0.0) return texel(level(0), u, v, s.mag_filter, s);
    switch (s.mip_filter) {
        case mr::MipFilter::none: return texel(level(0), u, v, s.min_filter, s);
        case mr::MipFilter::nearest: {
            const int k = std::clamp(int(std::ceil(lambda + 0.5)) - 1, 0, levels - 1);
            return texel(level(k), u, v, s.min_filter, s);
        }
        case mr::MipFilter::linear: {
            const int k = int(std::floor(lambda));
            const double f = lambda - k;
            const glm::dvec4 a = texel(level(k), u, v, s.min_filter, s);
            if (k + 1 >= levels) return a;
            const glm::dvec4 b = texel(level(k + 1), u, v, s.min_filter, s);
            return (1.0 - f) * a + f * b;
        }
    }
    return glm::dvec4(0.0);
}

/// EXT_texture_filter_anisotropic: Pmax, Pmin the derivative lengths in texels,
/// N = min(⌈Pmax/Pmin⌉, max_aniso) (max_aniso when Pmin = 0), λ = log2(Pmax/N).
struct AnisoPlan {
    int n = 1;
    double lambda = 0.0;
    double du = 0.0, dv = 0.0;  // major derivative in uv
};

inline AnisoPlan aniso_plan(int w, int h, int levels, const mr::Sampler& s, glm::vec2 dx, glm::vec2 dy) {
    AnisoPlan p;
    const Jacobian j = jacobian(w, h, dx, dy);
    if (!j.finite()) {
        p.lambda = lod_from_rho(std::numeric_limits<double>::infinity(), s, levels);
        return p;
    }
    const double pmax = std::max(j.px(), j.py()), pmin = std::min(j.px(), j.py());
    // N as a double first: max_anisotropy may be any float ≥ 1 (the oracle is only used where N
    // stays well inside int range).
    const double max_n = std::floor(double(s.max_anisotropy));
    const double n = pmin > 0.0 ? std::min(std::ceil(pmax / pmin), max_n) : max_n;
    p.n = int(std::clamp(n, 1.0, 1e9));
    p.lambda = lod_from_rho(pmax / p.n, s, levels);
    const glm::vec2 major = j.px() >= j.py() ? dx : dy;
    p.du = major.x;
    p.dv = major.y;
    return p;
}

/// The anisotropic lookup: the mean of N mip lookups at λ = log2(Pmax/N), spaced evenly over the
/// pixel along the major derivative at offsets (i + ½)/N − ½. Magnification (isotropic λ ≤ 0) is
/// one mag-filter lookup.
inline glm::dvec4 anisotropic(const LevelFn& level, int w, int h, int levels, double u, double v,
                              const mr::Sampler& s, glm::vec2 dx, glm::vec2 dy) {
    if (isotropic_lod(w, h, levels, s, dx, dy) <= 0.0) return texel(level(0), u, v, s.mag_filter, s);
    const AnisoPlan p = aniso_plan(w, h, levels, s, dx, dy);
    glm::dvec4 sum(0.0);
    for (int i = 0; i < p.n; ++i) {
        const double o = (i + 0.5) / p.n - 0.5;
        const double pu = u + o * p.du, pv = v + o * p.dv;
        sum += p.lambda <= 0.0 ? texel(level(0), pu, pv, s.min_filter, s) : mip_lookup(level, levels, pu, pv, p.lambda, s);
    }
    return sum / double(p.n);
}

// ---- Level generation -------------------------------------------------------------------------

/// Area-weighted downsampling with exact rational weights: output texel i of m covers
/// [i·n/m, (i+1)·n/m) of the n source texels; texel j's weight is its overlap, in units of
/// 1/m texel: min((j+1)m, (i+1)n) − max(jm, in), divided by n (the cell's area in those units).
inline std::vector<std::vector<std::pair<int, double>>> area_weights(int n, int m) {
    std::vector<std::vector<std::pair<int, double>>> taps(m);
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < n; ++j) {
            const long long lo = std::max<long long>(1LL * j * m, 1LL * i * n);
            const long long hi = std::min<long long>(1LL * (j + 1) * m, 1LL * (i + 1) * n);
            if (hi > lo) taps[i].push_back({j, double(hi - lo) / double(n)});
        }
    return taps;
}

/// A w×h image of doubles (RGBA), for oracle chains that never round to float.
struct DLevel {
    int width = 0, height = 0;
    std::vector<glm::dvec4> texels;
    glm::dvec4& at(int x, int y) { return texels[std::size_t(y) * width + x]; }
    const glm::dvec4& at(int x, int y) const { return texels[std::size_t(y) * width + x]; }
};

inline DLevel to_double(const mr::TextureLevel& l) {
    DLevel d{l.width, l.height, {}};
    for (const glm::vec4& t : l.texels) d.texels.push_back(glm::dvec4(t));
    return d;
}

inline DLevel downsample(const DLevel& src) {
    const int m = std::max(1, src.width / 2), mh = std::max(1, src.height / 2);
    const auto tx = area_weights(src.width, m), ty = area_weights(src.height, mh);
    DLevel out{m, mh, std::vector<glm::dvec4>(std::size_t(m) * mh, glm::dvec4(0.0))};
    for (int y = 0; y < mh; ++y)
        for (int x = 0; x < m; ++x)
            for (const auto& [sy, wy] : ty[y])
                for (const auto& [sx, wx] : tx[x]) out.at(x, y) += wx * wy * src.at(sx, sy);
    return out;
}

inline glm::dvec4 mean(const DLevel& l) {
    glm::dvec4 s(0.0);
    for (const glm::dvec4& t : l.texels) s += t;
    return s / double(l.texels.size());
}

// ---- Brute-force integrals ---------------------------------------------------------------------

/// Exact mean over the box [x0, x1]×[y0, y1] (level texel units) of the piecewise-constant
/// (nearest) texture with the sampler's wrap and border, by summing every covered cell's overlap.
inline glm::dvec4 box_mean_nearest(const mr::TextureLevel& level, double x0, double y0, double x1, double y1,
                                   const mr::Sampler& s) {
    glm::dvec4 sum(0.0);
    const long long i0 = (long long)std::floor(x0), i1 = (long long)std::floor(x1);
    const long long j0 = (long long)std::floor(y0), j1 = (long long)std::floor(y1);
    for (long long j = j0; j <= j1; ++j) {
        const double hy = std::min(double(j + 1), y1) - std::max(double(j), y0);
        if (hy <= 0.0) continue;
        for (long long i = i0; i <= i1; ++i) {
            const double hx = std::min(double(i + 1), x1) - std::max(double(i), x0);
            if (hx <= 0.0) continue;
            sum += hx * hy * fetch(level, i, j, s);
        }
    }
    return sum / ((x1 - x0) * (y1 - y0));
}

/// A single-channel, repeat-wrapped power-of-two image in double for the footprint references.
struct GreyImage {
    int size = 0;  // power of two
    std::vector<double> v;
    double at(long long i, long long j) const { return v[std::size_t((j & (size - 1)) * size + (i & (size - 1)))]; }
    /// Bilinear reconstruction (repeat) at texel coordinates (x, y) (texel centres at +½).
    double bilinear(double x, double y) const {
        const double fx = std::floor(x - 0.5), fy = std::floor(y - 0.5);
        const double s = x - (fx + 0.5), t = y - (fy + 0.5);
        const long long i = (long long)fx, j = (long long)fy;
        return (1.0 - t) * ((1.0 - s) * at(i, j) + s * at(i + 1, j)) + t * ((1.0 - s) * at(i, j + 1) + s * at(i + 1, j + 1));
    }
};

/// The box average over the pixel's footprint parallelogram c + s·Jx + t·Jy, s, t ∈ [−½, ½]
/// (texel units), of the bilinearly reconstructed image: midpoint rule on ns×nt samples.
inline double parallelogram_mean(const GreyImage& img, double cx, double cy, const Jacobian& j, int ns, int nt) {
    double sum = 0.0;
    for (int b = 0; b < nt; ++b) {
        const double t = (b + 0.5) / nt - 0.5;
        const double rx = cx + t * j.uy, ry = cy + t * j.vy;
        for (int a = 0; a < ns; ++a) {
            const double s = (a + 0.5) / ns - 0.5;
            sum += img.bilinear(rx + s * j.ux, ry + s * j.vx);
        }
    }
    return sum / (double(ns) * nt);
}

// ---- EWA (Heckbert), as documented in sample.hpp -------------------------------------------------

/// Elliptical weighted average on a square power-of-two texture: covariance Σ₀ = J·Jᵀ (level-0
/// texels, scaled by 2^bias), minor axis widened to major/max_aniso; level k = ⌊log2(minor
/// semi-axis / kEwaMinAxisTexels)⌋ (0 below one texel) clamped to the LOD clamps and the chain;
/// at level k both semi-axes at least one texel; weights exp(−α·Q), Q = dᵀΣ⁻¹d ≤ 1 over texel
/// centres d; the sum normalized by the weights. Magnification (isotropic λ ≤ 0): the mag filter.
inline glm::dvec4 ewa(const LevelFn& level, int size, int levels, double u, double v, const mr::Sampler& s,
                      glm::vec2 dx, glm::vec2 dy, double alpha, double min_axis) {
    if (isotropic_lod(size, size, levels, s, dx, dy) <= 0.0) return texel(level(0), u, v, s.mag_filter, s);
    const Jacobian j = jacobian(size, size, dx, dy);
    const double g = std::exp2(2.0 * s.lod_bias);
    const double a = (j.ux * j.ux + j.uy * j.uy) * g, b = (j.ux * j.vx + j.uy * j.vy) * g, c = (j.vx * j.vx + j.vy * j.vy) * g;
    // Eigenvalues of [[a, b], [b, c]] and the major eigenvector.
    const double tr = a + c, dt = std::sqrt((a - c) * (a - c) + 4.0 * b * b);
    const double l1 = 0.5 * (tr + dt);
    double l2 = std::max(0.5 * (tr - dt), 0.0);
    double ex = 1.0, ey = 0.0;
    if (b != 0.0 || a < c) {
        ex = b;
        ey = l1 - a;
        if (std::abs(ex) + std::abs(ey) < 1e-300 * l1) { ex = l1 - c; ey = b; }
        const double n = std::hypot(ex, ey);
        if (n > 0.0) { ex /= n; ey /= n; } else { ex = a >= c ? 1.0 : 0.0; ey = a >= c ? 0.0 : 1.0; }
    }
    l2 = std::max(l2, l1 / (double(s.max_anisotropy) * s.max_anisotropy));
    int k = std::sqrt(l2) > min_axis ? int(std::floor(std::log2(std::sqrt(l2) / min_axis) + 1e-6)) : 0;  // the snap
    k = std::max(k, int(std::ceil(std::clamp(double(s.min_lod), 0.0, double(levels)))));
    k = std::min(k, int(std::floor(std::clamp(double(s.max_lod), 0.0, double(levels)))));
    k = std::clamp(k, 0, levels - 1);
    const mr::TextureLevel& lv = level(k);
    const double scale2 = std::pow(double(lv.width) / size, 2.0);
    const double A = std::max(l1 * scale2, 1.0), B = std::max(l2 * scale2, 1.0);
    // Σ = R diag(A, B) Rᵀ with R's first column the major eigenvector; Σ⁻¹ = R diag(1/A, 1/B) Rᵀ.
    const double ixx = ex * ex / A + ey * ey / B, ixy = ex * ey * (1.0 / A - 1.0 / B), iyy = ey * ey / A + ex * ex / B;
    const double sxx = A * ex * ex + B * ey * ey, syy = A * ey * ey + B * ex * ex;
    const double cx = u * lv.width, cy = v * lv.height;
    const double rx = std::sqrt(sxx), ry = std::sqrt(syy);
    glm::dvec4 sum(0.0);
    double wsum = 0.0;
    for (long long jj = (long long)std::floor(cy - ry - 1.0); jj <= (long long)std::ceil(cy + ry + 1.0); ++jj)
        for (long long ii = (long long)std::floor(cx - rx - 1.0); ii <= (long long)std::ceil(cx + rx + 1.0); ++ii) {
            const double px = ii + 0.5 - cx, py = jj + 0.5 - cy;
            const double q = ixx * px * px + 2.0 * ixy * px * py + iyy * py * py;
            if (q > 1.0) continue;
            const double w = std::exp(-alpha * q);
            sum += w * fetch(lv, ii, jj, s);
            wsum += w;
        }
    if (!(wsum > 0.0)) return bilinear(lv, u, v, s);
    return sum / wsum;
}

// ---- Misc --------------------------------------------------------------------------------------

inline const char* wrap_name(mr::WrapMode m) {
    switch (m) {
        case mr::WrapMode::repeat: return "repeat";
        case mr::WrapMode::clamp: return "clamp";
        case mr::WrapMode::mirror: return "mirror";
        case mr::WrapMode::border: return "border";
    }
    return "?";
}

inline constexpr mr::WrapMode kAllWraps[4] = {mr::WrapMode::repeat, mr::WrapMode::clamp, mr::WrapMode::mirror,
                                              mr::WrapMode::border};

/// sRGB decode (IEC 61966-2-1) in double.
inline double srgb_to_linear(double e) {
    return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
}

}  // namespace tex_oracle
