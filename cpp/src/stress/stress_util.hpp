#pragma once
// Shared pieces of the stress cases: number formatting, coverage renders (additive white, so a
// sample's red value counts the triangles covering it) and their comparison with the exact
// coverage oracle, and the scenes the determinism case renders again.
#include <cstdint>
#include <memory>
#include <array>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>

#include "mipraster/pipeline/renderer.hpp"
#include "mipraster/scene/mesh.hpp"
#include "mipraster/stress/stress_row.hpp"

namespace mipraster::stress {

/// "%.3g"-style text of a number.
std::string fmt(double value, int digits = 3);
/// Thousands-grouped integer.
std::string count(std::uint64_t n);

/// Model matrix from (X, Y) in 1/256 px units (y down) to NDC of a W×H viewport with an identity
/// camera. For power-of-two W and H each step is exact in double, so the pipeline's snapped
/// position is X rounded, the same as the oracle's.
glm::dmat4 fixed_to_ndc(int width, int height);
/// Identity view and projection (OpenGL convention): clip space is the model matrix's output.
Camera identity_camera();

/// A scene the cases render and the determinism case renders again at other thread counts.
struct StressScene {
    std::string name;
    std::vector<std::shared_ptr<Mesh>> meshes;  ///< kept alive for the draws
    std::vector<Draw> draws;
    Camera camera;
    RenderSettings settings;
};

/// An additive, untested-depth draw of a mesh given in 1/256 px units: coverage counts.
StressScene coverage_scene(std::string name, std::shared_ptr<Mesh> mesh, int width, int height, int samples,
                           PatternKind pattern = PatternKind::automatic);

/// Sample-for-sample comparison of a coverage render with the exact oracle on the mesh's own
/// snapped vertices (float positions read as double, rounded half to even).
struct CoverageComparison {
    std::uint64_t samples = 0;          ///< samples compared
    std::uint64_t oracle_covered = 0;   ///< samples the oracle covers at least once
    std::uint64_t oracle_twice = 0;     ///< samples the oracle covers more than once
    std::uint64_t cracks = 0;           ///< oracle covers once or more, render 0
    std::uint64_t double_hits = 0;      ///< render > oracle
    std::uint64_t mismatches = 0;       ///< render ≠ oracle
    bool pattern_ok = true;             ///< the render used the documented sample offsets
    bool finite = true;                 ///< every sample value finite
};
CoverageComparison compare_coverage(const StressScene& scene, const RenderResult& result);

/// Render with the scene's settings.
RenderResult render_scene(const StressScene& scene);

// Scene builders (also rendered by the determinism case).
/// Jittered n×n grid of quads (random diagonals and windings) spanning [x0, x1]×[y0, y1] px.
std::shared_ptr<Mesh> jittered_grid_mesh(int nx, int ny, double x0, double y0, double x1, double y1, bool integer_units,
                                         std::uint64_t seed);
/// A fan of n triangles around (cx, cy) px with rim radius r px, alternate windings.
std::shared_ptr<Mesh> fan_mesh(double cx, double cy, double r, int n);
/// Slivers `length` px long and `width` px wide at `count` angles through the viewport.
std::shared_ptr<Mesh> sliver_mesh(int width_px, int height_px, double length, double width, int count, std::uint64_t seed);

/// Triangles given in clip space for the primitive layer (rasterize()).
struct ClipScene {
    std::string name;
    std::vector<glm::dvec4> clip;
    std::vector<glm::uvec3> triangles;
    RasterizeSettings settings;
};
/// Triangles with vertices `radius` px from a point of a W×W viewport, one edge through it (w = 1,
/// double precision); `units` receives each triangle's vertices in 1/256 px screen units.
ClipScene huge_scene(int width, double radius, int count, std::uint64_t seed,
                     std::vector<std::array<glm::dvec2, 3>>* units = nullptr);

/// The textured grazing plane of case 6 (also in the determinism case).
StressScene grazing_scene(double angle_degrees, int width, int height, int samples);
/// The depth case's scene: two offset tilted quads, nearer one drawn first or last.
StressScene depth_scene(bool reverse_z, double near, double far, double distance, double separation, bool near_first,
                        int size);
/// The near-plane case's clip-space triangles (w → 0⁺, w = 0, w < 0, grazing), OpenGL convention.
ClipScene near_plane_scene(int width, int samples);

}  // namespace mipraster::stress
