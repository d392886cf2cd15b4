// Tile kernel instances with Texturing::fixed.
#include "raster_kernel.hpp"

namespace mipraster::kernels {

TileKernel select_textured_fixed(const PipelineKey& key) { return pick_depth<Texturing::fixed>(key); }
OwnedShadingKernel select_owned_textured_fixed(const PipelineKey& key) { return pick_owned_shading<Texturing::fixed>(key); }

}  // namespace mipraster::kernels
