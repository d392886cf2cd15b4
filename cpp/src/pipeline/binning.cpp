#include "mipraster/pipeline/binning.hpp"

#include "mipraster/core/constants.hpp"
#include "mipraster/core/huge_pages.hpp"

namespace mipraster {

TileGrid TileGrid::for_viewport(int width, int height) {
    return TileGrid{width, height, (width + kTileSize - 1) / kTileSize, (height + kTileSize - 1) / kTileSize};
}

void bin_triangles(BinnedChunk& chunk, const TileGrid& grid) {
    // Pass 1 counts the entries of each tile, pass 2 places triangle indices in order.
    chunk.tile_start.assign(static_cast<std::size_t>(grid.count()) + 1, 0);
    auto for_each_tile = [&](const SetupTriangle& t, auto&& visit) {
        for (int ty = t.min_y / kTileSize; ty <= t.max_y / kTileSize; ++ty)
            for (int tx = t.min_x / kTileSize; tx <= t.max_x / kTileSize; ++tx) visit(ty * grid.tiles_x + tx);
    };
    for (const SetupTriangle& t : chunk.triangles)
        for_each_tile(t, [&](int tile) { ++chunk.tile_start[static_cast<std::size_t>(tile) + 1]; });
    for (std::size_t i = 1; i < chunk.tile_start.size(); ++i) chunk.tile_start[i] += chunk.tile_start[i - 1];
    reserve_on_huge_pages(chunk.tile_triangles, chunk.tile_start.back());
    chunk.tile_triangles.resize(chunk.tile_start.back());
    std::vector<std::uint32_t> cursor(chunk.tile_start.begin(), chunk.tile_start.end() - 1);
    for (std::uint32_t i = 0; i < chunk.triangles.size(); ++i)
        for_each_tile(chunk.triangles[i], [&](int tile) { chunk.tile_triangles[cursor[tile]++] = i; });
}

}  // namespace mipraster
