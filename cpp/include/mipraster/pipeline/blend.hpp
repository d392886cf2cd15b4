#pragma once
// Blend stage: combine a premultiplied linear fragment with the framebuffer sample (no clamping).
#include <cstdint>
#include <cstring>

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

/// blend_into for the samples of one pixel in `samples` (bit s: the slot dst + 4·s). Replacing
/// slots 0 … n − 1 (a pixel covered whole, as most are under MSAA) stores two slots at a time: the
/// loop over the bits took 6 instructions a slot (plane MSAA 4x: 20 M of a 395 M frame).
template <BlendMode kMode>
inline void blend_into_samples(float* dst, std::uint64_t samples, const glm::vec4& src) {
    if constexpr (kMode == BlendMode::replace) {
        if ((samples & (samples + 1)) == 0) {  // (all 64 bits too: samples + 1 wraps to 0)
            typedef float Slot __attribute__((vector_size(16)));
            Slot one;
            std::memcpy(&one, &src, sizeof one);
            const auto two = __builtin_shufflevector(one, one, 0, 1, 2, 3, 0, 1, 2, 3);
            if (samples == 0xF) {  // (4x: unrolled)
                std::memcpy(dst, &two, sizeof two);
                std::memcpy(dst + 8, &two, sizeof two);
                return;
            }
            const int n = __builtin_popcountll(samples);
            int s = 0;
            for (; s + 2 <= n; s += 2) std::memcpy(dst + 4 * s, &two, sizeof two);
            if (s < n) std::memcpy(dst + 4 * s, &one, sizeof one);
            return;
        }
    }
    for (std::uint64_t m = samples; m; m &= m - 1) blend_into<kMode>(dst + 4 * __builtin_ctzll(m), src);
}

}  // namespace mipraster
