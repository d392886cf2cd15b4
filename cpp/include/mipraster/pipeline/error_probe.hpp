#pragma once
// A render's error measured against a sparse reference: a few hundred of its pixels rendered
// again at reference quality. The CLI (--stats, --error-map) and Python (render(...,
// estimate_error=True), adaptive quality) both call measure_error, so they report the same numbers.
//
// The halves estimate (error_estimate.hpp) says *where* a render is uncertain, but it cannot see
// error both halves share (a mip-mapped filter's blur, MSAA's one shade per pixel), it is noisy
// with few samples and gives nothing at one sample per pixel. The probe says *how much*:
//
// 1. Choose n pixels i.i.d. with probability p_i = ½/N + ½·g_i/Σg, g the error_guide (edges,
//    texture detail, the halves map): half the draws are uniform, so error the guide misses is
//    still found. The generator is seeded; the choice does not depend on the thread count.
// 2. Render those pixels again (RenderSettings::pixels) in K passes of 64 stratified samples of
//    their own seeds, SSAA, every texture read at level 0 with bilinear: each sample is a point of
//    the pixel's box-filtered footprint integral, the quantity the study's references integrate.
//    The reference R_i is the passes' mean; v_i² = Σ_k (R_i^k − R_i)²/(K·(K − 1)) estimates its
//    own squared error without bias. K = max(2, spp/16), so the reference stays finer than the render.
// 3. d_i² = mean over R, G, B of (render_i − R_i)² − v_i² estimates the pixel's squared error
//    without bias, MSE = (1/n)·Σ d_k²/(N·p_k) the image's; the terms' spread its standard error.
// 4. Resolution. When the MSE is not kProbeResolvedStandardErrors standard errors above zero and
//    the reference's own squared error is larger than it (the reference's noise hides the
//    render's error), the passes double (up to kProbeMaxPasses) and the estimate is made again.
//    If the reference still hides it, the probe reports an upper bound: rmse = √(max(MSE, 0) +
//    2·SE), upper_bound = true ("rmse <= x"). An MSE that is noisy only because few pixels were
//    drawn stays a point estimate with its standard error (more passes would not help).
// 5. Reuse. The reference of a drawn pixel depends on the seed, the pass and the pixel only, not
//    on the image measured: a ProbeReference keeps the draws and their passes, so that a later
//    probe of another image of the same scene (adaptive quality, after a refinement pass) renders
//    no reference pixel again and gives exactly what a fresh probe of the same draws would.
#include <cstdint>
#include <string>
#include <vector>

#include "mipraster/core/image.hpp"
#include "mipraster/pipeline/draw.hpp"
#include "mipraster/pipeline/renderer.hpp"
#include "mipraster/scene/camera.hpp"

namespace mipraster {

/// What the sparse reference measured.
struct ErrorProbe {
    double rmse = 0;            ///< estimated RMSE of the image (linear R, G, B); an upper bound when upper_bound
    double standard_error = 0;  ///< of rmse (delta method; √(SE of the MSE) when the MSE is near 0)
    bool upper_bound = false;   ///< the reference's own error hid the render's: its RMSE is at most rmse
    int pixels = 0;             ///< draws n (a pixel drawn twice counts twice)
    int distinct_pixels = 0;    ///< pixels rendered again
    int reference_spp = 0;      ///< samples per pixel of the reference (all passes)
    int rendered_passes = 0;    ///< reference passes this probe rendered (0: all reused from a ProbeReference)
    double reference_rmse = 0;  ///< the reference's own estimated RMSE over the image
    double halves_rmse = -1;    ///< RMS of the halves map; −1 without one
    double ms = 0;              ///< wall time of the probe (choice, reference passes, arithmetic)

    std::string to_string() const;
};

/// The draws of a probe and their reference passes (step 5): filled by the first measure_error
/// given it, reused by later ones.
struct ProbeReference {
    int width = 0, height = 0;              ///< of the image the draws were made for
    std::uint64_t seed = 0;                 ///< the probe's seed (the passes' pattern seeds derive from it)
    std::vector<std::uint32_t> chosen;      ///< the draws, pixel indices y·W + x
    std::vector<double> probability;        ///< p of each draw
    std::vector<std::uint32_t> distinct;    ///< the pixels drawn, sorted
    std::vector<std::size_t> slot;          ///< each draw's index in distinct
    int passes = 0;                         ///< reference passes rendered so far
    std::vector<double> mean, m2;           ///< per distinct pixel and R, G, B: the passes' mean, Σ squared deviations

    bool empty() const { return passes == 0; }
    std::string to_string() const;
};

/// Reference passes of 64 samples the probe of a render with `spp` samples per pixel starts with:
/// max(2, spp/16).
int probe_reference_passes(int spp);

/// Pixels a probe renders by default: a quarter of the render's samples at
/// probe_reference_passes(spp) × 64 samples each, within [kProbeMinPixels, kProbeMaxPixels].
int default_probe_pixels(int width, int height, int spp);

/// Where error is likely, (H, W, 1) ≥ 0: the largest squared half colour step (mean over R, G, B)
/// to the 4 neighbours, plus the halves map (H, W, 1) squared and averaged over each pixel's 3×3
/// neighbourhood when `halves_map` is given (an edge pixel whose halves happen to agree lies next
/// to one whose halves do not). Throws std::invalid_argument naming a map of the wrong size.
Image error_guide(const Image& color, const Image* halves_map);

/// The draws with every texture read at level 0 with bilinear reconstruction (wrap, border and
/// everything else kept): the probe's reference.
std::vector<Draw> reference_draws(const std::vector<Draw>& draws);

/// Estimates the RMSE of `color` (H, W, ≥3, linear), the render of `draws` through `camera` with
/// `settings` (its size, threads, clear colour, derivatives, debug view and samples per pixel are
/// used), from `pixels` pixels rendered again at reference quality. `halves_map` (H, W, 1) is the
/// render's halves map or null; `guide` is error_guide(color, halves_map) when the caller has it,
/// else null; `seed` makes another choice. `reuse`, when given and filled, supplies the draws and
/// the reference passes instead (`pixels`, `seed` and the guide are then not used; passes are added
/// to it when needed); when given empty, it is filled. Throws std::invalid_argument naming a bad
/// input (probe_pixels < 1, a map of the wrong size, colour with fewer than 3 channels, a `reuse`
/// made for another image size).
ErrorProbe measure_error(const std::vector<Draw>& draws, const Camera& camera, const RenderSettings& settings,
                         const Image& color, const Image* halves_map, int pixels, std::uint64_t seed,
                         const Image* guide = nullptr, ProbeReference* reuse = nullptr);

/// Scales `error_map` (the halves map the probe was given) so that its RMS is the probe's RMSE;
/// leaves a map that is zero everywhere as it is.
void calibrate_error_map(Image& error_map, const ErrorProbe& probe);

}  // namespace mipraster
