#include "mipraster/texture/summed_area_table.hpp"

#include <algorithm>
#include <cmath>

namespace mipraster {

std::size_t summed_area_table_bytes(int width, int height) {
    return (static_cast<std::size_t>(width) + 1) * (static_cast<std::size_t>(height) + 1) * sizeof(glm::dvec4);
}

SummedAreaTable::SummedAreaTable(const TextureLevel& level)
    : width(level.width), height(level.height),
      sums((static_cast<std::size_t>(width) + 1) * (static_cast<std::size_t>(height) + 1), glm::dvec4(0.0)) {
    glm::dvec4 total(0.0);
    for (const glm::vec4& t : level.texels) total += glm::dvec4(t);
    mean = total / (static_cast<double>(width) * height);
    const std::size_t stride = static_cast<std::size_t>(width) + 1;
    for (int y = 0; y < height; ++y) {
        glm::dvec4 row(0.0);
        for (int x = 0; x < width; ++x) {
            row += glm::dvec4(level.at(x, y)) - mean;
            sums[(y + 1) * stride + x + 1] = sums[y * stride + x + 1] + row;
        }
    }
}

glm::dvec4 SummedAreaTable::integral_from_origin(double x, double y) const {
    // The integral of a piecewise-constant texture is bilinear within each texel cell, so
    // bilinear interpolation of the table is exact at fractional positions.
    const int ix = std::min(static_cast<int>(x), width - 1), iy = std::min(static_cast<int>(y), height - 1);
    const double fx = x - ix, fy = y - iy;
    const std::size_t stride = static_cast<std::size_t>(width) + 1;
    const glm::dvec4* r0 = &sums[iy * stride + ix];
    const glm::dvec4* r1 = r0 + stride;
    const glm::dvec4 top = r0[0] + fx * (r0[1] - r0[0]);
    const glm::dvec4 bottom = r1[0] + fx * (r1[1] - r1[0]);
    return top + fy * (bottom - top);
}

namespace {

// The integral along one axis from 0 to x of a texture of n texels, as a combination of table
// coordinates in [0, n]: Σ coef·I(coordinate), where I is the in-texture integral from 0.
struct Term {
    double coef, at;
};
struct AxisIntegral {
    Term terms[3];
    int count = 0;
    void add(double coef, double at) { terms[count++] = {coef, at}; }
};

// For clamp, the edge texel extends: beyond n the integral grows by (x − n)·(I(n) − I(n − 1)).
AxisIntegral cumulative(double x, int n, WrapMode mode) {
    AxisIntegral r;
    switch (mode) {
        case WrapMode::repeat: {
            const double q = std::floor(x / n);
            r.add(q, n);
            r.add(1.0, std::clamp(x - q * n, 0.0, double(n)));
            break;
        }
        case WrapMode::mirror: {
            const double q = std::floor(x / (2.0 * n));
            const double rem = std::clamp(x - q * 2.0 * n, 0.0, 2.0 * n);
            if (rem <= n) {
                r.add(2.0 * q, n);
                r.add(1.0, rem);
            } else {  // the mirrored half: 2·I(n) − I(2n − rem)
                r.add(2.0 * q + 2.0, n);
                r.add(-1.0, 2.0 * n - rem);
            }
            break;
        }
        case WrapMode::clamp:
            if (x < 0.0) {
                r.add(x, 1.0);  // x·(I(1) − I(0)), I(0) = 0
            } else if (x <= n) {
                r.add(1.0, x);
            } else {
                r.add(1.0 + (x - n), n);
                r.add(-(x - n), n - 1.0);
            }
            break;
        case WrapMode::border:  // outside the texture is the border colour, added separately
            r.add(1.0, std::clamp(x, 0.0, double(n)));
            break;
    }
    return r;
}

}  // namespace

glm::dvec4 SummedAreaTable::box_mean(double x0, double y0, double x1, double y1, const Sampler& sampler) const {
    const AxisIntegral u[2] = {cumulative(x1, width, sampler.wrap_u), cumulative(x0, width, sampler.wrap_u)};
    const AxisIntegral v[2] = {cumulative(y1, height, sampler.wrap_v), cumulative(y0, height, sampler.wrap_v)};
    glm::dvec4 sum(0.0);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            const double sign = a == b ? 1.0 : -1.0;
            for (int i = 0; i < u[a].count; ++i)
                for (int j = 0; j < v[b].count; ++j)
                    sum += sign * u[a].terms[i].coef * v[b].terms[j].coef *
                           integral_from_origin(u[a].terms[i].at, v[b].terms[j].at);
        }
    // The table holds texel − mean: add the mean back over the part of the box on the texture,
    // and the border colour over the rest.
    const double area = (x1 - x0) * (y1 - y0);
    auto inside = [](double lo, double hi, int n, WrapMode mode) {
        return mode == WrapMode::border ? std::clamp(hi, 0.0, double(n)) - std::clamp(lo, 0.0, double(n)) : hi - lo;
    };
    const double on_texture = inside(x0, x1, width, sampler.wrap_u) * inside(y0, y1, height, sampler.wrap_v);
    const glm::dvec4 total = sum + on_texture * mean + (area - on_texture) * glm::dvec4(sampler.border_color);
    return total / area;
}

}  // namespace mipraster
