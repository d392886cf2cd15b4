#include "mipraster/pipeline/draw.hpp"

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

std::string DrawState::to_string() const {
    return std::string("DrawState(depth_test=") + (depth_test ? "true" : "false") +
           ", depth_write=" + (depth_write ? "true" : "false") + ", blend=" + mipraster::to_string(blend) +
           ", interpolation=" + mipraster::to_string(interpolation) + ", cull=" + mipraster::to_string(cull) + ")";
}

std::string Draw::to_string() const {
    return "Draw(" + (mesh ? mesh->to_string() : std::string("no mesh")) + ", " +
           (texture ? texture.to_string() + ", " + sampler.to_string() + ", " : std::string()) + state.to_string() + ")";
}

}  // namespace mipraster
