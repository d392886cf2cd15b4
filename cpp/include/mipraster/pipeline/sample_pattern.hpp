#pragma once
// Sample positions inside a pixel, on the 1/256 px grid.
#include <cstdint>
#include <string>
#include <vector>

namespace mipraster {

/// Sample patterns. grid and stratified lay out S samples as C columns × R rows, the most
/// square factorization of S with C ≥ R (N×N for square S; 8 → 4×2; a prime S → S×1).
enum class PatternKind {
    automatic,   ///< center for 1 sample, rotated for 4, grid otherwise
    center,      ///< 1 sample at (½, ½)
    grid,        ///< C×R at ((a+½)/C, (b+½)/R), rounded to 1/256
    rotated,     ///< the standard rotated 4× pattern
    stratified,  ///< C×R strata, one seeded random position in each
};

std::string to_string(PatternKind kind);
/// Parses "auto", "center", "grid", "rotated", "stratified"; throws naming the accepted names.
PatternKind parse_pattern_kind(const std::string& name);

/// Offsets of each sample from the pixel's top-left corner in 1/256 px, each in [0, 256).
struct SamplePattern {
    PatternKind kind = PatternKind::center;
    std::vector<std::int32_t> x, y;
    /// The grid of cells the samples stand for (each sample one cell of 1/columns × 1/rows
    /// pixel): columns × rows for grid and stratified, 2 × 2 for rotated, 1 × 1 for center.
    int columns = 1, rows = 1;

    int count() const { return static_cast<int>(x.size()); }
    std::string to_string() const;
};

/// Builds the pattern of `samples` samples (1…64). rotated needs 4 and center 1; otherwise
/// std::invalid_argument names what was expected.
SamplePattern make_sample_pattern(PatternKind kind, int samples, std::uint64_t seed = 0);

}  // namespace mipraster
