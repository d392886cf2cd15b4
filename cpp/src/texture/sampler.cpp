#include "mipraster/texture/sampler.hpp"

#include <cmath>
#include <stdexcept>

namespace mipraster {

bool Sampler::uses_mip_levels() const {
    return mip_filter != MipFilter::none || footprint == FootprintFilter::ewa || footprint == FootprintFilter::sat;
}

void Sampler::validate() const {
    auto finite = [](float v, const char* name) {
        if (!std::isfinite(v)) throw std::invalid_argument(std::string("sampler.") + name + " is not finite");
    };
    finite(max_anisotropy, "max_anisotropy");
    finite(lod_bias, "lod_bias");
    finite(min_lod, "min_lod");
    finite(max_lod, "max_lod");
    for (int c = 0; c < 4; ++c) finite(border_color[c], "border_color");
    if (max_anisotropy < 1.0f)
        throw std::invalid_argument("sampler.max_anisotropy is " + std::to_string(max_anisotropy) + "; expected >= 1");
    if (min_lod > max_lod)
        throw std::invalid_argument("sampler.min_lod (" + std::to_string(min_lod) + ") exceeds max_lod (" +
                                    std::to_string(max_lod) + ")");
}

std::string Sampler::to_string() const {
    return "Sampler(mag=" + mipraster::to_string(mag_filter) + ", min=" + mipraster::to_string(min_filter) +
           ", mip=" + mipraster::to_string(mip_filter) + ", footprint=" + mipraster::to_string(footprint) +
           ", max_anisotropy=" + std::to_string(max_anisotropy) + ", wrap=" + mipraster::to_string(wrap_u) + "/" +
           mipraster::to_string(wrap_v) + ", lod_bias=" + std::to_string(lod_bias) + ")";
}

Sampler Sampler::from_filter_name(const std::string& name) {
    Sampler s;
    if (name == "nearest") {
        s.mag_filter = s.min_filter = TexelFilter::nearest;
        s.mip_filter = MipFilter::none;
    } else if (name == "bilinear") {
        s.mip_filter = MipFilter::none;
    } else if (name == "trilinear") {
    } else if (name == "anisotropic") {
        s.footprint = FootprintFilter::anisotropic;
    } else if (name == "ewa") {
        s.footprint = FootprintFilter::ewa;
    } else if (name == "sat") {
        s.footprint = FootprintFilter::sat;
    } else {
        throw std::invalid_argument("filter: unknown name '" + name +
                                    "'; expected nearest, bilinear, trilinear, anisotropic, ewa or sat");
    }
    return s;
}

std::string to_string(WrapMode mode) {
    switch (mode) {
        case WrapMode::repeat: return "repeat";
        case WrapMode::clamp: return "clamp";
        case WrapMode::mirror: return "mirror";
        case WrapMode::border: return "border";
    }
    return "?";
}

std::string to_string(TexelFilter filter) { return filter == TexelFilter::nearest ? "nearest" : "linear"; }

std::string to_string(MipFilter filter) {
    switch (filter) {
        case MipFilter::none: return "none";
        case MipFilter::nearest: return "nearest";
        case MipFilter::linear: return "linear";
    }
    return "?";
}

std::string to_string(FootprintFilter filter) {
    switch (filter) {
        case FootprintFilter::isotropic: return "isotropic";
        case FootprintFilter::anisotropic: return "anisotropic";
        case FootprintFilter::ewa: return "ewa";
        case FootprintFilter::sat: return "sat";
    }
    return "?";
}

WrapMode parse_wrap_mode(const std::string& name) {
    if (name == "repeat") return WrapMode::repeat;
    if (name == "clamp") return WrapMode::clamp;
    if (name == "mirror") return WrapMode::mirror;
    if (name == "border") return WrapMode::border;
    throw std::invalid_argument("wrap: unknown mode '" + name + "'; expected repeat, clamp, mirror or border");
}

}  // namespace mipraster
