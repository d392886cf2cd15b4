#include "mipraster/scene/mesh.hpp"

#include <cmath>
#include <stdexcept>

namespace mipraster {

namespace {
const char* const kAxis[4] = {"x", "y", "z", "w"};
const char* const kChannel[4] = {"r", "g", "b", "a"};
}  // namespace

void Mesh::validate(const std::string& name) const {
    for (std::size_t i = 0; i < positions.size(); ++i)
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(positions[i][c]))
                throw std::invalid_argument(name + ".positions[" + std::to_string(i) + "]." + kAxis[c] +
                                            " is " + std::to_string(positions[i][c]) + "; expected a finite number");
    if (!colors.empty() && colors.size() != positions.size())
        throw std::invalid_argument(name + ".colors has " + std::to_string(colors.size()) +
                                    " entries; expected one per vertex (" + std::to_string(positions.size()) + ") or none");
    for (std::size_t i = 0; i < colors.size(); ++i)
        for (int c = 0; c < 4; ++c)
            if (!std::isfinite(colors[i][c]))
                throw std::invalid_argument(name + ".colors[" + std::to_string(i) + "]." + kChannel[c] +
                                            " is " + std::to_string(colors[i][c]) + "; expected a finite number");
    validate_triangle_indices(triangles, positions.size(), name + ".triangles");
}

void validate_triangle_indices(const std::vector<glm::uvec3>& triangles, std::size_t vertex_count,
                               const std::string& name) {
    for (std::size_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
            if (triangles[t][k] >= vertex_count)
                throw std::invalid_argument(name + "[" + std::to_string(t) + "][" + std::to_string(k) + "] = " +
                                            std::to_string(triangles[t][k]) + " is out of range; expected < " +
                                            std::to_string(vertex_count) + " (the vertex count)");
}

std::string Mesh::to_string() const {
    return "Mesh(vertices=" + std::to_string(positions.size()) + ", triangles=" + std::to_string(triangles.size()) +
           (has_colors() ? ", colors" : "") + ")";
}

}  // namespace mipraster
