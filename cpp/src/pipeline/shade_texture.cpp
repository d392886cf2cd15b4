#include "mipraster/pipeline/shade_texture.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mipraster {

std::string to_string(DerivativeMode mode) { return mode == DerivativeMode::quad ? "quad" : "analytic"; }

std::string to_string(DebugView view) {
    switch (view) {
        case DebugView::none: return "none";
        case DebugView::mip_level: return "mip-level";
        case DebugView::uv: return "uv";
    }
    return "?";
}

DerivativeMode parse_derivative_mode(const std::string& name) {
    if (name == "analytic") return DerivativeMode::analytic;
    if (name == "quad") return DerivativeMode::quad;
    throw std::invalid_argument("derivatives: unknown mode '" + name + "'; expected analytic or quad");
}

DebugView parse_debug_view(const std::string& name) {
    if (name == "none") return DebugView::none;
    if (name == "mip-level" || name == "mip_level") return DebugView::mip_level;
    if (name == "uv") return DebugView::uv;
    throw std::invalid_argument("debug view: unknown view '" + name + "'; expected none, mip-level or uv");
}

glm::vec4 mip_level_colour(double lambda) {
    // Level 0 red, then orange, yellow, green, cyan, blue, violet, magenta, grey; coarser levels grey.
    static const glm::vec4 palette[] = {
        {1.0f, 0.0f, 0.0f, 1.0f}, {1.0f, 0.35f, 0.0f, 1.0f}, {1.0f, 1.0f, 0.0f, 1.0f},
        {0.0f, 1.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 1.0f, 1.0f},  {0.0f, 0.0f, 1.0f, 1.0f},
        {0.35f, 0.0f, 1.0f, 1.0f}, {1.0f, 0.0f, 1.0f, 1.0f}, {0.5f, 0.5f, 0.5f, 1.0f},
    };
    constexpr int last = static_cast<int>(sizeof palette / sizeof palette[0]) - 1;
    if (!(lambda > 0.0)) return palette[0];
    if (lambda >= last) return palette[last];
    const int k = static_cast<int>(lambda);
    const float f = static_cast<float>(lambda - k);
    return palette[k] + f * (palette[k + 1] - palette[k]);
}

}  // namespace mipraster
