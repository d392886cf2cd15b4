#pragma once
// Tile rasterization: edge functions stepped over the samples of one screen tile, then depth
// test, shading and blending of covered samples. Specialized at compile time on the features a
// draw uses; select_tile_kernel picks the instance.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/draw.hpp"
#include "mipraster/pipeline/framebuffer.hpp"
#include "mipraster/pipeline/sample_pattern.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"
#include "mipraster/texture/texture.hpp"

namespace mipraster {

enum class DepthFunc { none, greater, less };
/// What a fragment's colour needs: nothing but the draw colour, the provoking vertex's colour,
/// or interpolated vertex colours (screen space or perspective-correct). `visibility` shades
/// nothing: it records which triangle covers each sample and its perspective-correct barycentrics.
enum class Shading { constant, flat, screen, perspective, visibility };
/// single: one sample per pixel; ssaa: shade every sample; msaa: shade once per pixel per triangle.
enum class SampleMode { single, ssaa, msaa };
/// What the texture needs: nothing (untextured: no uv, no derivatives), a lookup without
/// derivatives (the sampler's result does not depend on λ), or a lookup with uv derivatives.
enum class Texturing { none, fixed, lod };

struct PipelineKey {
    DepthFunc depth = DepthFunc::none;
    BlendMode blend = BlendMode::replace;
    Shading shading = Shading::constant;
    SampleMode samples = SampleMode::single;
    Texturing texturing = Texturing::none;
};

/// A triangle that owns samples in deferred shading's pre-pass: the set-up triangle and the clip
/// weights of its chunk.
struct OwnerRef {
    const SetupTriangle* triangle;
    const ClipWeights* clip_weights;
};

/// TileTarget::owner_shade_at of a pixel shaded at its centre.
inline constexpr std::uint8_t kShadeAtCentre = 0xff;

/// The pixel rectangle [x0, x1) × [y0, y1) of one tile and the sample storage it writes: RGBA
/// colour and (when some draw tests depth) depth, each a window that covers the rectangle.
struct TileTarget {
    SampleWindow color, depth;
    const SamplePattern* pattern;
    int x0, y0, x1, y1;
    /// Shading::visibility only: per sample, the original triangle's index (indexed like `depth`)
    /// and the weights of its 2nd and 3rd vertex (a 2-channel window).
    std::int32_t* triangle_ids = nullptr;
    SampleWindow barycentrics;
    /// Per 8×8-pixel block, skip the samples a triangle cannot cover and the depth tests it would
    /// fail everywhere (the output is the same either way; false runs the plain per-sample path).
    bool block_skipping = true;
    /// Depth tested, one sample per pixel or SSAA: rows of pixels through test_sample_row; MSAA:
    /// a pixel's samples through test_pixel_samples_avx2; one sample per pixel: small triangles'
    /// boxes through box_coverage_avx2 (RenderSettings::sample_rows).
    bool sample_rows = true;
    /// Deferred shading only (heavy overdraw, see renderer.cpp). The pre-pass (Shading::visibility with owners set)
    /// records per sample the index into owner_refs of the triangle whose colour the sample ends
    /// up with, or −1; the shading pass then shades each sample once, with that triangle.
    std::int32_t* owners = nullptr;
    std::vector<OwnerRef>* owner_refs = nullptr;
    /// MSAA only, indexed like `owners`: where the owner shades the sample's pixel (MSAA shades a
    /// pixel once per triangle): kShadeAtCentre, or the index of the sample whose position it takes.
    std::uint8_t* owner_shade_at = nullptr;
    /// Sample s of pixel (x, y) in `owners`: the tile's pixels row by row from (x0, y0), kTileSize
    /// per row, S samples each.
    std::size_t owner_index(int x, int y, int s, int S) const {
        return (static_cast<std::size_t>(y - y0) * kTileSize + static_cast<std::size_t>(x - x0)) * static_cast<std::size_t>(S) +
               static_cast<std::size_t>(s);
    }
};

/// Per-draw inputs of the kernel.
struct DrawInputs {
    const glm::uvec3* triangles;
    const glm::vec4* vertex_colors;  ///< null when the mesh has none (then shading is constant)
    glm::vec4 color;
    bool depth_write;
    /// DrawState::alpha_cutoff. When set, the kernel shades before it writes depth: each triangle
    /// takes alpha_tested_triangle (not the sample rows, MSAA's pixel vectors or the lookup queue,
    /// which write depth before the colour is known), and no tile it reaches is deferred.
    std::optional<float> alpha_cutoff = std::nullopt;
    // Texturing only:
    const glm::vec2* uvs = nullptr;
    const TextureView* texture = nullptr;
    const Sampler* sampler = nullptr;
    Interpolation uv_interpolation = Interpolation::perspective;
    DerivativeMode derivatives = DerivativeMode::analytic;
    DebugView debug_view = DebugView::none;
    /// Multiplies the uv derivatives along screen x and y: under SSAA each sample stands for one
    /// cell of its pattern, 1/columns × 1/rows pixel (as if rendered at that finer resolution),
    /// so (1/columns, 1/rows); else (1, 1).
    glm::dvec2 footprint_scale{1.0};
    /// Look textures up kLookupBatch samples at a time in float (BatchSampler: within
    /// batch_sampling_tolerance of sample_texture); false: one sample_texture call per shade,
    /// the reference. Debug views always take the reference path.
    bool batched_lookups = true;
};

/// Triangles of one draw, in submission order: tris[indices[k]] for k < count.
struct TriangleBatch {
    const SetupTriangle* tris;
    const std::uint32_t* indices;
    std::size_t count;
    const ClipWeights* clip_weights;
};

struct TileCounters {
    std::uint64_t samples_covered = 0;  ///< samples inside a triangle
    std::uint64_t samples_passed = 0;   ///< of those, passed the depth test (and any alpha test)
    std::uint64_t shader_invocations = 0;
    std::uint64_t depth_blocks_rejected = 0;  ///< (triangle, 8×8 block) pairs whose depth tests were skipped
    std::uint64_t tiles_deferred = 0;         ///< tiles shaded after a visibility pre-pass
    std::uint64_t tiles_empty = 0;            ///< tiles no triangle reached: written without tile buffers
};

using TileKernel = void (*)(const TileTarget&, const DrawInputs&, const TriangleBatch&, TileCounters&);

TileKernel select_tile_kernel(const PipelineKey& key);

/// Deferred shading's second pass for one draw: shades every sample of the target whose owner
/// (recorded by the pre-pass) is a triangle of draw `draw`, exactly as the forward kernel would
/// have shaded it when that triangle drew it last.
using OwnedShadingKernel = void (*)(const TileTarget&, const DrawInputs&, std::uint32_t draw, TileCounters&);

/// The shading pass for a draw with this key; null where deferred shading would change the image:
/// blending other than replace (the result depends on what lies beneath) and MSAA (its one shade
/// per pixel depends on which samples passed when the triangle was drawn).
OwnedShadingKernel select_owned_shading_kernel(const PipelineKey& key);

}  // namespace mipraster
