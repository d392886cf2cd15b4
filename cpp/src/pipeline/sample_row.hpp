#pragma once
// One triangle along one sample of each pixel of a row (private to the pipeline): coverage, screen
// weights and the depth test, four pixels at a time in double vectors. Each value is the tile kernel's
// per-sample arithmetic on the same numbers in the same order (no fused multiply-add), so the
// coverage, weights, depths and test outcomes are the per-sample path's bits.
#include <cstdint>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace mipraster {
namespace kernels {

/// Rows shorter than this take the per-sample path: a vector pass costs more than a few samples.
inline constexpr int kSampleRowMinPixels = 8;

static_assert(kTileSize <= 32, "a tile row's pixels fit a 32-bit mask");

/// What test_sample_row found along a row of n ≤ kTileSize pixels; bit j is pixel j.
struct SampleRow {
    std::uint32_t covered;  ///< the pixel's sample is inside the triangle
    std::uint32_t passed;   ///< covered, asked for, and its depth test passed (depth stored if writing)
    double l0[kTileSize], l1[kTileSize], l2[kTileSize];  ///< screen weights where passed
};

/// Whether test_sample_row takes the row of every sample of pixels j < n whose first pixel's
/// corner has edge values `corner` (bias not added): true only where no sample's row is refused.
bool sample_rows_exact(const SetupTriangle& t, const std::int64_t (&corner)[3], int n);

/// Triangle t over one sample of pixels j < n of a row, whose first pixel's sample has edge values
/// e (bias not added). Tests depth (less or greater) at the pixels of `tested` against
/// depth[j·stride] (stride: the pixels' samples), storing the passing depths when depth_write;
/// with func none every covered pixel of `tested` passes and depth is neither read nor written.
/// Returns false, touching nothing, when an edge value along the row reaches 2^52 in magnitude
/// (its sums in double could round): the per-sample path then runs.
bool test_sample_row(const SetupTriangle& t, const std::int64_t (&e)[3], int n, std::uint32_t tested, DepthFunc func,
                     bool depth_write, float* depth, int stride, SampleRow& out);

/// test_sample_row on two doubles per vector (SSE2, every x86-64 CPU) and on four (AVX2, only where
/// the CPU has it): the same bits. test_sample_row takes the widest the CPU has.
bool test_sample_row_sse2(const SetupTriangle& t, const std::int64_t (&e)[3], int n, std::uint32_t tested,
                          DepthFunc func, bool depth_write, float* depth, int stride, SampleRow& out);
bool test_sample_row_avx2(const SetupTriangle& t, const std::int64_t (&e)[3], int n, std::uint32_t tested,
                          DepthFunc func, bool depth_write, float* depth, int stride, SampleRow& out);

/// test_sample_row for four samples of a pixel whose depths lie side by side (depth[j·stride + k]
/// for sample k of pixel j, stride a multiple of 4), sample k's edge values at the first pixel
/// e[k]: out[k] gets sample k's row, the same bits as four calls. Returns false, touching nothing,
/// where one of those calls would. Needs AVX2.
bool test_four_sample_rows_avx2(const SetupTriangle& t, const std::int64_t (&e)[4][3], int n, std::uint32_t tested,
                                DepthFunc func, bool depth_write, float* depth, int stride, SampleRow (&out)[4]);

/// Triangle t over every sample of pixels j < n of a row under MSAA, whose first pixel's corner has
/// edge values `corner` (bias not added; sample_rows_exact must hold), a pixel's S samples (a
/// multiple of 4) four per vector: sample s moves edge i from the corner by offsets[i][s]. Tests
/// depth (less or greater) at the covered samples against depth[j·S + s], storing the passing
/// depths when depth_write; samples[j] gets pixel j's passed samples. Where tested_depths is not
/// null, tested_depths[j·S + s] gets the depth the test computed for each covered sample s (the
/// others: unspecified). Returns the counts of the row. The per-sample path's bits (as
/// test_sample_row); needs AVX2.
struct PixelRowTest {
    std::uint64_t covered = 0;  ///< samples inside the triangle
    std::uint64_t passed = 0;   ///< samples that passed the depth test
    std::uint32_t pixels = 0;   ///< bit j: pixel j has a passed sample (samples[j] != 0)
};
PixelRowTest test_pixel_row_avx2(const SetupTriangle& t, const std::int64_t (&corner)[3], int n,
                                 const double* const (&offsets)[3], int S, DepthFunc func, bool depth_write,
                                 float* depth, std::uint64_t* samples, float* tested_depths = nullptr);

/// The screen weights of pixels j < n of a row whose first pixel's sample has edge values e (bias
/// not added), into l_i[j] (room for n rounded up to a multiple of 4): screen_weights' bits. False,
/// touching nothing, where test_sample_row would be. Two doubles per vector (SSE2) or four (AVX2,
/// where the CPU has it): the same bits; sample_row_weights takes the widest.
bool sample_row_weights(const SetupTriangle& t, const std::int64_t (&e)[3], int n, double* l0, double* l1, double* l2);
bool sample_row_weights_sse2(const SetupTriangle& t, const std::int64_t (&e)[3], int n, double* l0, double* l1,
                             double* l2);
bool sample_row_weights_avx2(const SetupTriangle& t, const std::int64_t (&e)[3], int n, double* l0, double* l1,
                             double* l2);

/// Set bits of a mask (baseline x86-64 has no popcnt instruction; GCC would call libgcc).
[[gnu::always_inline]] inline int count_bits(std::uint32_t m) {
    m = m - ((m >> 1) & 0x55555555u);
    m = (m & 0x33333333u) + ((m >> 2) & 0x33333333u);
    return static_cast<int>((((m + (m >> 4)) & 0x0F0F0F0Fu) * 0x01010101u) >> 24);
}
[[gnu::always_inline]] inline int count_bits(std::uint64_t m) {
    return count_bits(static_cast<std::uint32_t>(m)) + count_bits(static_cast<std::uint32_t>(m >> 32));
}

}  // namespace kernels
}  // namespace mipraster
