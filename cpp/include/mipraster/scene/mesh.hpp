#pragma once
// A triangle mesh as plain arrays: positions, triangle indices and optional per-vertex colours,
// texture coordinates and normals.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace mipraster {

/// Indexed triangles. Each optional array is empty or has one entry per vertex: `colors` linear
/// premultiplied RGBA, `uvs` texture coordinates (DESIGN.md §1: (0,0) is the top-left corner of
/// the image), `normals` (carried for users and scene files; shading does not use them yet).
struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    std::vector<glm::vec4> colors;
    std::vector<glm::vec2> uvs;
    std::vector<glm::vec3> normals;

    bool has_colors() const { return !colors.empty(); }
    bool has_uvs() const { return !uvs.empty(); }

    /// Throws std::invalid_argument naming the first bad element: a non-finite position, colour,
    /// uv or normal (which vertex, which component), an index out of range (which triangle, which
    /// corner), or an optional array whose size differs from the position array's.
    void validate(const std::string& name = "mesh") const;

    std::string to_string() const;
};

/// Throws std::invalid_argument naming the first index ≥ vertex_count as `name`[t][corner].
void validate_triangle_indices(const std::vector<glm::uvec3>& triangles, std::size_t vertex_count,
                               const std::string& name);

}  // namespace mipraster
