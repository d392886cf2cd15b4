#pragma once
// Alpha test stage (glTF alphaMode MASK, DrawState::alpha_cutoff): a shaded fragment is either
// discarded or made opaque, before any depth or colour is written.
#include <cstring>

#include <glm/vec4.hpp>

namespace mipraster {

/// False when premultiplied colour c's alpha is below `cutoff` or NaN (the fragment is discarded);
/// else true with c made opaque: rgb / alpha and alpha 1 (rgb kept at alpha 0, which only a cutoff
/// of 0 lets through: there is no colour to divide out).
inline bool alpha_test(glm::vec4& c, float cutoff) {
    if (!(c.a >= cutoff)) return false;
    if (c.a == 1.0f) return true;  // (already opaque: rgb / 1 is rgb, and the division waits long)
    if (c.a > 0.0f) {
        // One vector division for the three (a division's throughput is several cycles), each
        // lane rounded as a scalar division would be; stored at once.
        typedef float Four __attribute__((vector_size(16)));
        Four q = Four{c.r, c.g, c.b, c.a} / c.a;
        q[3] = 1.0f;
        std::memcpy(&c, &q, sizeof c);
    } else {
        c.a = 1.0f;
    }
    return true;
}

}  // namespace mipraster
