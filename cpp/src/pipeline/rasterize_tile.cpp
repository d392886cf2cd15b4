#include "mipraster/pipeline/rasterize_tile.hpp"

#include "raster_kernel.hpp"

namespace mipraster {

TileKernel select_tile_kernel(const PipelineKey& k) {
    if (k.shading == Shading::visibility) {
        switch (k.depth) {
            case DepthFunc::none: return kernels::pick_visibility<DepthFunc::none>(k.samples);
            case DepthFunc::greater: return kernels::pick_visibility<DepthFunc::greater>(k.samples);
            case DepthFunc::less: return kernels::pick_visibility<DepthFunc::less>(k.samples);
        }
    }
    switch (k.texturing) {
        case Texturing::none: return kernels::select_untextured(k);
        case Texturing::fixed: return kernels::select_textured_fixed(k);
        case Texturing::lod: return kernels::select_textured_lod(k);
    }
    return nullptr;
}

OwnedShadingKernel select_owned_shading_kernel(const PipelineKey& k) {
    if (k.shading == Shading::visibility) return nullptr;
    switch (k.texturing) {
        case Texturing::none: return kernels::select_owned_untextured(k);
        case Texturing::fixed: return kernels::select_owned_textured_fixed(k);
        case Texturing::lod: return kernels::select_owned_textured_lod(k);
    }
    return nullptr;
}

}  // namespace mipraster
