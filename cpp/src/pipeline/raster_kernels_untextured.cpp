// Tile kernel instances with Texturing::none.
#include "raster_kernel.hpp"

namespace mipraster::kernels {

TileKernel select_untextured(const PipelineKey& key) { return pick_depth<Texturing::none>(key); }
OwnedShadingKernel select_owned_untextured(const PipelineKey& key) { return pick_owned_shading<Texturing::none>(key); }

}  // namespace mipraster::kernels
