#pragma once
// The stress suite's coverage oracle: exact top-left sample coverage of a triangle on its own
// snapped 1/256 px vertices, in __int128. Written from DESIGN.md §1–2.1, independent of the
// pipeline's setup and edge code (own snapping, own edge tests, no shared helper).
#include <array>
#include <cstdint>
#include <vector>

#include "mipraster/pipeline/sample_pattern.hpp"

namespace mipraster::stress {

/// A point in 1/256 px units, screen space (x right, y down).
struct FixedPoint {
    std::int64_t x = 0, y = 0;
};

/// Round half to even of a value given in 1/256 px units. Throws std::domain_error for a
/// non-finite value or one of magnitude 2^62 or more (its products would leave __int128).
std::int64_t exact_snap(double units);

/// Whether the sample (sx, sy) (1/256 px units) is inside the triangle: strictly on the interior
/// side of every edge, or on an edge that is top or left (Direct3D rule, y down, any winding).
/// A zero-area triangle covers nothing.
bool exact_covers(const std::array<FixedPoint, 3>& v, std::int64_t sx, std::int64_t sy);

/// Zero area after snapping.
bool exact_degenerate(const std::array<FixedPoint, 3>& v);

/// Adds 1 to counts[(y·W + x)·S + s] for every sample of the W×H viewport the triangle covers;
/// sample s of pixel (x, y) sits at (256x + pattern.x[s], 256y + pattern.y[s]).
void exact_accumulate(const std::array<FixedPoint, 3>& v, int width, int height, const SamplePattern& pattern,
                      std::vector<int>& counts);

/// The documented offsets of a pattern (DESIGN.md §1), for checking the renderer's pattern:
/// center for 1 sample, rotated for "rotated", an n×n grid at ((a+½)/n, (b+½)/n) for n dividing 128.
std::vector<std::array<int, 2>> documented_offsets(PatternKind kind, int samples);

/// Whether the renderer's pattern holds exactly the documented offsets (in any order).
bool pattern_is_documented(const SamplePattern& pattern);

}  // namespace mipraster::stress
