#include "mipraster/texture/sample.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace mipraster {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// λ within this of an integer is taken as that integer (float derivatives carry ~1e-7 relative
// error; log2 turns that into ~1e-7 absolute).
constexpr double kLodSnap = 1e-6;

// A texel-space coordinate moved by whole periods (repeat, mirror) or clamped just past the
// edges (clamp, border), so that its floor and the indices next to it fit an int. No float
// reaches an int conversion before this (DESIGN.md §2.6).
[[gnu::noinline]] double reduce_outside(double x, int n, WrapMode mode) {
    switch (mode) {
        case WrapMode::repeat: return x - n * std::floor(x / n);
        case WrapMode::mirror: return x - 2.0 * n * std::floor(x / (2.0 * n));
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

glm::dvec4 fetch(const TextureLevel& level, int i, int j, const Sampler& s) {
    i = wrap_index(i, level.width, s.wrap_u);
    j = wrap_index(j, level.height, s.wrap_v);
    if (i < 0 || j < 0) return glm::dvec4(s.border_color);
    return glm::dvec4(level.at(i, j));
}

// The seeds' nearest rule: the texel whose cell holds the point, i = ⌊u·w⌋.
glm::dvec4 nearest(const TextureLevel& level, double u, double v, const Sampler& s) {
    const double x = reduce(u * level.width, level.width, s.wrap_u);
    const double y = reduce(v * level.height, level.height, s.wrap_v);
    return fetch(level, static_cast<int>(std::floor(x)), static_cast<int>(std::floor(y)), s);
}

// The bilinear blend of four texels a b / c d at fractions (ax, ay). Written as lerps so equal
// neighbours give back their value exactly.
inline glm::dvec4 lerp_quad(const glm::dvec4& a, const glm::dvec4& b, const glm::dvec4& c, const glm::dvec4& d,
                            double ax, double ay) {
    const glm::dvec4 top = a + ax * (b - a), bottom = c + ax * (d - c);
    return top + ay * (bottom - top);
}

// The quad at (i, j) when part of it lies outside the texture: each texel wrapped on its own.
// Out of line, so the in-range path below stays small enough to inline into the filter loops.
[[gnu::noinline]] glm::dvec4 bilinear_wrapped(const TextureLevel& level, int i, int j, double ax, double ay,
                                              const Sampler& s) {
    return lerp_quad(fetch(level, i, j, s), fetch(level, i + 1, j, s), fetch(level, i, j + 1, s),
                     fetch(level, i + 1, j + 1, s), ax, ay);
}

// Bilinear between the four nearest texel centres, i = ⌊u·w − ½⌋.
inline glm::dvec4 bilinear(const TextureLevel& level, double u, double v, const Sampler& s) {
    const double x = reduce(u * level.width, level.width, s.wrap_u) - 0.5;
    const double y = reduce(v * level.height, level.height, s.wrap_v) - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const int i = static_cast<int>(fx), j = static_cast<int>(fy);
    const double ax = x - fx, ay = y - fy;
    if (i < 0 || j < 0 || i + 1 >= level.width || j + 1 >= level.height) return bilinear_wrapped(level, i, j, ax, ay, s);
    const glm::vec4* row = &level.at(i, j);  // no wrapping: most lookups
    return lerp_quad(glm::dvec4(row[0]), glm::dvec4(row[1]), glm::dvec4(row[level.width]),
                     glm::dvec4(row[level.width + 1]), ax, ay);
}

glm::dvec4 texel_filter(const TextureLevel& level, double u, double v, TexelFilter filter, const Sampler& s) {
    return filter == TexelFilter::nearest ? nearest(level, u, v, s) : bilinear(level, u, v, s);
}

// The derivative vectors in texels of level 0.
struct Footprint {
    double ux, vx, uy, vy;  // ∂(u·w, v·h)/∂x and /∂y
    bool finite() const { return std::isfinite(ux) && std::isfinite(vx) && std::isfinite(uy) && std::isfinite(vy); }
    // Plain sqrt of the sum of squares (hypot is much slower): a length past ~1e154 overflows to
    // inf, which selects the coarsest level as the true length would.
    double length_x() const { return std::sqrt(ux * ux + vx * vx); }
    double length_y() const { return std::sqrt(uy * uy + vy * vy); }
};

Footprint texel_footprint(const TextureView& t, glm::vec2 dx, glm::vec2 dy) {
    return {double(dx.x) * t.width(), double(dx.y) * t.height(), double(dy.x) * t.width(), double(dy.y) * t.height()};
}

// λ from a footprint size ρ in texels: log2 ρ + bias, clamped; non-finite ρ → the coarsest level.
double lod_from_size(double rho, const Sampler& s, int levels) {
    double lambda = std::isfinite(rho) ? std::log2(rho) + s.lod_bias : kInf;  // log2(0) = −inf
    // Derivatives arrive as floats: a footprint of exactly 2^k texels comes out a few ulps short.
    // Snap such λ to the integer, so it reads one level, not two (the other at weight ~1e-8).
    if (std::abs(lambda - std::nearbyint(lambda)) < kLodSnap) lambda = std::nearbyint(lambda);
    lambda = std::clamp(lambda, double(s.min_lod), double(s.max_lod));
    return std::clamp(lambda, 0.0, double(levels - 1));  // [0, levels − 1] even for a negative min_lod
}

// Minification within the mip chain at λ > 0 with the sampler's min and mip filters.
glm::dvec4 mip_filter(const TextureView& t, double u, double v, double lambda, const Sampler& s) {
    switch (s.mip_filter) {
        case MipFilter::none: return texel_filter(t.level(0), u, v, s.min_filter, s);
        case MipFilter::nearest: {
            // GL's choice: level ⌈λ + ½⌉ − 1, so λ ≤ ½ stays on level 0.
            const int k = std::clamp(static_cast<int>(std::ceil(lambda + 0.5)) - 1, 0, t.level_count() - 1);
            return texel_filter(t.level(k), u, v, s.min_filter, s);
        }
        case MipFilter::linear: {
            const int k = std::min(static_cast<int>(lambda), t.level_count() - 1);
            const double f = lambda - k;
            const glm::dvec4 a = texel_filter(t.level(k), u, v, s.min_filter, s);
            if (f <= 0.0 || k + 1 >= t.level_count()) return a;
            return a + f * (texel_filter(t.level(k + 1), u, v, s.min_filter, s) - a);
        }
    }
    return glm::dvec4(0.0);
}

// Isotropic: one mip lookup at λ, or the magnification filter when λ ≤ 0.
glm::dvec4 isotropic(const TextureView& t, double u, double v, double lambda, const Sampler& s) {
    if (lambda <= 0.0) return texel_filter(t.level(0), u, v, s.mag_filter, s);
    return mip_filter(t, u, v, lambda, s);
}

double isotropic_lod(const Footprint& f, const Sampler& s, int levels) {
    if (!f.finite()) return lod_from_size(kInf, s, levels);
    return lod_from_size(std::max(f.length_x(), f.length_y()), s, levels);
}

// EXT_texture_filter_anisotropic: N = min(⌈Pmax/Pmin⌉, max anisotropy) probes spaced evenly
// along the major derivative over the pixel, each a mip lookup at λ = log2(Pmax/N).
struct AnisoProbes {
    int count = 1;
    double lambda = 0.0;
    double du = 0.0, dv = 0.0;  // the major derivative in uv
};

AnisoProbes aniso_probes(const Footprint& f, glm::vec2 dx, glm::vec2 dy, const Sampler& s, int levels) {
    AnisoProbes p;
    if (!f.finite()) {
        p.lambda = lod_from_size(kInf, s, levels);
        return p;
    }
    const double px = f.length_x(), py = f.length_y();
    const double pmax = std::max(px, py), pmin = std::min(px, py);
    // max_anisotropy is any finite float ≥ 1: bound it before the int conversion (UB beyond 2³¹).
    constexpr double kMostProbes = 1024.0;
    const int max_n = static_cast<int>(std::clamp(double(s.max_anisotropy), 1.0, kMostProbes));
    const double ratio = pmin > 0.0 ? std::ceil(pmax / pmin) : kInf;
    p.count = ratio < max_n ? std::max(1, static_cast<int>(ratio)) : max_n;
    p.lambda = lod_from_size(pmax / p.count, s, levels);
    const glm::vec2 major = px >= py ? dx : dy;
    p.du = major.x;
    p.dv = major.y;
    return p;
}

// The mean of p.count probes along the major axis, each a lookup on `fine`, blended towards
// `coarse` (when set) by `blend`. The filter is a template argument so that bilinear inlines
// into the loop: this loop is most of an anisotropic lookup's time.
template <TexelFilter kFilter>
glm::dvec4 anisotropic_probes(const AnisoProbes& p, double u, double v, const TextureLevel* fine,
                              const TextureLevel* coarse, double blend, const Sampler& s) {
    const auto filter = [&s](const TextureLevel& level, double pu, double pv) {
        return kFilter == TexelFilter::linear ? bilinear(level, pu, pv, s) : nearest(level, pu, pv, s);
    };
    glm::dvec4 sum(0.0);
    for (int i = 0; i < p.count; ++i) {
        const double o = (i + 0.5) / p.count - 0.5;
        const double pu = u + o * p.du, pv = v + o * p.dv;
        glm::dvec4 probe = filter(*fine, pu, pv);
        if (coarse) probe += blend * (filter(*coarse, pu, pv) - probe);
        sum += probe;
    }
    return sum / double(p.count);
}

glm::dvec4 anisotropic(const TextureView& t, double u, double v, const Footprint& f, glm::vec2 dx, glm::vec2 dy,
                       const Sampler& s) {
    if (isotropic_lod(f, s, t.level_count()) <= 0.0) return texel_filter(t.level(0), u, v, s.mag_filter, s);
    const AnisoProbes p = aniso_probes(f, dx, dy, s, t.level_count());
    if (p.count == 1) return isotropic(t, u, v, p.lambda, s);
    // The levels and the blend weight are the same for every probe (what mip_filter would pick).
    const TextureLevel* fine = &t.level(0);
    const TextureLevel* coarse = nullptr;
    double blend = 0.0;
    if (p.lambda > 0.0 && s.mip_filter == MipFilter::nearest) {
        fine = &t.level(std::clamp(static_cast<int>(std::ceil(p.lambda + 0.5)) - 1, 0, t.level_count() - 1));
    } else if (p.lambda > 0.0 && s.mip_filter == MipFilter::linear) {
        const int k = std::min(static_cast<int>(p.lambda), t.level_count() - 1);
        fine = &t.level(k);
        blend = p.lambda - k;
        if (blend > 0.0 && k + 1 < t.level_count()) coarse = &t.level(k + 1);
    }
    if (s.min_filter == TexelFilter::linear) return anisotropic_probes<TexelFilter::linear>(p, u, v, fine, coarse, blend, s);
    return anisotropic_probes<TexelFilter::nearest>(p, u, v, fine, coarse, blend, s);
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
glm::dvec4 ewa(const TextureView& t, double u, double v, const Footprint& f, const Sampler& s) {
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
    const int j0 = static_cast<int>(std::ceil(cy - ey - 0.5)), j1 = static_cast<int>(std::floor(cy + ey - 0.5));
    glm::dvec4 sum(0.0);
    double weight = 0.0;
    for (int j = j0; j <= j1; ++j) {
        const double dy = j + 0.5 - cy;
        // Row span where Q ≤ 1: qa·dx² + qb·dy·dx + qc·dy² − 1 ≤ 0.
        const double b = qb * dy, cc = qc * dy * dy - 1.0;
        const double disc = b * b - 4.0 * qa * cc;
        if (disc < 0.0) continue;
        const double root = std::sqrt(disc);
        const double x_lo = cx + (-b - root) / (2.0 * qa), x_hi = cx + (-b + root) / (2.0 * qa);
        const int i0 = static_cast<int>(std::ceil(x_lo - 0.5)), i1 = static_cast<int>(std::floor(x_hi - 0.5));
        for (int i = i0; i <= i1; ++i) {
            const double dx = i + 0.5 - cx;
            const double q = qa * dx * dx + qb * dx * dy + qc * dy * dy;
            if (q > 1.0) continue;
            const double w = kGaussian(std::max(q, 0.0));
            sum += w * fetch(level, i, j, s);
            weight += w;
        }
    }
    if (!(weight > 0.0)) return bilinear(level, u, v, s);
    return sum / weight;
}

// The notes' summed-area table: the exact mean over the bounding box of the pixel's footprint
// parallelogram (the texture taken piecewise constant), on the table's level.
glm::dvec4 summed_area(const TextureView& t, double u, double v, const Footprint& f, const Sampler& s) {
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
    return table.box_mean(cx - hx, cy - hy, cx + hx, cy + hy, s);
}

}  // namespace

double texture_lod(const TextureView& t, const Sampler& s, glm::vec2 dx, glm::vec2 dy) {
    const Footprint f = texel_footprint(t, dx, dy);
    const double lambda = isotropic_lod(f, s, t.level_count());
    // Anisotropic minification reads its probes at log2(Pmax/N); magnification is the same for all.
    if (s.footprint == FootprintFilter::anisotropic && lambda > 0.0)
        return aniso_probes(f, dx, dy, s, t.level_count()).lambda;
    return lambda;
}

glm::vec4 sample_texture(const TextureView& t, const Sampler& s, glm::vec2 uv, glm::vec2 dx, glm::vec2 dy) {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return s.border_color;
    const double u = uv.x, v = uv.y;
    // One filter on level 0 whatever λ is: no need to compute it.
    if (!s.needs_derivatives()) return glm::vec4(texel_filter(t.level(0), u, v, s.mag_filter, s));
    const Footprint f = texel_footprint(t, dx, dy);
    switch (s.footprint) {
        case FootprintFilter::isotropic: return glm::vec4(isotropic(t, u, v, isotropic_lod(f, s, t.level_count()), s));
        case FootprintFilter::anisotropic: return glm::vec4(anisotropic(t, u, v, f, dx, dy, s));
        case FootprintFilter::ewa: return glm::vec4(ewa(t, u, v, f, s));
        case FootprintFilter::sat: return glm::vec4(summed_area(t, u, v, f, s));
    }
    return s.border_color;
}

}  // namespace mipraster
