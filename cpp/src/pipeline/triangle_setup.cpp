#include "mipraster/pipeline/triangle_setup.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "mipraster/core/constants.hpp"

namespace mipraster {

namespace {

// ⌊v / 256⌋ for negative v too.
std::int64_t floor_to_pixel(std::int64_t v) {
    return v >= 0 ? v / kSubpixelOne : -((-v + kSubpixelOne - 1) / kSubpixelOne);
}

}  // namespace

bool setup_triangle(const std::array<glm::dvec4, 3>& p, const Viewport& viewport, CullMode cull, SetupTriangle& out,
                    SetupCounters& counters) {
    const std::array<ScreenVertex, 3> v = {project_vertex(p[0], viewport), project_vertex(p[1], viewport),
                                           project_vertex(p[2], viewport)};
    return setup_triangle(v, viewport, cull, out, counters);
}

bool setup_triangle(const std::array<ScreenVertex, 3>& v, const Viewport& viewport, CullMode cull, SetupTriangle& out,
                    SetupCounters& counters) {
    // Step 1: the projected, snapped vertices.
    if (!(v[0].valid() && v[1].valid() && v[2].valid())) {
        ++counters.dropped_nonfinite;
        return false;
    }
    const std::int64_t X[3] = {v[0].x, v[1].x, v[2].x}, Y[3] = {v[0].y, v[1].y, v[2].y};

    // Step 2: orientation and culling. In y-down coordinates area2 > 0 means the triangle
    // appears clockwise (on screen and in NDC alike: the flip changes the formula's sign, not
    // the picture), so front faces (counter-clockwise) have area2 < 0.
    std::int64_t area2 = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
    if (area2 == 0) {
        ++counters.culled_degenerate;
        return false;
    }
    if ((cull == CullMode::back && area2 > 0) || (cull == CullMode::front && area2 < 0)) {
        ++counters.culled_backface;
        return false;
    }

    // Step 3: bounds in pixels: those with a sample position inside the triangle's box. Pixel px
    // holds its samples at px·256 + [sample_x0, sample_x1], so it is one from
    // ⌈(min X − sample_x1) / 256⌉ to ⌊(max X − sample_x0) / 256⌋. A box that meets no pixel of the
    // viewport is outside it; one that meets some but no sample position, between the samples.
    const std::int64_t lo_x = std::min({X[0], X[1], X[2]}), hi_x = std::max({X[0], X[1], X[2]});
    const std::int64_t lo_y = std::min({Y[0], Y[1], Y[2]}), hi_y = std::max({Y[0], Y[1], Y[2]});
    if (floor_to_pixel(hi_x) < 0 || floor_to_pixel(lo_x) >= viewport.width || floor_to_pixel(hi_y) < 0 ||
        floor_to_pixel(lo_y) >= viewport.height) {
        ++counters.culled_outside;
        return false;
    }
    const std::int64_t to_first_x = kSubpixelOne - 1 - viewport.sample_x1;
    const std::int64_t to_first_y = kSubpixelOne - 1 - viewport.sample_y1;
    const std::int64_t min_x = std::max<std::int64_t>(floor_to_pixel(lo_x + to_first_x), 0);
    const std::int64_t max_x = std::min<std::int64_t>(floor_to_pixel(hi_x - viewport.sample_x0), viewport.width - 1);
    const std::int64_t min_y = std::max<std::int64_t>(floor_to_pixel(lo_y + to_first_y), 0);
    const std::int64_t max_y = std::min<std::int64_t>(floor_to_pixel(hi_y - viewport.sample_y0), viewport.height - 1);
    if (min_x > max_x || min_y > max_y) {
        ++counters.culled_between_samples;
        return false;
    }

    // Step 4: edge equations, oriented so the inside is positive whatever the winding, with the
    // top-left rule: a sample exactly on an edge belongs to the triangle only if the edge is a
    // left edge (inside to its right: a > 0) or a top edge (horizontal, inside below: a = 0, b > 0).
    const std::int64_t sign = area2 > 0 ? 1 : -1;
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3, k = (i + 2) % 3;  // edge j → k is opposite vertex i
        const std::int64_t a = sign * (Y[j] - Y[k]);
        const std::int64_t b = sign * (X[k] - X[j]);
        const std::int64_t c = -(a * X[j] + b * Y[j]);
        const bool top_left = a > 0 || (a == 0 && b > 0);
        out.edge_a[i] = static_cast<std::int32_t>(a);
        out.edge_b[i] = static_cast<std::int32_t>(b);
        out.bias[i] = top_left ? 0 : 1;
        out.edge_c[i] = c - out.bias[i];
    }
    out.min_x = static_cast<std::int32_t>(min_x);
    out.max_x = static_cast<std::int32_t>(max_x);
    out.min_y = static_cast<std::int32_t>(min_y);
    out.max_y = static_cast<std::int32_t>(max_y);
    out.inv_area2 = 1.0 / static_cast<double>(sign * area2);

    // Step 5: depth (affine in screen space) and 1/w planes. Depth is interpolated over the snapped
    // triangle from a value at each vertex: its depth moved along the depth plane to where the
    // vertex snapped, so that every sample's depth is the unsnapped plane's there (up to
    // rounding). From the vertices' own depths, two surfaces 10⁻⁶ apart whose vertices snapped to
    // different points could swap. The gradient is the unsnapped triangle's; a shift is at most the
    // triangle's depth range (only a near-degenerate unsnapped triangle would go beyond).
    double z[3] = {v[0].depth, v[1].depth, v[2].depth};
    {
        double px[3], py[3];  // the unsnapped positions, in 1/256 px
        for (int i = 0; i < 3; ++i) px[i] = double(X[i]) - v[i].snap_x, py[i] = double(Y[i]) - v[i].snap_y;
        const double ex1 = px[1] - px[0], ey1 = py[1] - py[0], ex2 = px[2] - px[0], ey2 = py[2] - py[0];
        const double dz1 = z[1] - z[0], dz2 = z[2] - z[0], inverse = 1.0 / (ex1 * ey2 - ey1 * ex2);
        // ∂z/∂x and ∂z/∂y per 1/256 px:
        const double gx = (dz1 * ey2 - dz2 * ey1) * inverse, gy = (dz2 * ex1 - dz1 * ex2) * inverse;
        const double range = std::max({z[0], z[1], z[2]}) - std::min({z[0], z[1], z[2]});
        for (int i = 0; i < 3; ++i) {
            const double shift = gx * v[i].snap_x + gy * v[i].snap_y;
            // (0: the same bits; not finite: an unsnapped triangle of no area, left as it is)
            if (shift != 0.0 && std::isfinite(shift)) z[i] += std::clamp(shift, -range, range);
        }
    }
    out.z0 = z[0];
    out.dz1 = z[1] - z[0];
    out.dz2 = z[2] - z[0];
    // 1/w enters only ratios (perspective weights, uv and its derivatives), so the three values are
    // scaled by the power of two that brings the largest to [1, 2). That is exact: where 1/w fits a
    // float nothing changes, and where it does not the values stay in range (a camera matrix scaled
    // by 10^46 gave 1/w = 0 at every vertex, and NaN colours). A value below float's normal range
    // (a vertex 2^126 times farther than another) is raised to its smallest, so that Σ λ_i/w_i > 0
    // at every sample.
    const double largest = std::max({v[0].inv_w, v[1].inv_w, v[2].inv_w});
    std::uint64_t bits;
    std::memcpy(&bits, &largest, sizeof bits);
    // largest = m·2^(E − 1023), m ∈ [1, 2), with E its exponent field; the scale 2^(1023 − E) has
    // the field 2046 − E, which is ≥ 1 (a normal double) because largest = 1/w < 2^1023.
    bits = (2046 - (bits >> 52)) << 52;
    double scale;
    std::memcpy(&scale, &bits, sizeof scale);
    for (int i = 0; i < 3; ++i)
        out.inv_w[i] = std::max(static_cast<float>(v[i].inv_w * scale), std::numeric_limits<float>::min());
    return true;
}

}  // namespace mipraster
