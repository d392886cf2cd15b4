#pragma once
// The stress suite's geometry oracle: a double-precision ray cast against a triangle given in
// clip space. Independent of the pipeline: no clipping, no snapping, no setup; it solves for the
// point of the triangle's plane on the line of sight through a screen point directly.
#include <array>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace mipraster::stress {

struct ClipHit {
    bool hit = false;        ///< the line of sight meets the visible part of the triangle
    glm::dvec3 weights{0.0}; ///< barycentric weights of the triangle's vertices (sum 1) at the point
    double w = 0.0;          ///< clip w at the point
    double window_depth = 0.0;  ///< z/w (reverse-Z) or z/(2w) + ½ (OpenGL) at the point
};

/// The point of the clip-space triangle p seen at NDC (x, y): weights b with Σb = 1,
/// Σ b_i (x_i − x·w_i) = 0 and Σ b_i (y_i − y·w_i) = 0 (Cramer's rule). It is a hit when every
/// b_i ≥ 0, w > 0, and z lies in the depth range (reverse-Z 0 ≤ z ≤ w, OpenGL −w ≤ z ≤ w): the
/// visible part is exactly what near/far clipping keeps. A triangle seen edge-on never hits.
ClipHit ray_cast_clip(const std::array<glm::dvec4, 3>& p, double x_ndc, double y_ndc, bool reverse_z);

/// NDC of a screen point (pixels, y down) of a W×H viewport (DESIGN.md §1 inverted).
inline double screen_to_ndc_x(double x, int width) { return 2.0 * x / width - 1.0; }
inline double screen_to_ndc_y(double y, int height) { return 1.0 - 2.0 * y / height; }

}  // namespace mipraster::stress
