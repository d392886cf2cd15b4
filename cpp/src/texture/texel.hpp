#pragma once
// One RGBA texel in one SSE register, and the blends every filter builds on (private to the
// texture module). A GCC/Clang vector type: the same SSE2 instructions on every x86-64, so
// results do not depend on the CPU (DESIGN.md §2.8).
#include <cstring>

#include <glm/vec4.hpp>

namespace mipraster {
namespace texel {

typedef float Texel __attribute__((vector_size(16)));

inline Texel load(const glm::vec4& t) {
    Texel r;
    std::memcpy(&r, &t, sizeof r);
    return r;
}
inline glm::vec4 to_vec4(Texel t) {
    glm::vec4 r;
    std::memcpy(&r, &t, sizeof r);
    return r;
}
inline Texel splat(float x) { return Texel{x, x, x, x}; }
// a + t·(b − a): equal a and b give back a exactly, whatever t is.
inline Texel lerp(Texel a, Texel b, float t) { return a + splat(t) * (b - a); }
// The bilinear blend of four texels a b / c d at fractions (ax, ay).
inline Texel lerp_quad(Texel a, Texel b, Texel c, Texel d, float ax, float ay) {
    return lerp(lerp(a, b, ax), lerp(c, d, ax), ay);
}

}  // namespace texel
}  // namespace mipraster
