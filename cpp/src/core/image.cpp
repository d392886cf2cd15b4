#include "mipraster/core/image.hpp"

namespace mipraster {

std::string Image::to_string() const {
    return "Image(" + std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(channels) + ")";
}

}  // namespace mipraster
