#pragma once
// Every numeric constant of the pipeline, each with why it has its value and a check of its bound.
#include <chrono>
#include <cstddef>
#include <cstdint>

namespace mipraster {

/// Sub-pixel precision of snapped vertex and sample positions: 16.8 fixed point (1/256 px).
inline constexpr int kSubpixelBits = 8;
inline constexpr std::int64_t kSubpixelOne = std::int64_t{1} << kSubpixelBits;

/// Largest framebuffer width or height. Bounds sample coordinates in fixed point.
inline constexpr int kMaxDimension = 32768;

/// Guard band: screen coordinates may lie this far (in pixels) from the viewport centre before
/// the sides are clipped; inside it, triangles are rasterized unclipped.
inline constexpr double kGuardBandPx = double(1 << 20);

/// Largest magnitude of a snapped coordinate (1/256 px units): guard band plus half the viewport.
inline constexpr std::int64_t kMaxFixedCoordinate =
    (std::int64_t{1 << 20} + kMaxDimension) * kSubpixelOne;
// Edge coefficients are differences of two coordinates: they must fit int32 for the stepping loop.
static_assert(2 * kMaxFixedCoordinate < (std::int64_t{1} << 31), "edge coefficients must fit int32");
// An edge value is A·X + B·Y + C with |A|,|B| ≤ 2·max and |X|,|Y|,|C/(2·max)| ≤ 2·max:
// at most 3·(2·max)² in magnitude, which must stay inside int64.
static_assert(2 * kMaxFixedCoordinate < (std::int64_t{1} << 30), "edge values need 4·(2^30)^2 < 2^63");

/// Samples per pixel: coverage of one pixel is a 64-bit mask.
inline constexpr int kMaxSamples = 64;

/// Square screen tile, in pixels: a thread rasterizes whole tiles. 32 px keeps a tile's colour
/// and depth samples (32·32·S·20 bytes) within L2 for S up to 16.
inline constexpr int kTileSize = 32;
static_assert(kTileSize % 8 == 0 && kTileSize <= 256, "tile size must be a small multiple of 8");

/// Deferred shading (RenderSettings::deferred_shading) takes a tile whose triangles' bounding
/// boxes cover it this many times over: below, most samples are shaded once anyway and the
/// pre-pass would only add its owner writes and the second walk over the tile.
inline constexpr double kDeferredMinOverdraw = 1.25;
static_assert(kDeferredMinOverdraw >= 1.0, "deferring pays only where triangles overlap");
/// The same under MSAA, which shades a pixel once per triangle already while its pre-pass tests
/// and records every sample. Measured (README, "Session 34"; 1080p layers of textured quads, one
/// thread): drawn back to front, deferring breaks even at an overdraw of about 1.3 and saves 12 %
/// at 2, 30 % at 4; front to back it costs 6 % without overlap and 16–24 % from 1.5 (a hidden layer
/// costs the pre-pass about 8 ms, the forward kernel about 3.5); in an unsorted order the layers
/// shaded per pixel grow as the harmonic number, which puts the break-even near 1.5. The
/// benchmark's cube (about 1.5) is 4 % faster deferred.
inline constexpr double kDeferredMinOverdrawMsaa = 1.5;
static_assert(kDeferredMinOverdrawMsaa >= kDeferredMinOverdraw, "MSAA gains less from deferring");
/// Untextured shading is cheap, so a tile without textures is deferred only where its overdraw O
/// and the mean area a (px²) its triangles cover of it give (O − 1)²·a ≥ this: tiny triangles at
/// a low overdraw repeat per-triangle work in the pre-pass that the shading they save does not
/// pay for. Measured (README, "Session 15"): many_small, and layers of grids of 2 … 128 px².
inline constexpr double kDeferredMinUntexturedGain = 4.0;

/// Freed large per-render buffers kept for the next buffer of the same size (block_recycler.hpp):
/// each from the smallest size worth it (a 1024×1024 RGBA float image is 16 MiB) to the largest
/// one worth holding on to; at most this many, and at most this many bytes in all (the oldest go
/// first).
inline constexpr int kRecycledBlocks = 16;
inline constexpr std::size_t kMinRecycledBytes = std::size_t{4} << 20;
inline constexpr std::size_t kMaxRecycledBytes = std::size_t{256} << 20;
inline constexpr std::size_t kMaxRecycledTotalBytes = std::size_t{512} << 20;
static_assert(kMinRecycledBytes <= kMaxRecycledBytes && kMaxRecycledBytes <= kMaxRecycledTotalBytes,
              "a block of the largest size fits the total");

/// A render setting up more triangles than this (in bytes of their set-up records) stores the
/// records past the cache (streaming stores): they do not fit it, and ordinary stores would
/// first read each of their lines from memory (many_small 1x −6 %). Fewer stay in the cache for
/// the rasterizer (a 50,000-triangle mesh was 2 % slower streamed).
inline constexpr std::size_t kStreamedSetupBytes = std::size_t{8} << 20;

/// Clipped vertices keep w at least this large so 1/w is finite (the near plane of a sane camera
/// is far above it; it matters only for degenerate user matrices).
inline constexpr double kMinClipW = 1e-30;

/// A clipped triangle whose |w| all lie below this is scaled up before clipping (clip.cpp), so
/// that the absolute kMinClipW does not cut it away; far above kMinClipW, far below the w of a
/// sane camera's geometry.
inline constexpr double kTinyClipScale = 0x1p-64;
static_assert(kTinyClipScale > 1e6 * kMinClipW, "a tiny triangle's w stays clear of kMinClipW once scaled");

/// An edge whose endpoints lie farther out than this many times the smaller |w| of the two
/// crosses a clip plane in binary128 (clip.cpp): their distances from the plane, in double, are
/// off by up to 2⁻⁵³ of their size, which moves a long-double crossing by up to 2⁻²⁷ in x/w and
/// y/w, 2⁻¹² px at the largest image (a triangle of 10²¹ px covered nothing before).
inline constexpr double kWideCrossingRatio = 0x1p26;
static_assert(kWideCrossingRatio * 0x1p-53 * kMaxDimension <= 0x1p-12, "crossings within 2^-12 px on the cheap path");

/// Texel values (after premultiplying) must lie within ±kMaxTexelMagnitude: the filters' float
/// sums then stay finite (a checker of ±1.7·10³⁸ gave infinity and NaN pixels). The largest are
/// an EWA ellipse's taps (at most 256² of weight ≤ 1) and a line of up to 1,024 anisotropic probes
/// summed as differences from the first (each ≤ 2 of the bound). Far beyond any real radiance.
inline constexpr float kMaxTexelMagnitude = 1e32f;

/// The alpha test's cutoff of scene files that give none: glTF's default alphaCutoff (also for a
/// glTF cutoff outside [0, 1]) and OBJ materials with a map_d alpha mask (MTL has no cutoff).
/// Halfway: a mask filtered across its edge keeps the edge where it was.
inline constexpr float kDefaultAlphaCutoff = 0.5f;
static_assert(kDefaultAlphaCutoff > 0.0f && kDefaultAlphaCutoff < 1.0f, "a cutoff that keeps and discards");
static_assert(double(kMaxTexelMagnitude) * 2.0 * 65536.0 < 3.4e38, "the filters' largest sums stay within float");

/// A triangle about to be clipped counts as projecting to a line when its homogeneous 3×3
/// determinant is within this many double epsilons of its permanent: the determinant's own
/// rounding (two products and a difference per minor, three terms) stays below 4 of them, so only
/// triangles thinner than rounding can tell are culled (stress suite, case 8).
inline constexpr double kProjectedAreaRoundingUlps = 8.0;
static_assert(kProjectedAreaRoundingUlps >= 4.0 && kProjectedAreaRoundingUlps <= 64.0,
              "above the determinant's rounding, far below any triangle a snapped sample can see");

/// How long a pool thread that ran out of work watches for more before it sleeps: waking a
/// sleeping thread took tens of microseconds here, and a frame's stages hand work to the pool
/// a few microseconds apart (a 640×480 frame takes under a millisecond on two threads). The spin
/// yields its core every few hundred pauses, so that a busier machine's other threads can run.
inline constexpr std::chrono::microseconds kPoolSpin{100};
static_assert(kPoolSpin.count() > 0 && kPoolSpin.count() <= 1000, "a short spin: idle pools must not burn a core");

/// Most threads a render may ask for.
inline constexpr int kMaxThreads = 256;

/// Error probe (error_probe.hpp): samples per pixel of one reference pass, the most a pass gives.
inline constexpr int kProbeReferenceSpp = kMaxSamples;
/// Reference passes at least: two independent passes are the fewest whose disagreement measures
/// the reference's own error.
inline constexpr int kProbeMinPasses = 2;
/// Reference passes at most (1024 samples per pixel): the probe doubles its passes while the
/// error it measures is unresolved and smaller than its reference's own; 8× its first cost at worst.
inline constexpr int kProbeMaxPasses = 16;
static_assert(kProbeMaxPasses >= 4 * kProbeMinPasses && kProbeMaxPasses % kProbeMinPasses == 0,
              "room to double the passes at least twice");
/// Pixels a probe renders by default at least and at most. At least: enough draws that an error
/// held by 1–3 % of the pixels, where the guide does not point (the checker plane's distance at
/// 1 spp, with no halves map; its horizon rows at 32 spp, where the reference's own noise is as
/// large as the error), is measured within a factor of 2 (README "Error against run time": 150
/// draws missed at 1 spp in 3 of 20 seeds, 512–600 in none; 1024 at 32 spp in 2 of 20, 4096 in
/// none). At most: a bounded cost on large images (4096 × 128 reference samples).
inline constexpr int kProbeMinPixels = 512, kProbeMaxPixels = 4096;
static_assert(kProbeMinPixels >= 2 && kProbeMinPixels <= kProbeMaxPixels, "a spread needs 2 draws");
/// The measured mean squared error counts as resolved when it is this many standard errors above 0
/// (one-sided 97.7 % for a normal estimate); below it, where the reference's own error is larger,
/// the probe adds passes and then reports an upper bound.
inline constexpr double kProbeResolvedStandardErrors = 2.0;
/// A mean squared error this small (RMSE 1e-5 in linear colour, far below an 8-bit step) needs no
/// finer reference: the probe adds no passes to resolve it.
inline constexpr double kProbeNegligibleMse = 1e-10;
static_assert(kProbeNegligibleMse > 0.0 && kProbeNegligibleMse < 1e-8, "below any visible error");

}  // namespace mipraster
