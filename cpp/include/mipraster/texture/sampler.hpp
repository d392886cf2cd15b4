#pragma once
// How a texture is read: texel filter, mip filter, footprint filter, wrap per axis, border
// colour and LOD controls (DESIGN.md §1: LOD, anisotropy; §2.6: sampling contract).
#include <string>

#include <glm/vec4.hpp>

namespace mipraster {

/// What lies outside [0, 1) along one axis.
enum class WrapMode {
    repeat,  ///< the texture tiles
    clamp,   ///< the edge texel extends (clamp-to-edge)
    mirror,  ///< the texture tiles, every other copy mirrored
    border,  ///< the border colour
};

/// Reconstruction within one level: the texel whose cell holds the point (the seeds'
/// i = ⌊u·w⌋), or bilinear between the four nearest texel centres (i = ⌊u·w − ½⌋).
enum class TexelFilter { nearest, linear };

/// Between levels: level 0 only, the nearest level, or linear between the two nearest (trilinear
/// when the texel filter is linear).
enum class MipFilter { none, nearest, linear };

/// How the pixel's footprint in the texture is integrated when minifying.
enum class FootprintFilter {
    isotropic,    ///< one lookup at the level of the longer derivative (standard mip-mapping)
    anisotropic,  ///< EXT_texture_filter_anisotropic: N probes along the major axis, λ from Pmax/N
    ewa,          ///< Heckbert's elliptical weighted average with a Gaussian over the footprint ellipse
    sat,          ///< summed-area table: the exact mean over the footprint's bounding box
};

struct Sampler {
    TexelFilter mag_filter = TexelFilter::linear;  ///< when λ ≤ 0 (magnification)
    TexelFilter min_filter = TexelFilter::linear;  ///< when λ > 0, within the chosen level(s)
    MipFilter mip_filter = MipFilter::linear;
    FootprintFilter footprint = FootprintFilter::isotropic;
    /// anisotropic: most probes per lookup; ewa: largest major/minor axis ratio before the minor
    /// axis is widened. At least 1.
    float max_anisotropy = 16.0f;
    WrapMode wrap_u = WrapMode::repeat, wrap_v = WrapMode::repeat;
    glm::vec4 border_color{0.0f};  ///< premultiplied linear RGBA; also returned for a non-finite uv
    float lod_bias = 0.0f;          ///< added to λ before clamping
    float min_lod = 0.0f, max_lod = 1000.0f;

    /// True when a lookup depends on the uv derivatives (some filter varies with λ). Inline: every
    /// lookup asks.
    bool needs_derivatives() const {
        // λ only chooses between the magnification and minification filters when they differ.
        return mip_filter != MipFilter::none || footprint != FootprintFilter::isotropic || mag_filter != min_filter;
    }
    /// True when a lookup may read levels other than 0.
    bool uses_mip_levels() const;

    /// Throws std::invalid_argument naming the bad field (non-finite values, max_anisotropy < 1,
    /// min_lod > max_lod).
    void validate() const;
    std::string to_string() const;

    /// A sampler from a filter name: "nearest" (nearest texel, no mip levels), "bilinear" (no mip
    /// levels), "trilinear", "anisotropic", "ewa" or "sat"; the other fields keep their defaults.
    static Sampler from_filter_name(const std::string& name);
};

std::string to_string(WrapMode mode);
std::string to_string(TexelFilter filter);
std::string to_string(MipFilter filter);
std::string to_string(FootprintFilter filter);
/// Parse a wrap mode name: repeat, clamp, mirror or border. Throws std::invalid_argument.
WrapMode parse_wrap_mode(const std::string& name);

}  // namespace mipraster
