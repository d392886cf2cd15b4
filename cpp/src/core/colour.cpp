#include "mipraster/core/colour.hpp"

#include <cmath>
#include <limits>

#include "mipraster/core/image.hpp"

namespace mipraster {

float srgb_to_linear(float encoded) {
    if (!(encoded > 0.0f)) return 0.0f;
    if (encoded >= 1.0f) return 1.0f;
    return encoded <= 0.04045f ? encoded / 12.92f
                               : static_cast<float>(std::pow((encoded + 0.055) / 1.055, 2.4));
}

float linear_to_srgb(float linear) {
    if (!(linear > 0.0f)) return 0.0f;  // also maps NaN to 0
    if (linear >= 1.0f) return 1.0f;
    return linear <= 0.0031308f ? linear * 12.92f
                                : static_cast<float>(1.055 * std::pow(static_cast<double>(linear), 1.0 / 2.4) - 0.055);
}

namespace {

// Linear value → sRGB code of type Code (8 or 16 bits), rounded to nearest.
template <typename Code>
Code linear_to_srgb_code(float linear) {
    constexpr float kMax = std::numeric_limits<Code>::max();
    return static_cast<Code>(std::lround(linear_to_srgb(linear) * kMax));
}

// Premultiplied linear RGBA → straight-alpha sRGB RGBA codes of type Code.
template <typename Code>
std::vector<Code> to_srgb_codes(const Image& img) {
    constexpr float kMax = std::numeric_limits<Code>::max();
    std::vector<Code> out(static_cast<std::size_t>(img.width) * img.height * 4);
    for (std::size_t p = 0, n = static_cast<std::size_t>(img.width) * img.height; p < n; ++p) {
        const float* src = &img.pixels[p * img.channels];
        const float a = img.channels == 4 ? src[3] : 1.0f;
        const float inv_a = a > 0.0f ? 1.0f / a : 0.0f;
        for (int c = 0; c < 3; ++c) {
            const float v = img.channels >= 3 ? src[c] : src[0];
            out[p * 4 + c] = linear_to_srgb_code<Code>(img.channels == 4 ? v * inv_a : v);
        }
        const float a_clamped = a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f;
        out[p * 4 + 3] = static_cast<Code>(std::lround(a_clamped * kMax));
    }
    return out;
}

}  // namespace

std::uint8_t linear_to_srgb8(float linear) { return linear_to_srgb_code<std::uint8_t>(linear); }
std::uint16_t linear_to_srgb16(float linear) { return linear_to_srgb_code<std::uint16_t>(linear); }

std::vector<std::uint8_t> to_srgb8(const Image& img) { return to_srgb_codes<std::uint8_t>(img); }
std::vector<std::uint16_t> to_srgb16(const Image& img) { return to_srgb_codes<std::uint16_t>(img); }

}  // namespace mipraster
