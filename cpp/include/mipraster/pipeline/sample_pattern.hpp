#pragma once
// Sample positions inside a pixel, on the 1/256 px grid.
#include <cstdint>
#include <string>
#include <vector>

namespace mipraster {

enum class PatternKind {
    automatic,   ///< center for 1 sample, rotated for 4, grid for other squares
    center,      ///< 1 sample at (½, ½)
    grid,        ///< N×N at ((a+½)/N, (b+½)/N), rounded to 1/256
    rotated,     ///< the standard rotated 4× pattern
    stratified,  ///< N×N strata, one seeded random position in each
};

std::string to_string(PatternKind kind);
/// Parses "auto", "center", "grid", "rotated", "stratified"; throws naming the accepted names.
PatternKind parse_pattern_kind(const std::string& name);

/// Offsets of each sample from the pixel's top-left corner in 1/256 px, each in [0, 256).
struct SamplePattern {
    PatternKind kind = PatternKind::center;
    std::vector<std::int32_t> x, y;

    int count() const { return static_cast<int>(x.size()); }
    std::string to_string() const;
};

/// Builds the pattern of `samples` samples (1…64). grid and stratified need a square count,
/// rotated needs 4, center needs 1; otherwise std::invalid_argument names what was expected.
SamplePattern make_sample_pattern(PatternKind kind, int samples, std::uint64_t seed = 0);

}  // namespace mipraster
