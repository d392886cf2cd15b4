#pragma once
// The pipeline driver: vertex transform → clip → setup → bin → rasterize tiles → resolve.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "mipraster/core/image.hpp"
#include "mipraster/pipeline/draw.hpp"
#include "mipraster/pipeline/error_estimate.hpp"
#include "mipraster/pipeline/framebuffer.hpp"
#include "mipraster/pipeline/resolve.hpp"
#include "mipraster/pipeline/sample_pattern.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/scene/camera.hpp"

namespace mipraster {

/// SSAA shades every sample; MSAA shades once per pixel per triangle and stores the colour to
/// the covered samples (depth is still per sample).
enum class AntiAliasing { ssaa, msaa };

std::string to_string(AntiAliasing aa);
AntiAliasing parse_anti_aliasing(const std::string& name);

struct RenderSettings {
    int width = 0, height = 0;
    int samples = 1;                                ///< samples per pixel, 1…64
    PatternKind pattern = PatternKind::automatic;   ///< see make_sample_pattern
    std::uint64_t pattern_seed = 0;                 ///< for PatternKind::stratified
    AntiAliasing anti_aliasing = AntiAliasing::ssaa;
    int threads = 0;                                ///< 0 = all hardware threads
    glm::vec4 clear_color{0.0f};                    ///< premultiplied linear RGBA
    /// box: the mean of each pixel's samples (tile by tile); others (tent, mitchell, catmull-rom,
    /// lanczos3) weigh the samples of the pixels around it (see resolve_framebuffer). One sample per
    /// pixel runs no resolve whatever the filter.
    ResolveFilter resolve_filter = ResolveFilter::box;
    bool keep_samples = false;                      ///< return the supersample framebuffer too
    bool depth_output = false;                      ///< return RenderResult::depth (when some draw tests depth)
    DerivativeMode derivatives = DerivativeMode::analytic;  ///< uv derivatives of textured draws
    DebugView debug_view = DebugView::none;         ///< replaces the texture lookup of textured draws
    /// Estimate the error from two interleaved halves of the samples (error_estimate.hpp) into
    /// RenderResult::error_map; needs samples ≥ 2.
    bool estimate_error = false;
    /// Empty: render every tile. Otherwise one flag per kTileSize² tile, row-major over
    /// ⌈W/kTileSize⌉ × ⌈H/kTileSize⌉: only flagged tiles are rendered, the others keep the clear
    /// colour (adaptive sampling re-renders the tiles that need more samples).
    std::vector<std::uint8_t> tile_mask;
    /// Empty: render every pixel. Otherwise the row-major indices y·W + x of the only pixels to
    /// render (any order, repeats ignored); the others keep the clear colour and no error. Each
    /// row of listed pixels in a tile is rasterized as one span, after one transform and setup of
    /// the scene (a sparse reference and per-pixel refinement render few pixels with many
    /// samples). Not with tile_mask, nor with a resolve filter wider than a pixel.
    std::vector<std::uint32_t> pixels;
    /// Per 8×8-pixel block, skip a triangle's samples where it covers none, and its depth tests
    /// where it lies behind every depth already stored (they would all fail); a tile no triangle
    /// reaches gets its pixels from the clear values without tile buffers to clear and resolve.
    /// The output and the sample counters are the same either way; false runs the plain
    /// per-sample path, for comparison.
    bool block_skipping = true;
    /// At one sample per pixel and under SSAA, a depth-tested triangle's coverage, weights and
    /// depth tests along a row of pixels run four pixels per vector (sample by sample); under MSAA
    /// (a multiple of four samples, AVX2) a pixel's depth tests run four samples per vector; at one
    /// sample per pixel (AVX2), a triangle narrower than 8 pixels finds its whole box's coverage at
    /// once. The output and counters are the same bits either way; false runs the per-sample path,
    /// for comparison.
    bool sample_rows = true;
    /// Where a tile's triangles overlap kDeferredMinOverdraw deep or more (MSAA: textured draws,
    /// kDeferredMinOverdrawMsaa) and every one of them is of a draw that replaces without an alpha
    /// test, shade only the samples that stay visible: a pre-pass records which triangle each
    /// sample ends up with, then each sample is shaded once (MSAA: each pixel once per triangle it
    /// ends up with, where that triangle's draw shaded it). The image is the same bit for bit, and
    /// so are the counters but shader_invocations; false always shades while rasterizing, for
    /// comparison.
    bool deferred_shading = true;
    /// Textured draws look their texture up sixteen samples at a time in float vectors where the
    /// sampler allows (BatchSampler: bilinear or trilinear, repeat or clamp), each value within
    /// batch_sampling_tolerance of the double-precision reference sample_texture; false calls
    /// the reference for every sample.
    bool batched_lookups = true;
    /// Called as tiles finish with (tiles done, tiles in all); calls are serialized (never
    /// concurrent) but may come from any worker thread. Empty: no progress reports.
    std::function<void(std::size_t, std::size_t)> progress;

    std::string to_string() const;
};

/// Counts and times of one render. Counts do not depend on the thread count. The triangle
/// counters count submitted triangles (a clipped triangle none of whose pieces drew is counted
/// once), except triangles_rasterized, which counts the pieces sent to the rasterizer.
struct RenderStats {
    std::uint64_t triangles_in = 0;        ///< submitted triangles
    std::uint64_t triangles_clipped = 0;   ///< crossed a clip plane and were clipped
    std::uint64_t triangles_outside = 0;   ///< entirely outside the clip volume or the viewport
    std::uint64_t triangles_between_samples = 0;  ///< in the viewport, no sample position in its box
    std::uint64_t triangles_backface = 0;  ///< removed by face culling
    std::uint64_t triangles_degenerate = 0;///< zero area after snapping
    std::uint64_t triangles_nonfinite = 0; ///< non-finite after transform (e.g. a degenerate matrix): dropped
    std::uint64_t triangles_rasterized = 0;///< set-up (sub-)triangles sent to the rasterizer
    /// Samples inside a drawn triangle (whether or not their depth test ran: see
    /// depth_blocks_rejected), of those the ones that passed the depth test and were not discarded
    /// by an alpha test (what an OpenGL occlusion query counts), and colour shader runs.
    std::uint64_t samples_covered = 0, samples_passed = 0, shader_invocations = 0;
    /// (triangle, 8×8-pixel block) pairs whose depth tests were skipped because the triangle lies
    /// behind every depth stored in the block (RenderSettings::block_skipping).
    std::uint64_t depth_blocks_rejected = 0;
    /// Tiles shaded after a visibility pre-pass (RenderSettings::deferred_shading).
    std::uint64_t tiles_deferred = 0;
    /// Tiles no triangle reached, written straight from the clear values without tile buffers
    /// (RenderSettings::block_skipping).
    std::uint64_t tiles_empty = 0;
    int threads = 1;
    double transform_ms = 0, setup_ms = 0;
    double raster_ms = 0;  ///< clear, rasterize, shade, test, blend and resolve, tile by tile
    double total_ms = 0;

    std::string to_string() const;
    /// The counters and times as a JSON object.
    std::string to_json() const;
};

struct RenderResult {
    Image color;              ///< (H, W, 4) linear premultiplied RGBA after resolve
    /// (H, W, 1) view-space depth (−z_view) of each pixel's nearest sample, +inf where no sample was
    /// drawn; only with RenderSettings::depth_output and when some draw tests depth, else empty.
    Image depth;
    Framebuffer framebuffer;  ///< all samples, when RenderSettings::keep_samples
    /// (H, W, 1) per-pixel error estimate (RMS over R, G, B), with RenderSettings::estimate_error.
    Image error_map;
    ErrorEstimate error_estimate;  ///< its summary (zero without estimate_error)
    SamplePattern pattern;
    RenderStats stats;
};

/// Renders the draws in order. Bad input (sizes, sample counts, meshes) throws
/// std::invalid_argument naming it, before any large allocation.
RenderResult render(const std::vector<Draw>& draws, const Camera& camera, const RenderSettings& settings);

/// Settings of rasterize().
struct RasterizeSettings {
    int width = 0, height = 0;
    int samples = 1;                               ///< samples per pixel, 1…64
    PatternKind pattern = PatternKind::automatic;  ///< see make_sample_pattern
    std::uint64_t pattern_seed = 0;
    int threads = 0;                               ///< 0 = all hardware threads
    /// The convention of the clip-space z: opengl (−w ≤ z ≤ w, nearer = smaller) or reverse_z
    /// (0 ≤ z ≤ w, nearer = larger).
    DepthConvention depth_convention = DepthConvention::opengl;
    CullMode cull = CullMode::none;

    std::string to_string() const;
};

/// Per sample: the nearest triangle that covers it and where. Arrays are (H, W, S[, 2]) with
/// sample s of pixel (x, y) at (y·W + x)·S + s.
struct Visibility {
    int width = 0, height = 0, samples = 1;
    std::vector<std::int32_t> triangle_id;  ///< index into the triangles; −1 where none covers the sample
    std::vector<float> barycentrics;        ///< perspective-correct weights of the triangle's 2nd and 3rd vertex
    std::vector<float> depth;               ///< window depth; the clear value (opengl 1, reverse_z 0) where empty
    SamplePattern pattern;
    RenderStats stats;
};

/// The primitive layer: clipping, watertight rasterization and the depth test of triangles given
/// by clip-space vertex positions (no camera, no shading). Barycentrics refer to the submitted
/// triangle even where it was clipped. Non-finite positions and out-of-range indices throw
/// std::invalid_argument naming the element.
Visibility rasterize(const std::vector<glm::dvec4>& clip_positions, const std::vector<glm::uvec3>& triangles,
                     const RasterizeSettings& settings);

}  // namespace mipraster
