#include "mipraster/core/reconstruction_filter.hpp"

#include <cmath>
#include <stdexcept>

namespace mipraster {

namespace {

// The Mitchell–Netravali family (1988): a piecewise cubic with parameters B and C.
double bc_cubic(double x, double b, double c) {
    x = std::fabs(x);
    if (x < 1.0)
        return ((12.0 - 9.0 * b - 6.0 * c) * x * x * x + (-18.0 + 12.0 * b + 6.0 * c) * x * x + (6.0 - 2.0 * b)) / 6.0;
    if (x < 2.0)
        return ((-b - 6.0 * c) * x * x * x + (6.0 * b + 30.0 * c) * x * x + (-12.0 * b - 48.0 * c) * x +
                (8.0 * b + 24.0 * c)) / 6.0;
    return 0.0;
}

double sinc(double x) {
    if (x == 0.0) return 1.0;
    if (x == std::round(x)) return 0.0;  // exact zeros at the other integers (sin(πk) rounds to ~1e-16)
    const double px = M_PI * x;
    return std::sin(px) / px;
}

// Lanczos lobes: 3 is the usual compromise between sharpness and ringing.
constexpr double kLanczosLobes = 3.0;
static_assert(kLanczosLobes >= 1.0, "a Lanczos window has at least one lobe");

}  // namespace

std::string to_string(ReconstructionFilter filter) {
    switch (filter) {
        case ReconstructionFilter::box: return "box";
        case ReconstructionFilter::tent: return "tent";
        case ReconstructionFilter::mitchell: return "mitchell";
        case ReconstructionFilter::catmull_rom: return "catmull-rom";
        case ReconstructionFilter::lanczos3: return "lanczos3";
    }
    return "unknown";
}

const char* reconstruction_filter_names() { return "box, tent, mitchell, catmull-rom, lanczos3"; }

ReconstructionFilter parse_reconstruction_filter(const std::string& name) {
    for (ReconstructionFilter f : {ReconstructionFilter::box, ReconstructionFilter::tent, ReconstructionFilter::mitchell,
                                   ReconstructionFilter::catmull_rom, ReconstructionFilter::lanczos3})
        if (name == to_string(f)) return f;
    throw std::invalid_argument("filter: unknown name '" + name + "'; expected one of " +
                                reconstruction_filter_names());
}

double filter_radius(ReconstructionFilter filter) {
    switch (filter) {
        case ReconstructionFilter::box: return 0.5;
        case ReconstructionFilter::tent: return 1.0;
        case ReconstructionFilter::mitchell:
        case ReconstructionFilter::catmull_rom: return 2.0;
        case ReconstructionFilter::lanczos3: return kLanczosLobes;
    }
    return 0.0;
}

double filter_weight(ReconstructionFilter filter, double x) {
    switch (filter) {
        case ReconstructionFilter::box: return x >= -0.5 && x < 0.5 ? 1.0 : 0.0;  // half-open: one pixel per point
        case ReconstructionFilter::tent: return std::fabs(x) < 1.0 ? 1.0 - std::fabs(x) : 0.0;
        case ReconstructionFilter::mitchell: return bc_cubic(x, 1.0 / 3.0, 1.0 / 3.0);
        case ReconstructionFilter::catmull_rom: return bc_cubic(x, 0.0, 0.5);
        case ReconstructionFilter::lanczos3:
            return std::fabs(x) < kLanczosLobes ? sinc(x) * sinc(x / kLanczosLobes) : 0.0;
    }
    return 0.0;
}

}  // namespace mipraster
