#pragma once
// A draw: a mesh, its model matrix, its material (constant colour, optional base-colour texture and
// sampler) and the fixed-function state it uses.
#include <optional>
#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "mipraster/scene/mesh.hpp"
#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture.hpp"

namespace mipraster {

/// How a fragment combines with the framebuffer (premultiplied linear float; nothing clamps).
enum class BlendMode {
    replace,  ///< dst = src
    add,      ///< dst = dst + src
    over,     ///< dst = src + (1 − src.a)·dst (Porter–Duff over, premultiplied)
};

/// How vertex attributes vary across a triangle.
enum class Interpolation {
    flat,         ///< the first vertex's value everywhere (provoking vertex)
    screen,       ///< affine in screen space (the seeds' "perspective-incorrect" interpolation)
    perspective,  ///< perspective-correct (interpolate a/w and 1/w, divide)
};

/// Face culling. Front faces wind counter-clockwise as seen on screen (OpenGL's default).
enum class CullMode { none, back, front };

std::string to_string(BlendMode mode);
std::string to_string(Interpolation mode);
std::string to_string(CullMode mode);

/// Fixed-function state of one draw.
struct DrawState {
    bool depth_test = true;   ///< compare with the camera's depth convention (GREATER / LESS)
    bool depth_write = true;  ///< store the depth of samples that pass
    BlendMode blend = BlendMode::replace;
    Interpolation interpolation = Interpolation::perspective;
    CullMode cull = CullMode::none;
    /// Alpha testing (glTF alphaMode MASK); none (the default): off. A fragment whose shaded alpha
    /// (draw colour × vertex colour × filtered texture, premultiplied) is below the cutoff, or NaN,
    /// is discarded: it writes neither colour nor depth. One at or above it is written opaque: rgb
    /// divided by its alpha (kept as it is at alpha 0, which only a cutoff of 0 lets through),
    /// alpha 1, then blended as `blend` says. A number in [0, 1].
    std::optional<float> alpha_cutoff;

    /// Throws std::invalid_argument naming `name`.alpha_cutoff when it is NaN or outside [0, 1].
    void validate(const std::string& name) const;
    std::string to_string() const;
};

/// One draw call. The fragment colour is `color` × the interpolated vertex colour (when the mesh
/// has vertex colours) × the texture sampled at the interpolated uv (when `texture` is set; the
/// mesh then needs uvs), all premultiplied linear RGBA. uvs interpolate like colours (the
/// state's interpolation mode). The mesh must outlive the render.
struct Draw {
    const Mesh* mesh = nullptr;
    glm::dmat4 model{1.0};
    glm::vec4 color{1.0f};
    Texture texture;  ///< base colour; empty for an untextured draw
    Sampler sampler;
    DrawState state;

    std::string to_string() const;
};

}  // namespace mipraster
