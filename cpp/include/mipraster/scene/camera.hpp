#pragma once
// Camera: view and projection matrices (double precision) and the depth convention they follow.
#include <limits>
#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace mipraster {

/// How a projection maps view depth to clip z, and so which depth test and clear value apply.
enum class DepthConvention {
    reverse_z,  ///< near → 1, far (or infinity) → 0; clip volume 0 ≤ z ≤ w; test GREATER, clear 0
    opengl,     ///< near → −1, far → +1; clip volume −w ≤ z ≤ w; window depth z/2+½; test LESS, clear 1
};

std::string to_string(DepthConvention convention);

/// Right-handed view matrix: the camera at `eye` looks at `target` down its −z axis, +y up
/// (the seeds' construction: rows u, v, −w with w the view direction).
glm::dmat4 look_at(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up);

inline constexpr double kInfiniteFar = std::numeric_limits<double>::infinity();

/// The smallest near distance of a perspective projection: float32's smallest normal number,
/// 2^−126 ≈ 1.18·10⁻³⁸. The depth buffer is float32 and holds near/d for a surface at view
/// distance d (reverse-Z, infinite far; a finite far gives less): with a near below it the
/// depth of everything beyond unit distance is subnormal (fewer than float's 24 bits, so
/// surfaces stop ordering) and at near ≈ 10⁻⁴⁵·d it rounds to 0, the clear depth, which fails
/// the GREATER test: a blank image (near = 10⁻⁴⁵ at d = 3). From there on near/d is a normal
/// float up to d = near / 2^−126; the depth contract (distances 10⁻² … 10⁵ at near = 10⁻³,
/// depths ≥ 10⁻⁸) is far inside. (OpenGL-convention depth, 1 − 2·near/d, loses far more, and
/// is bounded by the same minimum.) frustum, perspective and look_at_perspective throw
/// std::invalid_argument below it; orthographic depth is linear in distance and takes any near.
inline constexpr double kMinPerspectiveNear = static_cast<double>(std::numeric_limits<float>::min());

/// Perspective projection of the frustum (l, r, b, t) at distance n (≥ kMinPerspectiveNear), far
/// plane at f (may be kInfiniteFar for reverse-Z). With DepthConvention::opengl this is exactly
/// the seeds' matrix.
glm::dmat4 frustum(double l, double r, double b, double t, double n, double f,
                   DepthConvention convention = DepthConvention::reverse_z);

/// Perspective projection from the vertical field of view (radians) and aspect = width/height.
glm::dmat4 perspective(double fovy, double aspect, double near, double far = kInfiniteFar,
                       DepthConvention convention = DepthConvention::reverse_z);

/// Orthographic projection of the box [l,r]×[b,t]×[−n,−f] in view space (f must be finite).
glm::dmat4 orthographic(double l, double r, double b, double t, double n, double f,
                        DepthConvention convention = DepthConvention::reverse_z);

/// Window depth → view-space depth (−z_view, the distance along the viewing axis). Valid for
/// projections whose z and w rows depend on view-space z only — every perspective, frustum and
/// orthographic projection: z_clip = a·z + b, w_clip = c·z + d, so z = (b − d·n)/(c·n − a) for
/// the NDC depth n.
struct DepthDecoder {
    double a = 0, b = 0, c = 0, d = 1;
    DepthConvention convention = DepthConvention::reverse_z;

    double view_depth(float window_depth) const;
};

/// A camera: world → view → clip. The library's own constructors use reverse-Z; matrices from
/// elsewhere (OpenGL style) are accepted with DepthConvention::opengl.
struct Camera {
    glm::dmat4 view{1.0};
    glm::dmat4 projection{1.0};
    DepthConvention depth_convention = DepthConvention::reverse_z;

    /// Camera at `eye` looking at `target`, vertical field of view `fovy` (radians), reverse-Z with
    /// an infinite far plane.
    static Camera look_at_perspective(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up,
                                      double fovy, double aspect, double near);
    /// Raw matrices, e.g. from an OpenGL program (column vectors: clip = projection · view · p).
    static Camera from_matrices(const glm::dmat4& view, const glm::dmat4& projection,
                                DepthConvention convention = DepthConvention::opengl);

    /// The decoder of this camera's window depth; throws std::invalid_argument when the
    /// projection's z or w row depends on view-space x or y.
    DepthDecoder depth_decoder() const;

    std::string to_string() const;
};

}  // namespace mipraster
