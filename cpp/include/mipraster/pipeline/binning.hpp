#pragma once
// Binning stage: set-up triangles sorted into screen tiles, keeping submission order per tile.
#include <cstdint>
#include <limits>
#include <vector>

#include "mipraster/core/block_recycler.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace mipraster {

/// The screen split into kTileSize × kTileSize pixel tiles, row-major.
struct TileGrid {
    int width = 0, height = 0;  ///< viewport size in pixels
    int tiles_x = 0, tiles_y = 0;

    static TileGrid for_viewport(int width, int height);
    int count() const { return tiles_x * tiles_y; }
};

/// Runs of submitted triangles after setup (one draw's, or several small draws'), with their
/// per-tile lists (CSR layout:
/// the triangles touching tile i are tile_triangles[tile_start[i] … tile_start[i+1]), ascending).
/// Processing chunks in order and each tile list in order is submission order, however the
/// triangles were split into chunks. (On cache lines of its own: threads set up neighbouring
/// chunks at once, and each appended triangle changes its vector's end; sharing a line with the
/// neighbour's vectors cost a third of the two-thread setup.)
struct alignas(kBlockAlignment) BinnedChunk {
    RecycledVector<SetupTriangle> triangles;
    std::vector<ClipWeights> clip_weights;
    std::vector<std::uint32_t> tile_start;
    RecycledVector<std::uint32_t> tile_triangles;
    /// Per tile, about how many pixels of it the chunk's triangles cover, overlaps counted again
    /// (tile_overlap_area): what deciding on deferred shading sums. Empty when not asked for.
    std::vector<double> tile_area;
    bool one_draw = true;  ///< every triangle is of one draw (else a tile's list changes draw in runs)
};

/// About how many pixels of the rectangle [x0, x1) × [y0, y1) t covers: none when its bounding box
/// misses the rectangle; else all of them when t holds the whole rectangle, none when it misses it,
/// its area clipped to the rectangle when it is wider or taller than a tile, else its bounding box
/// within the rectangle times the share of its whole bounding box it fills. That last estimate is
/// also all that a triangle no wider and no taller than a tile gets where its box is narrower or
/// shorter than the rectangle (it cannot hold it): over the tiles such a box reaches, the estimates
/// add up to the triangle's area.
double tile_overlap_area(const SetupTriangle& t, int x0, int y0, int x1, int y1);

/// Bins a chunk while setup makes its triangles (a counting sort): add() counts each new
/// triangle's tiles (and, when `overlap_areas`, adds up chunk.tile_area) from the set-up record
/// at hand, finish() places them in chunk.tile_start / tile_triangles from each triangle's tile
/// range, kept in 8 bytes. No pass reads the triangles back: a million of them are 128 MB, and
/// reading them from memory twice was a sixth of a frame. Triangles whose bounds reach past one tile
/// add nothing more to a tile's sum once it reaches `enough_overdraw` times the tile's area: where
/// no more is asked of it (a textured tile is deferred from kDeferredMinOverdraw on), summing their
/// clipped areas would be work for nothing (a tenth of a frame of 1,000 large overlapping triangles).
class ChunkBinner {
public:
    ChunkBinner(BinnedChunk& chunk, const TileGrid& grid, bool overlap_areas,
                double enough_overdraw = std::numeric_limits<double>::infinity());
    /// Counts t, the triangle that becomes chunk.triangles[n] for the n-th call.
    void add(const SetupTriangle& t);
    /// Fills chunk.tile_start and chunk.tile_triangles (after the last add()).
    void finish();

private:
    struct TileSpan {  // tiles x0 … x1, y0 … y1 (inclusive)
        std::uint16_t x0, y0, x1, y1;
    };
    BinnedChunk& chunk_;
    const TileGrid& grid_;
    bool overlap_areas_;
    double enough_overdraw_;
    RecycledVector<TileSpan> spans_;
};

/// All of chunk.triangles at once: ChunkBinner's add() for each, then finish().
void bin_triangles(BinnedChunk& chunk, const TileGrid& grid, bool overlap_areas,
                   double enough_overdraw = std::numeric_limits<double>::infinity());

}  // namespace mipraster
