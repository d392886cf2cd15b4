#pragma once
// A triangle mesh as plain arrays: positions, triangle indices and optional vertex colours.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace mipraster {

/// Indexed triangles. `colors`, when present, has one linear premultiplied RGBA per vertex.
struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    std::vector<glm::vec4> colors;

    bool has_colors() const { return !colors.empty(); }

    /// Throws std::invalid_argument naming the first bad element: a non-finite position or
    /// colour (which vertex, which component), an index out of range (which triangle, which
    /// corner), or a colour array whose size differs from the position array's.
    void validate(const std::string& name = "mesh") const;

    std::string to_string() const;
};

/// Throws std::invalid_argument naming the first index ≥ vertex_count as `name`[t][corner].
void validate_triangle_indices(const std::vector<glm::uvec3>& triangles, std::size_t vertex_count,
                               const std::string& name);

}  // namespace mipraster
