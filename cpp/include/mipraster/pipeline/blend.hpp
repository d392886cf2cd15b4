#pragma once
// Blend stage: combine a premultiplied linear fragment with the framebuffer sample (no clamping).
#include "mipraster/pipeline/draw.hpp"

namespace mipraster {

template <BlendMode kMode>
inline void blend_into(float* dst, const glm::vec4& src) {
    for (int c = 0; c < 4; ++c) {
        if constexpr (kMode == BlendMode::replace) {
            dst[c] = src[c];
        } else if constexpr (kMode == BlendMode::add) {
            dst[c] = dst[c] + src[c];
        } else {
            dst[c] = src[c] + (1.0f - src.a) * dst[c];
        }
    }
}

}  // namespace mipraster
