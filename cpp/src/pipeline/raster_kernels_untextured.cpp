// Tile kernel instances with Texturing::none.
#include "raster_kernel.hpp"

namespace mipraster::kernels {

TileKernel select_untextured(const PipelineKey& key) { return pick_depth<Texturing::none>(key); }

}  // namespace mipraster::kernels
