#pragma once
// Per-value image comparison with thresholds, in the style of OpenImageIO's idiff: a value fails
// when it differs by more than a threshold; the comparison fails when more than a fraction of the
// values fail, or when any value differs by more than a hard threshold. Golden-image tests use it.
#include <cstddef>
#include <limits>
#include <string>

#include "mipraster/core/image.hpp"

namespace mipraster {

/// Thresholds of compare_images(). Every value of both images is compared (all channels, alpha too).
struct CompareSettings {
    /// A value fails when |actual − expected| > fail_threshold (strictly greater).
    double fail_threshold = 1.0 / 255;
    /// The comparison fails when failing values / values compared > fail_fraction (strictly
    /// greater; 0 = no value may fail). In [0, 1].
    double fail_fraction = 0.0;
    /// The comparison fails when any value differs by more than this (strictly greater), however
    /// few such values there are. +inf disables the hard limit.
    double hard_fail_threshold = 1.0;

    /// Throws std::invalid_argument naming the setting when a threshold is NaN or negative, or
    /// fail_fraction is NaN or outside [0, 1].
    void validate() const;
    std::string to_string() const;
};

/// What compare_images() found. Errors are |actual − expected| computed in double from the float
/// values; two equal values (equal infinities included) differ by 0, and a NaN in either image
/// differs by +inf: it fails, fails hard, and makes max / mean / RMSE +inf and PSNR −inf.
struct CompareReport {
    int width = 0;
    int height = 0;
    int channels = 0;
    std::size_t values_compared = 0;   ///< width · height · channels

    double max_abs_error = 0.0;        ///< largest |a − b|
    double mean_abs_error = 0.0;       ///< mean |a − b| over every value (0 for empty images)
    double rmse = 0.0;                 ///< sqrt(mean (a − b)²)
    /// 10 · log10(1 / mse), the peak value taken as 1.0; +inf when the images are identical.
    double psnr = std::numeric_limits<double>::infinity();

    std::size_t failing_values = 0;        ///< values with |a − b| > fail_threshold (NaN included)
    double failing_fraction = 0.0;         ///< failing_values / values_compared (0 for empty images)
    std::size_t hard_failing_values = 0;   ///< values with |a − b| > hard_fail_threshold (NaN included)
    std::size_t nan_values = 0;            ///< values where either image holds a NaN

    /// The first value (in row-major order) with the largest error; −1 when no value differs.
    int worst_x = -1;
    int worst_y = -1;
    int worst_channel = -1;
    float worst_actual = 0.0f;     ///< actual value there (0 when no value differs)
    float worst_expected = 0.0f;   ///< expected value there (0 when no value differs)

    CompareSettings settings;  ///< the thresholds the verdict used
    bool passed = true;        ///< failing_fraction <= fail_fraction and no hard failure

    /// A short multi-line report: the verdict and why, the worst value, the error metrics.
    std::string to_string() const;
};

/// Compares two images value by value (see CompareSettings for the verdict).
/// Throws std::invalid_argument naming both sizes when width, height or channel count differ, or
/// naming the setting when `settings` is invalid.
CompareReport compare_images(const Image& actual, const Image& expected, const CompareSettings& settings = {});

}  // namespace mipraster
