#pragma once
// Shading one sample (private to the pipeline): the colour before texturing, the texture lookup's
// inputs, and the reference lookup, at a sample's screen weights. The scalar path every batched
// one (lookup_queue.hpp, interpolate_batch.hpp) is measured against.
#include <cmath>

#include "mipraster/pipeline/interpolate.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/texture/sample.hpp"

namespace mipraster {
namespace kernels {

// The texture lookup's inputs at screen weights l of pixel (px, py): uv and, for λ, its
// derivatives (per pixel, or per sample cell under SSAA).
template <Texturing kTexturing>
inline UvSample texture_lookup(const DrawInputs& draw, const SetupTriangle& t, const TriangleUvs& uvs,
                               const glm::dvec3& l, int px, int py) {
    constexpr bool kLod = kTexturing == Texturing::lod;
    UvSample s = interpolate_uv<kLod>(t, uvs, l, draw.uv_interpolation);
    if constexpr (kLod) {
        if (draw.derivatives == DerivativeMode::quad) quad_derivatives(t, uvs, draw.uv_interpolation, px, py, s);
        if (draw.footprint_scale != glm::dvec2(1.0)) {  // SSAA: the sample's own cell, not the pixel
            s.dx *= draw.footprint_scale.x;
            s.dy *= draw.footprint_scale.y;
        }
    }
    return s;
}

// The texture's contribution at screen weights l of pixel (px, py), one reference lookup.
template <Texturing kTexturing>
inline glm::vec4 texture_colour(const DrawInputs& draw, const SetupTriangle& t, const TriangleUvs& uvs,
                                const glm::dvec3& l, int px, int py) {
    const UvSample s = texture_lookup<kTexturing>(draw, t, uvs, l, px, py);
    if constexpr (kTexturing == Texturing::lod) {
        if (draw.debug_view == DebugView::uv)
            return glm::vec4(static_cast<float>(s.uv.x - std::floor(s.uv.x)), static_cast<float>(s.uv.y - std::floor(s.uv.y)),
                             0.0f, 1.0f);
        if (draw.debug_view == DebugView::mip_level)
            return mip_level_colour(texture_lod(*draw.texture, *draw.sampler, glm::vec2(s.dx), glm::vec2(s.dy)));
    }
    return sample_texture(*draw.texture, *draw.sampler, glm::vec2(s.uv), glm::vec2(s.dx), glm::vec2(s.dy));
}

// The colour before texturing: the draw colour × the vertex colours.
template <Shading kShading>
inline glm::vec4 untextured_colour(const DrawInputs& draw, const VertexValues& colors, const SetupTriangle& t,
                                   const glm::dvec3& screen, const ClipWeights* clip_weights) {
    if constexpr (kShading == Shading::constant) {
        return draw.color;
    } else if constexpr (kShading == Shading::flat) {
        return draw.color * colors.v[0];
    } else {
        const glm::dvec3 w = kShading == Shading::perspective ? perspective_weights(t, screen) : screen;
        return draw.color * colors.interpolate(original_weights(t, w, clip_weights));
    }
}

template <Shading kShading, Texturing kTexturing>
inline glm::vec4 shade(const DrawInputs& draw, const VertexValues& colors, const TriangleUvs& uvs,
                       const SetupTriangle& t, const glm::dvec3& screen, const ClipWeights* clip_weights, int px,
                       int py) {
    if constexpr (kTexturing == Texturing::lod) {  // a debug view shows its colour unmodulated
        if (draw.debug_view != DebugView::none) return texture_colour<kTexturing>(draw, t, uvs, screen, px, py);
    }
    glm::vec4 c = untextured_colour<kShading>(draw, colors, t, screen, clip_weights);
    if constexpr (kTexturing != Texturing::none) c *= texture_colour<kTexturing>(draw, t, uvs, screen, px, py);
    return c;
}

}  // namespace kernels
}  // namespace mipraster
