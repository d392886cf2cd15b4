#pragma once
// Summed-area table of one level (the seeds' SAT) for box-filtered lookups.
#include <cstddef>
#include <vector>

#include <glm/vec4.hpp>

#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture_level.hpp"

namespace mipraster {

/// Prefix sums of (texel − mean) in double, (w+1)×(h+1) entries with a zero first row and
/// column. Subtracting the mean first keeps the sums small, so a box far from the origin of a
/// large texture keeps its precision and a constant texture averages to itself exactly.
struct SummedAreaTable {
    int width = 0, height = 0;
    glm::dvec4 mean{0.0};
    std::vector<glm::dvec4> sums;

    explicit SummedAreaTable(const TextureLevel& level);
    std::size_t bytes() const { return sums.size() * sizeof(glm::dvec4); }

    /// Mean of the texture over the box [x0, x1] × [y0, y1] in texel units of this level (the
    /// texture piecewise constant per texel), with the sampler's wrap modes and border colour.
    /// Needs x0 < x1 and y0 < y1, all finite.
    glm::dvec4 box_mean(double x0, double y0, double x1, double y1, const Sampler& sampler) const;

private:
    // ∫∫ over [0, x] × [0, y] of (texel − mean) for 0 ≤ x ≤ width, 0 ≤ y ≤ height (bilinear in the table).
    glm::dvec4 integral_from_origin(double x, double y) const;
};

/// Bytes the table of a w×h level needs.
std::size_t summed_area_table_bytes(int width, int height);

}  // namespace mipraster
