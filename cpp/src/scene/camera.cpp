#include "mipraster/scene/camera.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include <glm/geometric.hpp>

namespace mipraster {

namespace {

void require(bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument(message);
}

// A number for messages, as %.9g (std::to_string printed 1e-45 as 0.000000).
std::string number(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.9g", v);
    return buffer;
}

// Depth rows (third row of the projection, as z_clip = a·z + b·w_view) for each convention.
// Perspective: w_clip = −z, so z_ndc = (a·z + b)/(−z).
void set_perspective_depth(glm::dmat4& m, double n, double f, DepthConvention c) {
    // glm is column-major: m[col][row].
    if (c == DepthConvention::opengl) {
        require(std::isfinite(f), "frustum: far must be finite for DepthConvention::opengl");
        m[2][2] = -(f + n) / (f - n);
        m[3][2] = -2.0 * f * n / (f - n);
    } else if (std::isinf(f)) {
        m[2][2] = 0.0;  // z_ndc = n / (−z): near → 1, infinity → 0
        m[3][2] = n;
    } else {
        m[2][2] = n / (f - n);  // near → 1, far → 0
        m[3][2] = f * n / (f - n);
    }
    m[2][3] = -1.0;
    m[3][3] = 0.0;
}

}  // namespace

std::string to_string(DepthConvention c) { return c == DepthConvention::opengl ? "opengl" : "reverse_z"; }

glm::dmat4 look_at(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up) {
    const glm::dvec3 w = target - eye;
    // (Finite inputs can still overflow here: the cross product then held NaN, which read as
    // "up is parallel".)
    require(std::isfinite(glm::length(w)), "look_at: eye and target are too far apart (target - eye overflows)");
    require(glm::length(w) > 0.0, "look_at: eye and target coincide");
    const glm::dvec3 u = glm::cross(w, up);  // the seeds: u = w × y
    require(std::isfinite(glm::length(u)),
            "look_at: up and the view direction are too large (their cross product overflows)");
    require(glm::length(u) > 0.0, "look_at: up is parallel to the view direction");
    const glm::dvec3 v = glm::cross(u, w);
    const glm::dvec3 un = glm::normalize(u), vn = glm::normalize(v), wn = glm::normalize(w);
    glm::dmat4 r(1.0);
    for (int i = 0; i < 3; ++i) {  // rows u, v, −w
        r[i][0] = un[i];
        r[i][1] = vn[i];
        r[i][2] = -wn[i];
    }
    r[3] = glm::dvec4(-glm::dot(un, eye), -glm::dot(vn, eye), glm::dot(wn, eye), 1.0);
    return r;
}

glm::dmat4 frustum(double l, double r, double b, double t, double n, double f, DepthConvention c) {
    require(std::isfinite(n) && n > 0.0, "frustum: near must be finite and > 0, got " + number(n));
    require(n >= kMinPerspectiveNear,
            "near = " + number(n) + " is too small: expected a near plane >= " + number(kMinPerspectiveNear) +
                " (float32's smallest normal number: the depth buffer holds near / distance in float32, which "
                "below it loses precision and rounds to 0, the clear depth, so nothing would be drawn)");
    require(std::isfinite(l) && std::isfinite(r) && std::isfinite(b) && std::isfinite(t) && r != l && t != b,
            "frustum: l, r, b, t must be finite with l != r and b != t");
    require(f > n, "frustum: far must be > near, got far=" + std::to_string(f));
    glm::dmat4 m(0.0);
    m[0][0] = 2.0 * n / (r - l);
    m[2][0] = (r + l) / (r - l);
    m[1][1] = 2.0 * n / (t - b);
    m[2][1] = (t + b) / (t - b);
    set_perspective_depth(m, n, f, c);
    return m;
}

glm::dmat4 perspective(double fovy, double aspect, double near, double far, DepthConvention c) {
    require(std::isfinite(fovy) && fovy > 0.0 && fovy < M_PI, "perspective: fovy must be in (0, pi) radians");
    require(std::isfinite(aspect) && aspect > 0.0, "perspective: aspect must be finite and > 0");
    const double t = near * std::tan(fovy / 2.0);
    return frustum(-t * aspect, t * aspect, -t, t, near, far, c);
}

glm::dmat4 orthographic(double l, double r, double b, double t, double n, double f, DepthConvention c) {
    require(std::isfinite(l) && std::isfinite(r) && std::isfinite(b) && std::isfinite(t) && r != l && t != b,
            "orthographic: l, r, b, t must be finite with l != r and b != t");
    require(std::isfinite(n) && std::isfinite(f) && f != n, "orthographic: near and far must be finite and differ");
    glm::dmat4 m(1.0);
    m[0][0] = 2.0 / (r - l);
    m[3][0] = -(r + l) / (r - l);
    m[1][1] = 2.0 / (t - b);
    m[3][1] = -(t + b) / (t - b);
    if (c == DepthConvention::opengl) {
        m[2][2] = -2.0 / (f - n);
        m[3][2] = -(f + n) / (f - n);
    } else {  // z = −n → 1, z = −f → 0
        m[2][2] = 1.0 / (f - n);
        m[3][2] = f / (f - n);
    }
    // Finite bounds can still overflow their difference (r − l = ∞ gave a zero scale and a blank
    // image) or make it so small that its reciprocal overflows.
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            require(std::isfinite(m[i][j]) && (i != j || m[i][j] != 0.0),
                    "orthographic: the extents r - l, t - b and far - near must be finite, nonzero and not so small "
                    "that their reciprocals overflow");
    return m;
}

Camera Camera::look_at_perspective(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up,
                                   double fovy, double aspect, double near) {
    return Camera{look_at(eye, target, up), perspective(fovy, aspect, near), DepthConvention::reverse_z};
}

Camera Camera::from_matrices(const glm::dmat4& view, const glm::dmat4& projection, DepthConvention c) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            require(std::isfinite(view[i][j]), "Camera: view matrix has a non-finite entry");
            require(std::isfinite(projection[i][j]), "Camera: projection matrix has a non-finite entry");
        }
    return Camera{view, projection, c};
}

double DepthDecoder::view_depth(float window_depth) const {
    const double n = convention == DepthConvention::opengl ? 2.0 * window_depth - 1.0 : window_depth;
    return -(b - d * n) / (c * n - a);
}

DepthDecoder Camera::depth_decoder() const {
    // glm is column-major: projection[col][row].
    require(projection[0][2] == 0.0 && projection[1][2] == 0.0 && projection[0][3] == 0.0 && projection[1][3] == 0.0,
            "Camera: depth output needs a projection whose z and w rows depend on view-space z only");
    return DepthDecoder{projection[2][2], projection[3][2], projection[2][3], projection[3][3], depth_convention};
}

std::string Camera::to_string() const {
    std::ostringstream s;
    s << "Camera(depth=" << mipraster::to_string(depth_convention) << ", projection=[";
    for (int row = 0; row < 4; ++row) {
        s << (row ? "; " : "");
        for (int col = 0; col < 4; ++col) s << (col ? " " : "") << projection[col][row];
    }
    s << "])";
    return s.str();
}

}  // namespace mipraster
