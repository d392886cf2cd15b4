#pragma once
// Vertex transform stage: object-space positions → homogeneous clip space, in double precision.
#include <cstddef>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace mipraster {

/// out[i] = mvp · (in[i], 1) for i in [0, count). Double precision so that clipping and
/// snapping see each clip coordinate with (far) more precision than float32 input carries.
void transform_vertices(const glm::vec3* in, std::size_t count, const glm::dmat4& mvp, glm::dvec4* out);

}  // namespace mipraster
