#pragma once
// Reconstruction filters of the notes' resampling chapter: 1-D kernels applied separably, shared by
// image resampling (core/resample.hpp) and the renderer's resolve (pipeline/resolve.hpp).
#include <string>

namespace mipraster {

/// Separable reconstruction filters, each a 1-D kernel f(x) with x in pixels of the grid it
/// reconstructs (unit spacing) and f integrating to 1.
enum class ReconstructionFilter {
    box,          ///< constant reconstruction: 1 on [−½, ½)
    tent,         ///< linear (bilinear in 2-D): 1 − |x| on (−1, 1)
    mitchell,     ///< Mitchell–Netravali cubic, B = C = ⅓, radius 2
    catmull_rom,  ///< the interpolating cubic, B = 0, C = ½, radius 2
    lanczos3,     ///< sinc(x)·sinc(x/3) on (−3, 3)
};

std::string to_string(ReconstructionFilter filter);
/// "box", "tent", "mitchell", "catmull-rom", "lanczos3"; std::invalid_argument listing them otherwise.
ReconstructionFilter parse_reconstruction_filter(const std::string& name);
/// Every filter's name, in the order of the enum, separated by ", " (for messages and help).
const char* reconstruction_filter_names();

/// Half-width of the kernel's support: f(x) = 0 for |x| ≥ radius (box: for x ≥ ½ and x < −½).
double filter_radius(ReconstructionFilter filter);
/// The kernel at x (pixels of the reconstructed grid).
double filter_weight(ReconstructionFilter filter, double x);

}  // namespace mipraster
