#pragma once
// Test oracles for mipraster, written from the definitions in DESIGN.md and not from the library
// code: exact top-left coverage on snapped 1/256 px coordinates (__int128 cross products), and a
// double-precision ray caster (own 4×4 inverse, Möller–Trumbore) for depth, barycentrics and the
// visible part of a triangle.
#include <algorithm>
#include <array>
#include <cfenv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace oracle {

using i128 = __int128;

/// One pixel in fixed point (DESIGN.md §2.1: 16.8 fixed point).
inline constexpr std::int64_t kOne = 256;

// ---------------------------------------------------------------------------------------------
// Snapping and exact coverage
// ---------------------------------------------------------------------------------------------

/// A point in 1/256 px units, screen space (x right, y down).
struct Fixed2 {
    std::int64_t x = 0, y = 0;
    bool operator==(const Fixed2& o) const { return x == o.x && y == o.y; }
};

/// Round half to even of a value already in 1/256 px units.
inline std::int64_t snap(double units) {
    if (std::fegetround() != FE_TONEAREST) throw std::logic_error("oracle::snap needs FE_TONEAREST");
    return static_cast<std::int64_t>(std::nearbyint(units));
}

/// Screen position in pixels of an NDC point (DESIGN.md §1: x_s = (x+1)·W/2, y_s = (1−y)·H/2).
inline double ndc_to_screen_x(double x_ndc, int width) { return (x_ndc + 1.0) * (0.5 * width); }
inline double ndc_to_screen_y(double y_ndc, int height) { return (1.0 - y_ndc) * (0.5 * height); }

/// Snapped screen position of an NDC point.
inline Fixed2 snap_ndc(double x_ndc, double y_ndc, int width, int height) {
    return {snap(ndc_to_screen_x(x_ndc, width) * 256.0), snap(ndc_to_screen_y(y_ndc, height) * 256.0)};
}

/// ⌊a / b⌋ for b > 0 and any sign of a.
inline std::int64_t floor_div(std::int64_t a, std::int64_t b) {
    std::int64_t q = a / b;
    if ((a % b != 0) && (a < 0)) --q;
    return q;
}

/// (b − a) × (p − a): twice the signed area of the triangle (a, b, p) in a y-down frame.
inline i128 cross(const Fixed2& a, const Fixed2& b, std::int64_t px, std::int64_t py) {
    return static_cast<i128>(b.x - a.x) * static_cast<i128>(py - a.y) -
           static_cast<i128>(b.y - a.y) * static_cast<i128>(px - a.x);
}

/// Top-left rule (Direct3D), y down, independent of winding. For the edge a–b of a triangle
/// whose third vertex is c:
///   top edge  = horizontal, with the interior (c) below it (larger y);
///   left edge = not horizontal, with the interior to its right: c lies at larger x than the
///               point of the edge's line at c's height.
inline bool is_top_or_left(const Fixed2& a, const Fixed2& b, const Fixed2& c) {
    if (a.y == b.y) return c.y > a.y;
    // Line x at height c.y: x_e = a.x + (c.y − a.y)(b.x − a.x)/(b.y − a.y). c.x > x_e, times
    // (b.y − a.y), which flips the comparison when that is negative.
    const i128 lhs = static_cast<i128>(c.x - a.x) * static_cast<i128>(b.y - a.y);
    const i128 rhs = static_cast<i128>(c.y - a.y) * static_cast<i128>(b.x - a.x);
    return b.y > a.y ? lhs > rhs : lhs < rhs;
}

/// Whether the sample (sx, sy) (1/256 px units) is inside the snapped triangle v: strictly on the
/// interior side of every edge, or exactly on an edge only if that edge is top or left. A
/// zero-area triangle covers nothing.
inline bool covers(const std::array<Fixed2, 3>& v, std::int64_t sx, std::int64_t sy) {
    const i128 area = cross(v[0], v[1], v[2].x, v[2].y);
    if (area == 0) return false;
    for (int i = 0; i < 3; ++i) {
        const Fixed2& a = v[i];
        const Fixed2& b = v[(i + 1) % 3];
        const Fixed2& c = v[(i + 2) % 3];
        i128 e = cross(a, b, sx, sy);
        if (area < 0) e = -e;  // positive on the interior side whatever the winding
        if (e < 0) return false;
        if (e == 0 && !is_top_or_left(a, b, c)) return false;
    }
    return true;
}

inline bool is_degenerate(const std::array<Fixed2, 3>& v) { return cross(v[0], v[1], v[2].x, v[2].y) == 0; }

/// Sample offsets inside a pixel, 1/256 px from the top-left corner.
struct Pattern {
    std::vector<int> x, y;
    int count() const { return static_cast<int>(x.size()); }
};

/// The documented patterns (DESIGN.md §1), independent of make_sample_pattern.
inline Pattern center_pattern() { return Pattern{{128}, {128}}; }
inline Pattern rotated_pattern() { return Pattern{{96, 224, 32, 160}, {32, 96, 160, 224}}; }
/// N×N grid at ((a+½)/N, (b+½)/N) for N dividing 128 (exact on the 1/256 grid).
inline Pattern grid_pattern(int n) {
    Pattern p;
    for (int b = 0; b < n; ++b)
        for (int a = 0; a < n; ++a) {
            p.x.push_back((2 * a + 1) * 128 / n);
            p.y.push_back((2 * b + 1) * 128 / n);
        }
    return p;
}

/// Sample s of pixel (px, py) in 1/256 px units.
inline Fixed2 sample_position(int px, int py, const Pattern& p, int s) {
    return {std::int64_t{px} * kOne + p.x[s], std::int64_t{py} * kOne + p.y[s]};
}

/// Adds 1 to counts[(y·W + x)·S + s] for every sample the triangle covers.
inline void accumulate_coverage(const std::array<Fixed2, 3>& v, int width, int height, const Pattern& pattern,
                                std::vector<int>& counts) {
    if (is_degenerate(v)) return;
    const std::int64_t min_x = std::min({v[0].x, v[1].x, v[2].x}), max_x = std::max({v[0].x, v[1].x, v[2].x});
    const std::int64_t min_y = std::min({v[0].y, v[1].y, v[2].y}), max_y = std::max({v[0].y, v[1].y, v[2].y});
    const std::int64_t px0 = std::max<std::int64_t>(0, floor_div(min_x, kOne));
    const std::int64_t px1 = std::min<std::int64_t>(width - 1, floor_div(max_x, kOne));
    const std::int64_t py0 = std::max<std::int64_t>(0, floor_div(min_y, kOne));
    const std::int64_t py1 = std::min<std::int64_t>(height - 1, floor_div(max_y, kOne));
    const int S = pattern.count();
    for (std::int64_t py = py0; py <= py1; ++py)
        for (std::int64_t px = px0; px <= px1; ++px)
            for (int s = 0; s < S; ++s) {
                const Fixed2 q = sample_position(static_cast<int>(px), static_cast<int>(py), pattern, s);
                if (covers(v, q.x, q.y)) ++counts[(static_cast<std::size_t>(py) * width + px) * S + s];
            }
}

// ---------------------------------------------------------------------------------------------
// Exact (unsnapped) screen-space geometry in double
// ---------------------------------------------------------------------------------------------

/// Distance from p to the segment a–b (pixels).
inline double distance_to_segment(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a, ap = p - a;
    const double len2 = ab.x * ab.x + ab.y * ab.y;
    double t = len2 > 0.0 ? (ap.x * ab.x + ap.y * ab.y) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const glm::dvec2 d = ap - t * ab;
    return std::sqrt(d.x * d.x + d.y * d.y);
}

/// Signed distance of p from the line a→b, positive on the left in a y-down frame (the side
/// where cross((b−a),(p−a)) > 0).
inline double signed_line_distance(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double c = ab.x * (p.y - a.y) - ab.y * (p.x - a.x);
    return c / std::sqrt(ab.x * ab.x + ab.y * ab.y);
}

/// Largest distance a snapped edge can be from the exact one: each vertex moves at most half a
/// 1/256 step in x and in y, so any point of an edge moves at most √2/512 px.
inline constexpr double kSnapBandPx = 1.4142135623730951 / 512.0;

// ---------------------------------------------------------------------------------------------
// Double-precision 4×4 matrices (row-major, own code) and the ray caster
// ---------------------------------------------------------------------------------------------

struct Mat4 {
    double m[4][4] = {};  // m[row][col]
};

inline Mat4 from_glm(const glm::dmat4& g) {
    Mat4 r;
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) r.m[row][col] = g[col][row];
    return r;
}

inline Mat4 mul(const Mat4& a, const Mat4& b) {
    Mat4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0.0;
            for (int k = 0; k < 4; ++k) s += a.m[i][k] * b.m[k][j];
            r.m[i][j] = s;
        }
    return r;
}

inline std::array<double, 4> apply(const Mat4& a, const std::array<double, 4>& v) {
    std::array<double, 4> r{};
    for (int i = 0; i < 4; ++i) r[i] = a.m[i][0] * v[0] + a.m[i][1] * v[1] + a.m[i][2] * v[2] + a.m[i][3] * v[3];
    return r;
}

/// Gauss–Jordan elimination with partial pivoting (long double internally).
inline Mat4 inverse(const Mat4& a) {
    long double aug[4][8];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 8; ++j) aug[i][j] = j < 4 ? a.m[i][j] : (j - 4 == i ? 1.0L : 0.0L);
    for (int col = 0; col < 4; ++col) {
        int pivot = col;
        for (int r = col + 1; r < 4; ++r)
            if (std::fabs(aug[r][col]) > std::fabs(aug[pivot][col])) pivot = r;
        if (aug[pivot][col] == 0.0L) throw std::runtime_error("oracle::inverse: singular matrix");
        for (int j = 0; j < 8; ++j) std::swap(aug[col][j], aug[pivot][j]);
        const long double inv = 1.0L / aug[col][col];
        for (int j = 0; j < 8; ++j) aug[col][j] *= inv;
        for (int r = 0; r < 4; ++r) {
            if (r == col) continue;
            const long double f = aug[r][col];
            for (int j = 0; j < 8; ++j) aug[r][j] -= f * aug[col][j];
        }
    }
    Mat4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = static_cast<double>(aug[i][4 + j]);
    return r;
}

struct Ray {
    glm::dvec3 origin, direction;
};

struct Hit {
    bool hit = false;
    glm::dvec3 bary{0.0};  ///< barycentric weights of v0, v1, v2
    glm::dvec3 point{0.0};
    double view_distance = 0.0;  ///< −z of the hit in view space
};

/// A perspective camera given by its world→view and view→clip matrices. Rays go through screen
/// points (pixels, y down) of a W×H viewport.
class RayCaster {
public:
    RayCaster(const glm::dmat4& view, const glm::dmat4& projection, bool reverse_z, int width, int height)
        : view_(from_glm(view)), proj_(from_glm(projection)), reverse_z_(reverse_z), width_(width), height_(height) {
        view_proj_ = mul(proj_, view_);
        inv_view_proj_ = inverse(view_proj_);
    }

    /// World point on the ray through the screen point with NDC depth z_ndc.
    glm::dvec3 unproject(double sx, double sy, double z_ndc) const {
        const double x = 2.0 * sx / width_ - 1.0, y = 1.0 - 2.0 * sy / height_;
        const auto p = apply(inv_view_proj_, {x, y, z_ndc, 1.0});
        return {p[0] / p[3], p[1] / p[3], p[2] / p[3]};
    }

    /// The line of sight through the screen point (pixels), from the near plane away from the eye.
    Ray ray(double sx, double sy) const {
        const double z_near = reverse_z_ ? 1.0 : -1.0, z_mid = reverse_z_ ? 0.5 : 0.0;
        const glm::dvec3 a = unproject(sx, sy, z_near), b = unproject(sx, sy, z_mid);
        return {a, b - a};
    }

    /// −z in view space.
    double view_distance(const glm::dvec3& world) const {
        return -apply(view_, {world.x, world.y, world.z, 1.0})[2];
    }

    /// Screen position (pixels) and clip w of a world point.
    glm::dvec3 project(const glm::dvec3& world) const {
        const auto c = apply(view_proj_, {world.x, world.y, world.z, 1.0});
        return {(c[0] / c[3] + 1.0) * 0.5 * width_, (1.0 - c[1] / c[3]) * 0.5 * height_, c[3]};
    }

    /// Window depth: z_ndc for reverse-Z, z_ndc/2 + ½ for OpenGL.
    double window_depth(const glm::dvec3& world) const {
        const auto c = apply(view_proj_, {world.x, world.y, world.z, 1.0});
        const double z = c[2] / c[3];
        return reverse_z_ ? z : 0.5 * z + 0.5;
    }

    /// Möller–Trumbore against the whole line (any ray parameter): the caller decides which
    /// view distances count.
    Hit intersect(const Ray& r, const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& v2) const {
        Hit h;
        const glm::dvec3 e1 = v1 - v0, e2 = v2 - v0;
        const glm::dvec3 p = cross3(r.direction, e2);
        const double det = dot3(e1, p);
        if (det == 0.0 || !std::isfinite(det)) return h;
        const double inv = 1.0 / det;
        const glm::dvec3 s = r.origin - v0;
        const double u = dot3(s, p) * inv;
        const glm::dvec3 q = cross3(s, e1);
        const double v = dot3(r.direction, q) * inv;
        const double t = dot3(e2, q) * inv;
        h.bary = {1.0 - u - v, u, v};
        h.point = r.origin + t * r.direction;
        h.view_distance = view_distance(h.point);
        h.hit = u >= 0.0 && v >= 0.0 && u + v <= 1.0;
        return h;
    }

    int width() const { return width_; }
    int height() const { return height_; }

    static glm::dvec3 cross3(const glm::dvec3& a, const glm::dvec3& b) {
        return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    }
    static double dot3(const glm::dvec3& a, const glm::dvec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

private:
    Mat4 view_, proj_, view_proj_, inv_view_proj_;
    bool reverse_z_;
    int width_, height_;
};

/// The part of a convex world polygon with view distance in [near, far], projected to the screen
/// (pixels): Sutherland–Hodgman against the two planes in view space, then the perspective divide.
inline std::vector<glm::dvec2> visible_polygon(const RayCaster& rc, const std::vector<glm::dvec3>& poly, double near,
                                               double far = std::numeric_limits<double>::infinity()) {
    std::vector<glm::dvec3> cur = poly;
    for (int plane = 0; plane < 2; ++plane) {
        if (plane == 1 && !std::isfinite(far)) break;
        std::vector<glm::dvec3> out;
        for (std::size_t i = 0; i < cur.size(); ++i) {
            const glm::dvec3& a = cur[i];
            const glm::dvec3& b = cur[(i + 1) % cur.size()];
            const double da = plane == 0 ? rc.view_distance(a) - near : far - rc.view_distance(a);
            const double db = plane == 0 ? rc.view_distance(b) - near : far - rc.view_distance(b);
            if (da >= 0.0) out.push_back(a);
            if ((da >= 0.0) != (db >= 0.0)) out.push_back(a + (da / (da - db)) * (b - a));
        }
        cur = std::move(out);
    }
    std::vector<glm::dvec2> screen;
    for (const auto& p : cur) {
        const glm::dvec3 s = rc.project(p);
        screen.push_back({s.x, s.y});
    }
    return screen;
}

inline std::vector<glm::dvec2> visible_polygon(const RayCaster& rc, const std::array<glm::dvec3, 3>& tri, double near,
                                               double far = std::numeric_limits<double>::infinity()) {
    return visible_polygon(rc, std::vector<glm::dvec3>(tri.begin(), tri.end()), near, far);
}

/// Snapped screen position of an object-space point through `mvp` (= projection·view·model), for
/// a point in front of the camera (w > 0), no clipping.
inline Fixed2 project_and_snap(const Mat4& mvp, const glm::dvec3& p, int width, int height) {
    const auto c = apply(mvp, {p.x, p.y, p.z, 1.0});
    if (!(c[3] > 0.0)) throw std::logic_error("oracle::project_and_snap: point not in front of the camera");
    return snap_ndc(c[0] / c[3], c[1] / c[3], width, height);
}

inline Mat4 model_view_projection(const glm::dmat4& projection, const glm::dmat4& view, const glm::dmat4& model) {
    return mul(mul(from_glm(projection), from_glm(view)), from_glm(model));
}

/// Smallest distance from p to the boundary of a polygon (pixels).
inline double distance_to_boundary(const glm::dvec2& p, const std::vector<glm::dvec2>& poly) {
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < poly.size(); ++i) d = std::min(d, distance_to_segment(p, poly[i], poly[(i + 1) % poly.size()]));
    return d;
}

}  // namespace oracle
