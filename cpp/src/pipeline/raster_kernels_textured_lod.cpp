// Tile kernel instances with Texturing::lod.
#include "raster_kernel.hpp"

namespace mipraster::kernels {

TileKernel select_textured_lod(const PipelineKey& key) { return pick_depth<Texturing::lod>(key); }
OwnedShadingKernel select_owned_textured_lod(const PipelineKey& key) { return pick_owned_shading<Texturing::lod>(key); }

}  // namespace mipraster::kernels
