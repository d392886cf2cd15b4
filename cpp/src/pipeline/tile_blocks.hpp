#pragma once
// What a triangle needs in each 8×8-pixel block of a tile (private to the pipeline): nothing where
// it covers no sample; no depth test where it lies behind every depth stored there (each test would
// fail, and a failed test changes nothing); nothing at all where both hold for all its samples
// (their count is known without them). The output is unchanged bit for bit, counters included.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/framebuffer.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace mipraster {
namespace kernels {

/// Pixels per side of a block: small enough to follow the edges of triangles and of the surfaces in
/// front, large enough that a block's bounds cost little next to the samples they save.
inline constexpr int kBlockShift = 3;
inline constexpr int kBlock = 1 << kBlockShift;
static_assert(kTileSize % kBlock == 0, "blocks must tile a tile");
inline constexpr int kBlocksPerSide = kTileSize / kBlock;
static_assert(kBlocksPerSide * kBlocksPerSide <= 32, "one bit per block of a tile in a uint32");

/// A triangle classifies a block only where its bounding box covers at least this many of the
/// block's pixels: a small triangle pays more for the bounds than the few samples they could skip.
inline constexpr int kBlockMinPixels = 16;
static_assert(kBlockMinPixels >= 1 && kBlockMinPixels <= kBlock * kBlock, "a pixel count");

/// Relative margin of the depth-plane bound: far above the ~1e-15 relative rounding of
/// sample_depth's double arithmetic, far below float depth's 6e-8 resolution.
inline constexpr double kDepthBoundMargin = 1e-9;
static_assert(kDepthBoundMargin > 1e-14 && kDepthBoundMargin < 1e-8, "between double and float resolution");

enum class BlockCoverage { none, some, all };

/// The positions, in 1/256 px, of the samples of a rectangle of pixels: X0 ≤ X ≤ X1, Y0 ≤ Y ≤ Y1.
struct SampleExtent {
    std::int64_t X0, Y0, X1, Y1;
};

/// Whether t covers no sample, some or all samples inside the extent. Edge values are affine, so
/// their extremes over the extent are at the corners the signs of a and b pick; exact in int64.
inline BlockCoverage block_coverage(const SetupTriangle& t, const SampleExtent& r) {
    bool all = true;
    for (int i = 0; i < 3; ++i) {
        const std::int64_t a = t.edge_a[i], b = t.edge_b[i];
        const std::int64_t hi = a * (a >= 0 ? r.X1 : r.X0) + b * (b >= 0 ? r.Y1 : r.Y0) + t.edge_c[i];
        if (hi < 0) return BlockCoverage::none;
        const std::int64_t lo = a * (a >= 0 ? r.X0 : r.X1) + b * (b >= 0 ? r.Y0 : r.Y1) + t.edge_c[i];
        if (lo < 0) all = false;
    }
    return all ? BlockCoverage::all : BlockCoverage::some;
}

/// A float that no sample of t inside the extent has a nearer depth than (sample_depth is ≤ it for
/// greater, ≥ it for less), from the edge values e1, e2 of edges 1 and 2 (without their bias) at
/// the extent's corners X0 Y0, X1 Y0, X0 Y1, X1 Y1. Depth is affine in the screen position, so
/// the plane's extremes over the extent are at its corners; the margin covers rounding, and
/// rounding to float is monotonic. A NaN anywhere makes the bound NaN, which rejects nothing.
template <DepthFunc kDepth>
float nearest_depth(const SetupTriangle& t, const std::int64_t (&e1)[4], const std::int64_t (&e2)[4]) {
    constexpr bool kGreater = kDepth == DepthFunc::greater;
    double nearest = kGreater ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
    double reach = 1.0;  // the largest weight magnitude involved, for the margin
    for (int corner = 0; corner < 4; ++corner) {
        const double l1 = static_cast<double>(e1[corner] + t.bias[1]) * t.inv_area2;
        const double l2 = static_cast<double>(e2[corner] + t.bias[2]) * t.inv_area2;
        const double z = t.z0 + l1 * t.dz1 + l2 * t.dz2;
        if (kGreater ? !(z <= nearest) : !(z >= nearest)) nearest = z;  // keeps a NaN
        reach = std::max({reach, std::abs(l1), std::abs(l2)});
    }
    const double margin = kDepthBoundMargin * (std::abs(t.z0) + 2.0 * reach * (std::abs(t.dz1) + std::abs(t.dz2)));
    return static_cast<float>(kGreater ? nearest + margin : nearest - margin);
}

/// nearest_depth over the samples inside the extent.
template <DepthFunc kDepth>
float nearest_depth(const SetupTriangle& t, const SampleExtent& r) {
    std::int64_t e1[4], e2[4];
    for (int corner = 0; corner < 4; ++corner) {
        const std::int64_t X = corner & 1 ? r.X1 : r.X0, Y = corner & 2 ? r.Y1 : r.Y0;
        e1[corner] = t.edge_a[1] * X + t.edge_b[1] * Y + t.edge_c[1];
        e2[corner] = t.edge_a[2] * X + t.edge_b[2] * Y + t.edge_c[2];
    }
    return nearest_depth<kDepth>(t, e1, e2);
}

/// Whether samples no nearer than `nearest` (nearest_depth) all fail the depth test against stored
/// depths no farther than `farthest`: z > stored (z < stored) cannot hold. False for a NaN.
template <DepthFunc kDepth>
inline bool behind(float nearest, float farthest) {
    return kDepth == DepthFunc::greater ? nearest <= farthest : nearest >= farthest;
}

/// What one triangle needs in the blocks of its bounding box, one bit per block (TileBlocks::bit).
struct BlockClasses {
    std::uint32_t skipped = 0;  ///< no per-pixel work: covers no sample, or covers all and is hidden
    std::uint32_t hidden = 0;   ///< covers some samples, all behind the stored depths: coverage only
    std::uint64_t skipped_samples = 0;  ///< covered samples of the skipped blocks
    int depth_rejected = 0;             ///< blocks, skipped or hidden, that are behind the stored depths
};

/// The blocks of one tile target and the farthest depth stored in each, computed when a triangle
/// first asks and again after a depth write into the block (depth only moves nearer, so a bound
/// computed before later writes stays valid, only looser).
class TileBlocks {
public:
    /// For a target whose pixels hold the first S samples of its pattern.
    TileBlocks(const TileTarget& target, int S)
        : target_(target), bx0_(target.x0 >> kBlockShift), by0_(target.y0 >> kBlockShift) {
        const auto& x = target.pattern->x;
        const auto& y = target.pattern->y;
        ox0_ = *std::min_element(x.begin(), x.begin() + S);
        ox1_ = *std::max_element(x.begin(), x.begin() + S);
        oy0_ = *std::min_element(y.begin(), y.begin() + S);
        oy1_ = *std::max_element(y.begin(), y.begin() + S);
    }

    /// Bit of the block holding pixel (x, y).
    int bit(int x, int y) const { return ((y >> kBlockShift) - by0_) * kBlocksPerSide + (x >> kBlockShift) - bx0_; }
    /// After a depth write at pixel (x, y).
    void written(int x, int y) { known_ &= ~(std::uint32_t{1} << bit(x, y)); }
    /// After depth writes at the pixels x0 + j of row y, bit j of `pixels` (j < kTileSize): once per block.
    void written_row(int y, int x0, std::uint32_t pixels) {
        while (pixels) {
            const int x = x0 + __builtin_ctz(pixels);
            written(x, y);
            const int next_block = (((x >> kBlockShift) + 1) << kBlockShift) - x0;  // its first bit
            pixels = next_block >= 32 ? 0 : pixels & (~std::uint32_t{0} << next_block);  // (no shift by 32)
        }
    }

    /// The bits of the blocks that hold pixels of [x0, x1) × [y0, y1) (inside the target).
    std::uint32_t blocks_in(int x0, int y0, int x1, int y1) const {
        static_assert(kBlocksPerSide == 4, "rows of four bits");
        const int column0 = (x0 >> kBlockShift) - bx0_, column1 = ((x1 - 1) >> kBlockShift) - bx0_;
        const int row0 = (y0 >> kBlockShift) - by0_, row1 = ((y1 - 1) >> kBlockShift) - by0_;
        const std::uint32_t row = (std::uint32_t{2} << column1) - (std::uint32_t{1} << column0);
        // The row repeated at rows row0 … row1: times Σ 16^r = (16^(row1 + 1) − 16^row0) / 15, whose
        // products with a four-bit row do not overlap.
        return row * (((std::uint32_t{16} << 4 * row1) - (std::uint32_t{1} << 4 * row0)) / 15);
    }

    /// Bit j set where pixel (x0 + j, y) lies in a block of `bits` (j < n ≤ 32).
    std::uint32_t row_pixels(std::uint32_t bits, int y, int x0, int n) const {
        const std::uint64_t columns = block_columns(bits, y) >> (x0 - (bx0_ << kBlockShift));
        return static_cast<std::uint32_t>(columns & ((std::uint64_t{1} << n) - 1));
    }

    /// Narrows the pixels [x0, x1) of row y to leave out skipped blocks at either end (x0 ≥ x1
    /// when all of them are).
    void trim(std::uint32_t skipped, int y, int& x0, int& x1) const {
        if (!skipped || x0 >= x1) return;
        const int first = bx0_ << kBlockShift;  // column 0 of block_columns
        const std::uint64_t range = (std::uint64_t{1} << (x1 - first)) - (std::uint64_t{1} << (x0 - first));
        const std::uint64_t kept = range & ~std::uint64_t{block_columns(skipped, y)};
        if (!kept) {
            x0 = x1;
            return;
        }
        x0 = first + __builtin_ctzll(kept);
        x1 = first + 64 - __builtin_clzll(kept);
    }

    /// Classifies the blocks of t's bounding box [x0, x1) × [y0, y1) (clipped to the target) with
    /// S samples per pixel; kDepth none tests coverage only.
    template <DepthFunc kDepth>
    [[gnu::always_inline]] BlockClasses classify(const SetupTriangle& t, int x0, int y0, int x1, int y1, int S) {
        const bool whole = x0 == target_.x0 && y0 == target_.y0 && x1 == target_.x1 && y1 == target_.y1;
        // Fewer pixels than a block needs: no block of the box can be classified (the common case
        // of small triangles, which so skip the call).
        if (!whole && (x1 - x0) * (y1 - y0) < kBlockMinPixels) return {};
        return classify_blocks<kDepth>(t, x0, y0, x1, y1, S, whole);
    }

private:
    // The pixels of the blocks of `bits` on pixel row y's row of blocks: bit c for the column
    // (bx0_ << kBlockShift) + c, each block's bit spread over its kBlock columns (a multiply
    // moves bit b to bit 8b; the four partial products do not overlap, so nothing carries).
    std::uint32_t block_columns(std::uint32_t bits, int y) const {
        static_assert(kBlock == 8 && kBlocksPerSide == 4, "the spread is for a row of four blocks of eight");
        const std::uint32_t row = bits >> (((y >> kBlockShift) - by0_) * kBlocksPerSide) & 0xfu;
        return ((row * 0x204081u) & 0x01010101u) * 0xffu;
    }

    template <DepthFunc kDepth>
    [[gnu::noinline]] BlockClasses classify_blocks(const SetupTriangle& t, int x0, int y0, int x1, int y1, int S,
                                                   bool whole) {
        BlockClasses out;
        // A triangle whose bounding box holds the whole target is tested on the target first: under
        // heavy overdraw most such triangles cover all of it behind everything stored, or none of it.
        BlockCoverage coverage_of_target = BlockCoverage::some;  // (all: every block's is all)
        if (whole && whole_target<kDepth>(t, S, out, coverage_of_target)) return out;
        // The edge functions' parts along x at the first and last sample columns of each column of
        // blocks (a·X), and along y at each row of blocks' (b·Y): an edge value at a block's corner
        // is one of each plus c, the same int64 value block_coverage and nearest_depth compute at
        // the corner (exact), for 16 products per edge instead of 64 for a tile's 16 blocks.
        const int column0 = x0 >> kBlockShift, columns = ((x1 - 1) >> kBlockShift) - column0 + 1;
        const int row0 = y0 >> kBlockShift, rows = ((y1 - 1) >> kBlockShift) - row0 + 1;
        std::int64_t along_x[3][2][kBlocksPerSide], along_y[3][2][kBlocksPerSide];
        int width[kBlocksPerSide], height[kBlocksPerSide];
        for (int c = 0; c < columns; ++c) {
            const int bx = column0 + c;
            const int rx0 = std::max(x0, bx << kBlockShift), rx1 = std::min(x1, (bx + 1) << kBlockShift);
            const std::int64_t X0 = rx0 * kSubpixelOne + ox0_, X1 = (rx1 - 1) * kSubpixelOne + ox1_;  // (extent)
            width[c] = rx1 - rx0;
            for (int i = 0; i < 3; ++i) along_x[i][0][c] = t.edge_a[i] * X0, along_x[i][1][c] = t.edge_a[i] * X1;
        }
        for (int k = 0; k < rows; ++k) {
            const int by = row0 + k;
            const int ry0 = std::max(y0, by << kBlockShift), ry1 = std::min(y1, (by + 1) << kBlockShift);
            const std::int64_t Y0 = ry0 * kSubpixelOne + oy0_, Y1 = (ry1 - 1) * kSubpixelOne + oy1_;
            height[k] = ry1 - ry0;
            for (int i = 0; i < 3; ++i) along_y[i][0][k] = t.edge_b[i] * Y0, along_y[i][1][k] = t.edge_b[i] * Y1;
        }
        for (int k = 0; k < rows; ++k) {
            for (int c = 0; c < columns; ++c) {
                const int pixels = width[c] * height[k];
                if (pixels < kBlockMinPixels) continue;
                const std::uint32_t m = std::uint32_t{1} << ((row0 + k - by0_) * kBlocksPerSide + column0 + c - bx0_);
                // block_coverage: each edge's largest and smallest value at the corners its a and b pick.
                BlockCoverage coverage = coverage_of_target;
                if (coverage != BlockCoverage::all) {
                    coverage = BlockCoverage::all;
                    for (int i = 0; i < 3; ++i) {
                        const bool right = t.edge_a[i] >= 0, down = t.edge_b[i] >= 0;
                        if (along_x[i][right][c] + along_y[i][down][k] + t.edge_c[i] < 0) {
                            coverage = BlockCoverage::none;
                            break;
                        }
                        if (along_x[i][!right][c] + along_y[i][!down][k] + t.edge_c[i] < 0)
                            coverage = BlockCoverage::some;
                    }
                }
                if (coverage == BlockCoverage::none) {
                    out.skipped |= m;
                    continue;
                }
                if constexpr (kDepth != DepthFunc::none) {
                    known_farthest<kDepth>(m);
                    std::int64_t e1[4], e2[4];  // at the corners, in nearest_depth's order
                    for (int corner = 0; corner < 4; ++corner) {
                        e1[corner] = along_x[1][corner & 1][c] + along_y[1][corner >> 1][k] + t.edge_c[1];
                        e2[corner] = along_x[2][corner & 1][c] + along_y[2][corner >> 1][k] + t.edge_c[2];
                    }
                    if (!behind<kDepth>(nearest_depth<kDepth>(t, e1, e2), farthest_[__builtin_ctz(m)])) continue;
                    ++out.depth_rejected;
                    if (coverage == BlockCoverage::some) {
                        out.hidden |= m;
                    } else {
                        out.skipped |= m;
                        out.skipped_samples += static_cast<std::uint64_t>(pixels) * static_cast<std::uint64_t>(S);
                    }
                }
            }
        }
        return out;
    }

    // The samples of the pixels [x0, x1) × [y0, y1).
    SampleExtent extent(int x0, int y0, int x1, int y1) const {
        return {std::int64_t{x0} * kSubpixelOne + ox0_, std::int64_t{y0} * kSubpixelOne + oy0_,
                std::int64_t{x1 - 1} * kSubpixelOne + ox1_, std::int64_t{y1 - 1} * kSubpixelOne + oy1_};
    }

    // When t covers no sample of the target, or covers all and all fail the depth test: every block
    // skipped, and true. `coverage`: t's over the whole target. The samples are counted as the blocks
    // one by one would count them (depth_rejected also counts blocks too thin to classify one by one,
    // at a viewport's edge).
    template <DepthFunc kDepth>
    bool whole_target(const SetupTriangle& t, int S, BlockClasses& out, BlockCoverage& coverage) {
        const SampleExtent r = extent(target_.x0, target_.y0, target_.x1, target_.y1);
        coverage = block_coverage(t, r);
        if (coverage == BlockCoverage::none) {
            out.skipped = blocks_in(target_.x0, target_.y0, target_.x1, target_.y1);
            return true;
        }
        if constexpr (kDepth == DepthFunc::none) return false;
        else {
            if (coverage != BlockCoverage::all) return false;
            const std::uint32_t blocks = blocks_in(target_.x0, target_.y0, target_.x1, target_.y1);
            constexpr bool kGreater = kDepth == DepthFunc::greater;
            const float nearest = nearest_depth<kDepth>(t, r);
            if (!behind<kDepth>(nearest, target_farthest_)) {
                constexpr float kInfinity = std::numeric_limits<float>::infinity();
                float farthest_of_all = kGreater ? kInfinity : -kInfinity;
                for (std::uint32_t m = blocks; m; m &= m - 1) {  // hidden behind every block's farthest depth
                    known_farthest<kDepth>(m & -m);
                    const float farthest = farthest_[__builtin_ctz(m)];
                    if (!behind<kDepth>(nearest, farthest)) return false;
                    farthest_of_all =
                        kGreater ? std::min(farthest_of_all, farthest) : std::max(farthest_of_all, farthest);
                }
                target_farthest_ = farthest_of_all;
            }
            out.skipped = blocks;
            out.skipped_samples = static_cast<std::uint64_t>(target_.x1 - target_.x0) *
                                  static_cast<std::uint64_t>(target_.y1 - target_.y0) * static_cast<std::uint64_t>(S);
            out.depth_rejected = __builtin_popcount(blocks);
            return true;
        }
    }

    // Makes farthest_ of block m current.
    template <DepthFunc kDepth>
    void known_farthest(std::uint32_t m) {
        if (!(known_ & m)) {
            farthest_[__builtin_ctz(m)] = farthest_stored<kDepth>(__builtin_ctz(m));
            known_ |= m;
        }
    }

    // The farthest stored depth of block b within the target: the smallest for greater, the
    // largest for less. Four lanes at a time: stored depths are never NaN (a NaN never passes the
    // test), so the order does not matter (but for the sign of a zero, which compares equal).
    template <DepthFunc kDepth>
    float farthest_stored(int b) const {
        typedef float Four __attribute__((vector_size(16)));
        const auto farther = [](auto a, auto b) {
            return kDepth == DepthFunc::greater ? (b < a ? b : a) : (b > a ? b : a);
        };
        const int bx = bx0_ + b % kBlocksPerSide, by = by0_ + b / kBlocksPerSide;
        const SampleWindow& depth = target_.depth;
        const int x0 = std::max(target_.x0, bx << kBlockShift), x1 = std::min(target_.x1, (bx + 1) << kBlockShift);
        const int y0 = std::max(target_.y0, by << kBlockShift), y1 = std::min(target_.y1, (by + 1) << kBlockShift);
        float f = *depth.at(x0, y0, 0);
        Four lanes = Four{} + f;
        for (int y = y0; y < y1; ++y) {
            const float* p = depth.at(x0, y, 0);
            const float* const end = depth.at(x1 - 1, y, depth.samples - 1) + 1;
            for (; end - p >= 4; p += 4) {
                Four v;
                std::memcpy(&v, p, sizeof v);
                lanes = farther(lanes, v);
            }
            for (; p != end; ++p) f = farther(f, *p);
        }
        for (int i = 0; i < 4; ++i) f = farther(f, lanes[i]);
        return f;
    }

    const TileTarget& target_;
    int bx0_, by0_;
    std::int32_t ox0_, ox1_, oy0_, oy1_;  ///< the extremes of the sample offsets, in 1/256 px
    std::uint32_t known_ = 0;  ///< blocks whose farthest_ is current
    float farthest_[kBlocksPerSide * kBlocksPerSide];
    /// No nearer than the farthest depth of every block of the target (NaN: none known yet). Kept
    /// from the last time whole_target looked at every block: depths written since then only moved
    /// nearer, so it stays a bound, and a triangle behind it is behind every block without the look.
    float target_farthest_ = std::numeric_limits<float>::quiet_NaN();
};

}  // namespace kernels
}  // namespace mipraster
