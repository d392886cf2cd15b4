#include "mipraster/pipeline/binning.hpp"

#include <algorithm>
#include <cmath>

#include "mipraster/core/constants.hpp"
#include "mipraster/core/huge_pages.hpp"
#include "tile_blocks.hpp"

namespace mipraster {

TileGrid TileGrid::for_viewport(int width, int height) {
    return TileGrid{width, height, (width + kTileSize - 1) / kTileSize, (height + kTileSize - 1) / kTileSize};
}

namespace {

// The area (pixels) of the rectangle [x0, x1) × [y0, y1) on t's inner side of all three edges:
// the rectangle clipped by each edge's half-plane in turn (Sutherland–Hodgman, in double on 1/256 px
// coordinates), then the shoelace formula. A convex polygon gains at most a corner per clip: ≤ 7.
double clipped_area(const SetupTriangle& t, int x0, int y0, int x1, int y1) {
    struct Point {
        double x, y;
    };
    constexpr double kOne = kSubpixelOne;
    Point polygon[8] = {{x0 * kOne, y0 * kOne}, {x1 * kOne, y0 * kOne}, {x1 * kOne, y1 * kOne}, {x0 * kOne, y1 * kOne}};
    int n = 4;
    for (int e = 0; e < 3; ++e) {
        const auto value = [&](const Point& p) {
            return double(t.edge_a[e]) * p.x + double(t.edge_b[e]) * p.y + double(t.edge_c[e]);
        };
        Point kept[8];
        int m = 0;
        for (int k = 0; k < n; ++k) {
            const Point p = polygon[k], q = polygon[(k + 1) % n];
            const double vp = value(p), vq = value(q);
            if (vp >= 0.0) kept[m++] = p;
            if ((vp >= 0.0) != (vq >= 0.0)) {
                const double s = vp / (vp - vq);
                kept[m++] = {p.x + s * (q.x - p.x), p.y + s * (q.y - p.y)};
            }
        }
        if (m < 3) return 0.0;
        std::copy(kept, kept + m, polygon);
        n = m;
    }
    double twice_area = 0.0;
    for (int k = 0; k < n; ++k) {
        const Point p = polygon[k], q = polygon[(k + 1) % n];
        twice_area += p.x * q.y - q.x * p.y;
    }
    return std::abs(twice_area) / (2.0 * kOne * kOne);
}

// The share of its bounding box t fills, times the part [bx0, bx1) × [by0, by1) of the box.
inline double box_share(const SetupTriangle& t, int bx0, int by0, int bx1, int by1) {
    constexpr double kPixelArea2 = 2.0 * double(kSubpixelOne) * double(kSubpixelOne);  // 2A units per px²
    const double box = double(t.max_x + 1 - t.min_x) * double(t.max_y + 1 - t.min_y);
    const double fill = std::min(1.0, 1.0 / (t.inv_area2 * kPixelArea2 * box));
    return double(bx1 - bx0) * double(by1 - by0) * fill;
}

// A bounding box strictly inside the rectangle holds the vertices (bounds are the floors of their
// positions, and a clamp to the viewport lands on the rectangle's edge), so t covers some of it
// and not all: only a box reaching an edge needs the corner tests.
inline bool box_inside(const SetupTriangle& t, int x0, int y0, int x1, int y1) {
    return t.min_x > x0 && t.max_x + 1 < x1 && t.min_y > y0 && t.max_y + 1 < y1;
}

// A bounding box no wider and no taller than a tile, narrower or shorter than the rectangle: t is
// small and cannot hold the rectangle, and its box share is estimate enough even where t misses
// the rectangle (over the tiles its box reaches, the shares add up to its area).
inline bool small_box_cannot_hold(const SetupTriangle& t, int x0, int y0, int x1, int y1) {
    const int w = t.max_x + 1 - t.min_x, h = t.max_y + 1 - t.min_y;
    return w <= kTileSize && h <= kTileSize && (w < x1 - x0 || h < y1 - y0);
}

}  // namespace

double tile_overlap_area(const SetupTriangle& t, int x0, int y0, int x1, int y1) {
    const int bx0 = std::max(t.min_x, x0), bx1 = std::min(t.max_x + 1, x1);
    const int by0 = std::max(t.min_y, y0), by1 = std::min(t.max_y + 1, y1);
    if (bx0 >= bx1 || by0 >= by1) return 0.0;
    if (!box_inside(t, x0, y0, x1, y1) && !small_box_cannot_hold(t, x0, y0, x1, y1)) {
        const kernels::SampleExtent extent{std::int64_t{x0} * kSubpixelOne, std::int64_t{y0} * kSubpixelOne,
                                           std::int64_t{x1} * kSubpixelOne - 1, std::int64_t{y1} * kSubpixelOne - 1};
        const kernels::BlockCoverage coverage = kernels::block_coverage(t, extent);
        if (coverage == kernels::BlockCoverage::none) return 0.0;
        if (coverage == kernels::BlockCoverage::all) return double(x1 - x0) * double(y1 - y0);
        // A triangle wider or taller than a tile that covers part of it: its bounding box says
        // little (clamped to the viewport, it can be smaller than the triangle), so clip.
        if (t.max_x + 1 - t.min_x > kTileSize || t.max_y + 1 - t.min_y > kTileSize) return clipped_area(t, x0, y0, x1, y1);
    }
    return box_share(t, bx0, by0, bx1, by1);
}

static_assert((kMaxDimension + kTileSize - 1) / kTileSize <= 65536, "tile coordinates must fit 16 bits");

ChunkBinner::ChunkBinner(BinnedChunk& chunk, const TileGrid& grid, bool overlap_areas, double enough_overdraw)
    : chunk_(chunk), grid_(grid), overlap_areas_(overlap_areas), enough_overdraw_(enough_overdraw) {
    chunk.tile_start.assign(static_cast<std::size_t>(grid.count()) + 1, 0);
    chunk.tile_area.assign(overlap_areas ? static_cast<std::size_t>(grid.count()) : 0, 0.0);
    reserve_on_huge_pages(spans_, chunk.triangles.capacity());
}

void ChunkBinner::add(const SetupTriangle& t) {
    // (Bounds lie inside the viewport, ≥ 0: an unsigned division, a shift without a sign fix-up.)
    const auto tile_of = [](int pixel) { return static_cast<std::uint16_t>(static_cast<unsigned>(pixel) / kTileSize); };
    const TileSpan span{tile_of(t.min_x), tile_of(t.min_y), tile_of(t.max_x), tile_of(t.max_y)};
    spans_.push_back(span);
    if (span.x0 == span.x1 && span.y0 == span.y1) {  // most small triangles: one tile
        const std::size_t tile = static_cast<std::size_t>(span.y0) * grid_.tiles_x + span.x0;
        ++chunk_.tile_start[tile + 1];
        if (!overlap_areas_) return;
        // A box off the viewport's edges was not clamped to it, so it holds the vertices: t lies
        // in the tile and covers some of it, not all (tile_overlap_area's last case, inline).
        const bool unclamped = t.min_x > 0 && t.min_y > 0 && t.max_x + 1 < grid_.width && t.max_y + 1 < grid_.height;
        const int x0 = span.x0 * kTileSize, y0 = span.y0 * kTileSize;
        chunk_.tile_area[tile] += unclamped ? box_share(t, t.min_x, t.min_y, t.max_x + 1, t.max_y + 1)
                                            : tile_overlap_area(t, x0, y0, std::min(x0 + kTileSize, grid_.width),
                                                                std::min(y0 + kTileSize, grid_.height));
        return;
    }
    for (int ty = span.y0; ty <= span.y1; ++ty)
        for (int tx = span.x0; tx <= span.x1; ++tx) {
            const std::size_t tile = static_cast<std::size_t>(ty) * grid_.tiles_x + tx;
            ++chunk_.tile_start[tile + 1];
            if (!overlap_areas_) continue;
            const int x0 = tx * kTileSize, y0 = ty * kTileSize;
            const int x1 = std::min(x0 + kTileSize, grid_.width), y1 = std::min(y0 + kTileSize, grid_.height);
            double& sum = chunk_.tile_area[tile];
            const double enough = enough_overdraw_ * (double(x1 - x0) * double(y1 - y0));
            if (sum < enough) sum += tile_overlap_area(t, x0, y0, x1, y1);
        }
}

void ChunkBinner::finish() {
    std::vector<std::uint32_t>& start = chunk_.tile_start;
    for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    reserve_on_huge_pages(chunk_.tile_triangles, start.back());
    chunk_.tile_triangles.resize(start.back());
    std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
    for (std::uint32_t i = 0; i < spans_.size(); ++i) {
        const TileSpan span = spans_[i];
        if (span.x0 == span.x1 && span.y0 == span.y1) {  // (most small triangles: without the loops)
            chunk_.tile_triangles[cursor[static_cast<std::size_t>(span.y0) * grid_.tiles_x + span.x0]++] = i;
            continue;
        }
        for (int ty = span.y0; ty <= span.y1; ++ty)
            for (int tx = span.x0; tx <= span.x1; ++tx)
                chunk_.tile_triangles[cursor[static_cast<std::size_t>(ty) * grid_.tiles_x + tx]++] = i;
    }
}

void bin_triangles(BinnedChunk& chunk, const TileGrid& grid, bool overlap_areas, double enough_overdraw) {
    ChunkBinner binner(chunk, grid, overlap_areas, enough_overdraw);
    for (const SetupTriangle& t : chunk.triangles) binner.add(t);
    binner.finish();
}

}  // namespace mipraster
