#pragma once
// The stress suite (issue 6): twelve cases that push each stage to its limits and measure a
// figure against an independent oracle (exact_coverage.hpp, clip_ray_cast.hpp, closed forms).
// Each returns one or more rows; none throws for a failed bound (the row says FAIL).
#include <functional>
#include <vector>

#include "mipraster/stress/stress_row.hpp"

namespace mipraster {

/// 1. Conforming grids, random meshes and fans at S = 1 and 16: cracks and double hits vs the exact reference.
std::vector<StressRow> stress_watertight(StressSize size);
/// 2. Slivers 10⁴ px long and 10⁻³ px wide at every angle: coverage vs the exact reference.
std::vector<StressRow> stress_slivers(StressSize size);
/// 3. Vertices at ±10⁶, ±10⁹, ±10¹² px: clipped coverage vs the exact reference; edge bit budget.
std::vector<StressRow> stress_huge_coordinates(StressSize size);
/// 4. Near-plane crossings, w → 0⁺, w = 0, w < 0: visible part vs a clip-space ray cast; NaN/Inf count.
std::vector<StressRow> stress_near_plane(StressSize size);
/// 5. Coplanar-offset quads: fraction correctly ordered, reverse-Z cameras vs OpenGL matrices.
std::vector<StressRow> stress_depth(StressSize size);
/// 6. A textured plane at 80°…89.99°: λ finite and monotonic, anisotropy clamped, error vs the box footprint.
std::vector<StressRow> stress_grazing_texture(StressSize size);
/// 7. Zero, infinite, NaN and mixed derivatives; uv at ±10⁸ with repeat wrap (precision measured).
std::vector<StressRow> stress_derivatives(StressSize size);
/// 8. Collinear, repeated-vertex and snapped-to-zero triangles: no coverage, no NaN.
std::vector<StressRow> stress_degenerate(StressSize size);
/// 9. Textures 1×1, 1×N, 3×5, non-power-of-two, 16384² (full): lookups at the borders in every wrap mode vs a reference.
std::vector<StressRow> stress_texture_sizes(StressSize size);
/// 10. A triangle moved in 1/256 px steps: coverage monotonic and equal to the exact reference.
std::vector<StressRow> stress_subpixel_motion(StressSize size);
/// 11. Tilted quads out to 10⁶ × near: perspective-correct weights and depth vs the ray cast.
std::vector<StressRow> stress_interpolation(StressSize size);
/// 12. The scenes above at 1, 2 and 4 threads: bit-identical samples.
std::vector<StressRow> stress_determinism(StressSize size);

/// Every case in order; `on_row` (optional) is called as each row is ready.
std::vector<StressRow> run_stress_suite(StressSize size, const std::function<void(const StressRow&)>& on_row = {});

}  // namespace mipraster
