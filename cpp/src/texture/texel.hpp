#pragma once
// One RGBA texel in one SSE register, and the blends every filter builds on (private to the
// texture module). A GCC/Clang vector type: the same SSE2 instructions on every x86-64, so
// results do not depend on the CPU (DESIGN.md §2.8).
#include <cstring>

#include <glm/vec4.hpp>
#if defined(__AVX__)
#include <immintrin.h>
#endif

namespace mipraster {
namespace texel {

typedef float Texel __attribute__((vector_size(16)));

inline Texel load(const glm::vec4& t) {
    Texel r;
    std::memcpy(&r, &t, sizeof r);
    return r;
}
inline Texel load(const float* rgba) {
    Texel r;
    std::memcpy(&r, rgba, sizeof r);
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

#if defined(__AVX__)
// A texel of each of two mip levels in one AVX register (builds for x86-64-v3): the bilinear
// blends of both levels' quads at once, each half the arithmetic of lerp_quad on its own.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
typedef float TexelPair __attribute__((vector_size(32)));

// (Intrinsics: two 16-byte copies into a 32-byte variable were read back through memory, and the
// wide load waited for the narrow stores, doubling the frame.)
inline TexelPair load_pair(const float* finer, const float* coarser) {
    const __m128 low = _mm_loadu_ps(finer), high = _mm_loadu_ps(coarser);
    return TexelPair(_mm256_insertf128_ps(_mm256_castps128_ps256(low), high, 1));
}
inline Texel finer_half(TexelPair p) { return Texel(_mm256_castps256_ps128(__m256(p))); }
inline Texel coarser_half(TexelPair p) { return Texel(_mm256_extractf128_ps(__m256(p), 1)); }
inline TexelPair lerp_pair(TexelPair a, TexelPair b, float t_finer, float t_coarser) {
    const TexelPair t{t_finer, t_finer, t_finer, t_finer, t_coarser, t_coarser, t_coarser, t_coarser};
    return a + t * (b - a);
}
#pragma GCC diagnostic pop
#endif

}  // namespace texel
}  // namespace mipraster
