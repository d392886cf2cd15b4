#include "mipraster/pipeline/vertex_transform.hpp"

namespace mipraster {

void transform_vertices(const glm::vec3* in, std::size_t count, const glm::dmat4& mvp, glm::dvec4* out) {
    for (std::size_t i = 0; i < count; ++i) out[i] = mvp * glm::dvec4(glm::dvec3(in[i]), 1.0);
}

}  // namespace mipraster
