#include "mipraster/stress/exact_coverage.hpp"

#include <algorithm>
#include <cfenv>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mipraster::stress {

namespace {

using i128 = __int128;

constexpr std::int64_t kUnitsPerPixel = 256;

// (b − a) × (p − a): twice the signed area of (a, b, p), y down.
i128 cross(const FixedPoint& a, const FixedPoint& b, std::int64_t px, std::int64_t py) {
    return static_cast<i128>(b.x - a.x) * static_cast<i128>(py - a.y) -
           static_cast<i128>(b.y - a.y) * static_cast<i128>(px - a.x);
}

// Top edge: horizontal with the third vertex below it. Left edge: not horizontal, with the third
// vertex to its right (at larger x than the edge's line at that height).
bool top_or_left(const FixedPoint& a, const FixedPoint& b, const FixedPoint& c) {
    if (a.y == b.y) return c.y > a.y;
    const i128 lhs = static_cast<i128>(c.x - a.x) * static_cast<i128>(b.y - a.y);
    const i128 rhs = static_cast<i128>(c.y - a.y) * static_cast<i128>(b.x - a.x);
    return b.y > a.y ? lhs > rhs : lhs < rhs;
}

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
    std::int64_t q = a / b;
    if (a % b != 0 && a < 0) --q;
    return q;
}

}  // namespace

std::int64_t exact_snap(double units) {
    if (!std::isfinite(units) || std::fabs(units) >= 0x1p62)
        throw std::domain_error("exact_snap: coordinate " + std::to_string(units) + " is not finite or too large");
    if (std::fegetround() != FE_TONEAREST) throw std::logic_error("exact_snap needs round-to-nearest");
    return static_cast<std::int64_t>(std::nearbyint(units));
}

bool exact_degenerate(const std::array<FixedPoint, 3>& v) { return cross(v[0], v[1], v[2].x, v[2].y) == 0; }

bool exact_covers(const std::array<FixedPoint, 3>& v, std::int64_t sx, std::int64_t sy) {
    const i128 area = cross(v[0], v[1], v[2].x, v[2].y);
    if (area == 0) return false;
    for (int i = 0; i < 3; ++i) {
        const FixedPoint &a = v[i], &b = v[(i + 1) % 3], &c = v[(i + 2) % 3];
        i128 e = cross(a, b, sx, sy);
        if (area < 0) e = -e;  // positive inside whatever the winding
        if (e < 0 || (e == 0 && !top_or_left(a, b, c))) return false;
    }
    return true;
}

void exact_accumulate(const std::array<FixedPoint, 3>& v, int width, int height, const SamplePattern& pattern,
                      std::vector<int>& counts) {
    if (exact_degenerate(v)) return;
    const auto [min_x, max_x] = std::minmax({v[0].x, v[1].x, v[2].x});
    const auto [min_y, max_y] = std::minmax({v[0].y, v[1].y, v[2].y});
    const std::int64_t px0 = std::max<std::int64_t>(0, floor_div(min_x, kUnitsPerPixel));
    const std::int64_t px1 = std::min<std::int64_t>(width - 1, floor_div(max_x, kUnitsPerPixel));
    const std::int64_t py0 = std::max<std::int64_t>(0, floor_div(min_y, kUnitsPerPixel));
    const std::int64_t py1 = std::min<std::int64_t>(height - 1, floor_div(max_y, kUnitsPerPixel));
    const int S = pattern.count();
    for (std::int64_t py = py0; py <= py1; ++py)
        for (std::int64_t px = px0; px <= px1; ++px)
            for (int s = 0; s < S; ++s)
                if (exact_covers(v, px * kUnitsPerPixel + pattern.x[s], py * kUnitsPerPixel + pattern.y[s]))
                    ++counts[(static_cast<std::size_t>(py) * width + static_cast<std::size_t>(px)) * S + s];
}

std::vector<std::array<int, 2>> documented_offsets(PatternKind kind, int samples) {
    if (samples == 1) return {{128, 128}};
    if (kind == PatternKind::rotated) return {{96, 32}, {224, 96}, {32, 160}, {160, 224}};
    const int n = static_cast<int>(std::lround(std::sqrt(double(samples))));
    if (n * n != samples || 128 % n != 0) return {};
    std::vector<std::array<int, 2>> out;
    for (int b = 0; b < n; ++b)
        for (int a = 0; a < n; ++a) out.push_back({(2 * a + 1) * 128 / n, (2 * b + 1) * 128 / n});
    return out;
}

bool pattern_is_documented(const SamplePattern& pattern) {
    std::vector<std::array<int, 2>> want = documented_offsets(pattern.kind, pattern.count()), got;
    for (int s = 0; s < pattern.count(); ++s) got.push_back({pattern.x[s], pattern.y[s]});
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    return !want.empty() && want == got;
}

}  // namespace mipraster::stress
