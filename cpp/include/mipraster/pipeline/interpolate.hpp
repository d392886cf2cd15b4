#pragma once
// Interpolation stage: barycentric weights of a sample from its exact edge values, in screen
// space or perspective-correct, mapped back to the original (unclipped) triangle's vertices.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mipraster/pipeline/draw.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace mipraster {

/// Screen-space barycentrics λ from the (biased) edge values at a sample: λ_i = E_i / 2A.
inline glm::dvec3 screen_weights(const SetupTriangle& t, std::int64_t e0, std::int64_t e1, std::int64_t e2) {
    return glm::dvec3(static_cast<double>(e0 + t.bias[0]), static_cast<double>(e1 + t.bias[1]),
                      static_cast<double>(e2 + t.bias[2])) * t.inv_area2;
}

/// Window depth at a sample: z0 + λ1·dz1 + λ2·dz2 (exact for a constant-depth triangle).
inline float sample_depth(const SetupTriangle& t, const glm::dvec3& l) {
    return static_cast<float>(t.z0 + l.y * t.dz1 + l.z * t.dz2);
}

/// Perspective-correct weights: λ_i/w_i normalized. Each is ≥ 0 inside the triangle and they
/// sum to 1, so interpolated values stay within the vertex values (up to rounding).
inline glm::dvec3 perspective_weights(const SetupTriangle& t, const glm::dvec3& l) {
    const glm::dvec3 q(l.x * t.inv_w[0], l.y * t.inv_w[1], l.z * t.inv_w[2]);
    return q * (1.0 / (q.x + q.y + q.z));
}

/// The interpolation the pipeline runs for a draw that asked for `requested`. Perspective-correct
/// weights λ_i·q / Σ λ_j·q equal the screen weights λ_i when every vertex has the same clip w = 1/q
/// (an orthographic camera), so such a draw interpolates affinely and skips a division per
/// sample; the values differ by rounding only. Any other draw keeps what it asked for.
inline Interpolation effective_interpolation(Interpolation requested, const glm::dvec4* clip_positions,
                                             std::size_t count) {
    if (requested != Interpolation::perspective || count == 0) return requested;
    const double w = clip_positions[0].w;
    for (std::size_t i = 1; i < count; ++i)
        if (!(clip_positions[i].w == w)) return requested;
    return w == w ? Interpolation::screen : requested;  // (a NaN w is never the same)
}

/// Maps weights of the setup triangle's vertices to weights of the original triangle's vertices
/// (they differ only when the triangle was clipped).
inline glm::dvec3 original_weights(const SetupTriangle& t, const glm::dvec3& w, const ClipWeights* clip_weights) {
    if (t.clip_index < 0) return w;
    const ClipWeights& c = clip_weights[t.clip_index];
    return w.x * glm::dvec3(c[0]) + w.y * glm::dvec3(c[1]) + w.z * glm::dvec3(c[2]);
}

/// The values of an attribute at a triangle's three vertices, with their per-component range.
struct VertexValues {
    glm::vec4 v[3];
    glm::vec4 lo, hi;
    glm::dvec4 wide[3];  ///< v in double, once per triangle, not per sample interpolated
    /// Every component one finite, nonzero value c at all three vertices: then a weighted sum with
    /// finite weights, clamped to [lo, hi] = [c, c], is c with its bits. (Zero is left out: a sum
    /// of −0 and +0 terms can give the other signed zero, which the clamp keeps. Compared vertex
    /// by vertex, not through lo and hi, whose selections pass over a NaN.)
    bool one = false;

    VertexValues() = default;
    /// lo = glm::min(a, glm::min(b, c)) and hi = glm::max(a, glm::max(b, c)), four components at
    /// once: glm's min(x, y) is y < x ? y : x and max(x, y) is x < y ? y : x, selected the same way.
    VertexValues(const glm::vec4& a, const glm::vec4& b, const glm::vec4& c)
        : v{a, b, c}, wide{glm::dvec4(a), glm::dvec4(b), glm::dvec4(c)} {
        typedef float Four __attribute__((vector_size(16)));
        Four x, y, z;
        std::memcpy(&x, &a, sizeof x);
        std::memcpy(&y, &b, sizeof y);
        std::memcpy(&z, &c, sizeof z);
        const Four min_yz = z < y ? z : y, max_yz = y < z ? z : y;
        const Four low = min_yz < x ? min_yz : x, high = x < max_yz ? max_yz : x;
        std::memcpy(&lo, &low, sizeof lo);
        std::memcpy(&hi, &high, sizeof hi);
        const auto same = (x == y) & (y == z) & (x != 0.0f) & (x - x == 0.0f);  // (x − x: NaN for ±inf, NaN)
        one = same[0] & same[1] & same[2] & same[3];
    }

    /// Σ w_i·v_i, clamped to the vertex values' range so rounding never leaves it: per component,
    /// std::clamp(float(w.x·v0 + w.y·v1 + w.z·v2), lo, hi), four components at once.
    glm::vec4 interpolate(const glm::dvec3& w) const {
        typedef float Four __attribute__((vector_size(16)));
        typedef double FourDoubles __attribute__((vector_size(32)));
        Four low, high;
        FourDoubles a2, b2, c2;
        std::memcpy(&a2, &wide[0], sizeof a2);
        std::memcpy(&b2, &wide[1], sizeof b2);
        std::memcpy(&c2, &wide[2], sizeof c2);
        std::memcpy(&low, &lo, sizeof low);
        std::memcpy(&high, &hi, sizeof high);
        const FourDoubles sum = w.x * a2 + w.y * b2 + w.z * c2;
        const Four x = __builtin_convertvector(sum, Four);
        const Four clamped = x < low ? low : (high < x ? high : x);
        glm::vec4 r;
        std::memcpy(&r, &clamped, sizeof r);
        return r;
    }
};

}  // namespace mipraster
