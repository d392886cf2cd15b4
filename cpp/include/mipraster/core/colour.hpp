#pragma once
// sRGB transfer functions (IEC 61966-2-1) and 8- and 16-bit encoding of linear premultiplied colour.
#include <cstdint>
#include <vector>

namespace mipraster {

struct Image;

/// sRGB-encoded value in [0,1] → linear value (exact piecewise formula).
float srgb_to_linear(float encoded);
/// Linear value → sRGB-encoded value; clamps to [0,1] first, NaN maps to 0.
float linear_to_srgb(float linear);
/// Linear value → sRGB8 code, rounded to nearest (linear 0.5 → 188).
std::uint8_t linear_to_srgb8(float linear);
/// Linear value → 16-bit sRGB code, rounded to nearest (linear 0.5 → 48 192).
std::uint16_t linear_to_srgb16(float linear);

/// Premultiplied linear RGBA (C = 4) → straight-alpha sRGB8 RGBA, (H, W, 4) bytes.
/// Colour is un-premultiplied before encoding; alpha is stored linearly (as PNG expects).
std::vector<std::uint8_t> to_srgb8(const Image& premultiplied_rgba);
/// to_srgb8 with 16-bit codes (code / 65535).
std::vector<std::uint16_t> to_srgb16(const Image& premultiplied_rgba);

}  // namespace mipraster
