#pragma once
// The depth test of one triangle at the samples of one pixel under MSAA (private to the pipeline):
// four samples per double vector. Each value is the tile kernel's per-sample arithmetic,
// sample_depth(screen_weights(...)), on the same numbers in the same order (no fused
// multiply-add), so the depths and outcomes are the per-sample path's bits.
#include <cstdint>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace mipraster {
namespace kernels {

/// The samples of one pixel of triangle t: edges 1 and 2 at the pixel's corner (bias not added)
/// and each sample's offset from it, as doubles (exact: offsets are below 2^40).
struct PixelSamples {
    std::int64_t corner1, corner2;
    const double *offset1, *offset2;  // [s] for s < count
    int count;                        // a multiple of 4
};

/// Tests the depth of samples `covered` (bit s: sample s) against depth[s] (less or greater) and
/// stores the passing depths when depth_write; the passing samples go to `passed`. Returns
/// false, touching nothing, when an edge value reaches 2^51 in magnitude (its sums in double
/// could round): the per-sample path then runs. Needs AVX2 (BatchSampler::widest_vector() == 8;
/// elsewhere the kernel keeps the per-sample path).
bool test_pixel_samples_avx2(const SetupTriangle& t, const PixelSamples& p, std::uint64_t covered, DepthFunc func,
                             bool depth_write, float* depth, std::uint64_t& passed);

}  // namespace kernels
}  // namespace mipraster
