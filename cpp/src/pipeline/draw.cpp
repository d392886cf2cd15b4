#include "mipraster/pipeline/draw.hpp"

#include <cstdio>
#include <stdexcept>

namespace mipraster {

std::string to_string(BlendMode m) {
    switch (m) {
        case BlendMode::replace: return "replace";
        case BlendMode::add: return "add";
        case BlendMode::over: return "over";
    }
    return "?";
}

std::string to_string(Interpolation m) {
    switch (m) {
        case Interpolation::flat: return "flat";
        case Interpolation::screen: return "screen";
        case Interpolation::perspective: return "perspective";
    }
    return "?";
}

std::string to_string(CullMode m) {
    switch (m) {
        case CullMode::none: return "none";
        case CullMode::back: return "back";
        case CullMode::front: return "front";
    }
    return "?";
}

namespace {

// A cutoff as %g prints it (0.5, 0.3, nan).
std::string cutoff_text(float cutoff) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", static_cast<double>(cutoff));
    return buf;
}

}  // namespace

void DrawState::validate(const std::string& name) const {
    if (alpha_cutoff && !(*alpha_cutoff >= 0.0f && *alpha_cutoff <= 1.0f))
        throw std::invalid_argument(name + ".alpha_cutoff is " + cutoff_text(*alpha_cutoff) +
                                    "; expected a number in [0, 1] (or none: no alpha test)");
}

std::string DrawState::to_string() const {
    // (alpha_cutoff only when set: the text of a draw without one is as before)
    return std::string("DrawState(depth_test=") + (depth_test ? "true" : "false") +
           ", depth_write=" + (depth_write ? "true" : "false") + ", blend=" + mipraster::to_string(blend) +
           ", interpolation=" + mipraster::to_string(interpolation) + ", cull=" + mipraster::to_string(cull) +
           (alpha_cutoff ? ", alpha_cutoff=" + cutoff_text(*alpha_cutoff) : std::string()) + ")";
}

std::string Draw::to_string() const {
    return "Draw(" + (mesh ? mesh->to_string() : std::string("no mesh")) + ", " +
           (texture ? texture.to_string() + ", " + sampler.to_string() + ", " : std::string()) + state.to_string() + ")";
}

}  // namespace mipraster
