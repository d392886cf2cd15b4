#include "mipraster/texture/texture_level.hpp"

#include <algorithm>
#include <cmath>

namespace mipraster {

int mip_level_count(int width, int height) {
    int levels = 1;
    for (int size = std::max(width, height); size > 1; size /= 2) ++levels;
    return levels;
}

namespace {

// Weights of the source texels under each output cell along one axis: output i covers
// [i·r, (i+1)·r) with r = n/m; texel j's weight is its overlap with the cell, divided by r.
struct AxisTaps {
    std::vector<int> first;                 // first source texel of each output texel
    std::vector<std::vector<double>> weights;
};

AxisTaps axis_taps(int n, int m) {
    AxisTaps taps;
    taps.first.resize(m);
    taps.weights.resize(m);
    const double r = static_cast<double>(n) / m;
    for (int i = 0; i < m; ++i) {
        // Cell bounds as exact rationals (i·n/m): compare in integers to find the texels.
        const int lo = static_cast<int>((static_cast<long long>(i) * n) / m);
        const int hi = static_cast<int>((static_cast<long long>(i + 1) * n + m - 1) / m);  // exclusive
        taps.first[i] = lo;
        for (int j = lo; j < hi; ++j) {
            const double a = std::max<double>(j, i * r), b = std::min<double>(j + 1, (i + 1) * r);
            taps.weights[i].push_back((b - a) / r);
        }
    }
    return taps;
}

}  // namespace

TextureLevel downsample(const TextureLevel& source) {
    const int w = std::max(1, source.width / 2), h = std::max(1, source.height / 2);
    const AxisTaps tx = axis_taps(source.width, w), ty = axis_taps(source.height, h);
    TextureLevel out(w, h);
    std::vector<glm::dvec4> row(static_cast<std::size_t>(w));
    for (int y = 0; y < h; ++y) {
        std::fill(row.begin(), row.end(), glm::dvec4(0.0));
        for (std::size_t b = 0; b < ty.weights[y].size(); ++b) {
            const int sy = ty.first[y] + static_cast<int>(b);
            const double wy = ty.weights[y][b];
            for (int x = 0; x < w; ++x) {
                glm::dvec4 sum(0.0);
                for (std::size_t a = 0; a < tx.weights[x].size(); ++a)
                    sum += tx.weights[x][a] * glm::dvec4(source.at(tx.first[x] + static_cast<int>(a), sy));
                row[x] += wy * sum;
            }
        }
        for (int x = 0; x < w; ++x) out.at(x, y) = glm::vec4(row[x]);
    }
    return out;
}

}  // namespace mipraster
