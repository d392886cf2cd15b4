#include "mipraster/scene/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace mipraster {

namespace {
const char* const kAxis[4] = {"x", "y", "z", "w"};
const char* const kChannel[4] = {"r", "g", "b", "a"};
}  // namespace

namespace {

// True when every component is finite: its exponent bits are not all ones (±∞ and NaN). A pass
// without branches on the bits, which vectorizes: a render validates its meshes every frame,
// and a million triangles' took a few per cent of it one component at a time.
template <typename Vec>
bool all_finite(const std::vector<Vec>& values) {
    static_assert(sizeof(Vec) == Vec::length() * sizeof(std::uint32_t), "float components, packed");
    constexpr std::uint32_t kExponent = 0x7f800000;
    const std::size_t n = values.size() * Vec::length();
    const auto* x = reinterpret_cast<const unsigned char*>(values.data());
    std::uint32_t largest = 0;
    for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t b;
        std::memcpy(&b, x + 4 * i, 4);
        largest = std::max(largest, b & kExponent);
    }
    return largest != kExponent;
}

// Throws unless `values` is empty or has one finite entry per vertex.
template <typename Vec>
void validate_per_vertex(const std::vector<Vec>& values, std::size_t vertex_count, const std::string& name,
                         const char* const* component_names) {
    if (!values.empty() && values.size() != vertex_count)
        throw std::invalid_argument(name + " has " + std::to_string(values.size()) +
                                    " entries; expected one per vertex (" + std::to_string(vertex_count) + ") or none");
    if (all_finite(values)) return;
    for (std::size_t i = 0; i < values.size(); ++i)
        for (int c = 0; c < Vec::length(); ++c)
            if (!std::isfinite(values[i][c]))
                throw std::invalid_argument(name + "[" + std::to_string(i) + "]." + component_names[c] + " is " +
                                            std::to_string(values[i][c]) + "; expected a finite number");
}

const char* const kUv[2] = {"u", "v"};

}  // namespace

void Mesh::validate(const std::string& name) const {
    validate_per_vertex(positions, positions.size(), name + ".positions", kAxis);
    validate_per_vertex(colors, positions.size(), name + ".colors", kChannel);
    validate_per_vertex(uvs, positions.size(), name + ".uvs", kUv);
    validate_per_vertex(normals, positions.size(), name + ".normals", kAxis);
    validate_triangle_indices(triangles, positions.size(), name + ".triangles");
}

void validate_triangle_indices(const std::vector<glm::uvec3>& triangles, std::size_t vertex_count,
                               const std::string& name) {
    // The largest index first, without branches (it vectorizes); the first bad one only if it is.
    static_assert(sizeof(glm::uvec3) == 3 * sizeof(std::uint32_t), "packed indices");
    const std::uint32_t* index = triangles.empty() ? nullptr : &triangles[0][0];
    std::uint32_t largest = 0;
    for (std::size_t i = 0; i < 3 * triangles.size(); ++i) largest = std::max(largest, index[i]);
    if (triangles.empty() || largest < vertex_count) return;
    for (std::size_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
            if (triangles[t][k] >= vertex_count)
                throw std::invalid_argument(name + "[" + std::to_string(t) + "][" + std::to_string(k) + "] = " +
                                            std::to_string(triangles[t][k]) + " is out of range; expected < " +
                                            std::to_string(vertex_count) + " (the vertex count)");
}

std::string Mesh::to_string() const {
    return "Mesh(vertices=" + std::to_string(positions.size()) + ", triangles=" + std::to_string(triangles.size()) +
           (has_colors() ? ", colors" : "") + (has_uvs() ? ", uvs" : "") + (normals.empty() ? "" : ", normals") + ")";
}

}  // namespace mipraster
