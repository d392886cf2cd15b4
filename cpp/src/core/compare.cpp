#include "mipraster/core/compare.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace mipraster {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string num(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.6g", v);
    return buffer;
}

std::string percent(double fraction) {
    if (!std::isfinite(fraction)) return num(fraction);
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.4g%%", fraction * 100.0);
    return buffer;
}

std::string size_text(const Image& image) {
    return std::to_string(image.width) + "x" + std::to_string(image.height) + " with " +
           std::to_string(image.channels) + (image.channels == 1 ? " channel" : " channels");
}

void require_threshold(double value, const char* name) {
    if (std::isnan(value) || value < 0.0)
        throw std::invalid_argument(std::string("CompareSettings::") + name + ": expected a threshold >= 0, got " +
                                    num(value));
}

}  // namespace

void CompareSettings::validate() const {
    require_threshold(fail_threshold, "fail_threshold");
    require_threshold(hard_fail_threshold, "hard_fail_threshold");
    if (!(fail_fraction >= 0.0 && fail_fraction <= 1.0))
        throw std::invalid_argument("CompareSettings::fail_fraction: expected a fraction in [0, 1], got " +
                                    num(fail_fraction));
}

std::string CompareSettings::to_string() const {
    return "CompareSettings(fail_threshold=" + num(fail_threshold) + ", fail_fraction=" + num(fail_fraction) +
           ", hard_fail_threshold=" + num(hard_fail_threshold) + ")";
}

CompareReport compare_images(const Image& actual, const Image& expected, const CompareSettings& settings) {
    settings.validate();
    if (actual.width != expected.width || actual.height != expected.height || actual.channels != expected.channels)
        throw std::invalid_argument("compare_images: the images differ in size: actual is " + size_text(actual) +
                                    ", expected is " + size_text(expected));
    const std::size_t n = static_cast<std::size_t>(actual.width) * static_cast<std::size_t>(actual.height) *
                          static_cast<std::size_t>(actual.channels);
    if (actual.pixels.size() != n || expected.pixels.size() != n)
        throw std::invalid_argument("compare_images: an image's pixel count does not match its size (actual " +
                                    std::to_string(actual.pixels.size()) + " values, expected " +
                                    std::to_string(expected.pixels.size()) + ", size " + std::to_string(n) + ")");

    CompareReport r;
    r.width = actual.width;
    r.height = actual.height;
    r.channels = actual.channels;
    r.values_compared = n;
    r.settings = settings;

    double sum = 0.0, sum_sq = 0.0;
    std::size_t worst = n;  // index of the worst value; n = none differs
    for (std::size_t i = 0; i < n; ++i) {
        const float a = actual.pixels[i];
        const float b = expected.pixels[i];
        double d;
        if (a == b) {
            d = 0.0;  // equal infinities too (their difference would be NaN)
        } else if (std::isnan(a) || std::isnan(b)) {
            // A NaN fails and fails hard whatever the thresholds (even infinite ones).
            d = kInf;
            ++r.nan_values;
            ++r.failing_values;
            ++r.hard_failing_values;
        } else {
            d = std::fabs(static_cast<double>(a) - static_cast<double>(b));
            if (d > settings.fail_threshold) ++r.failing_values;
            if (d > settings.hard_fail_threshold) ++r.hard_failing_values;
        }
        if (d > r.max_abs_error) {
            r.max_abs_error = d;
            worst = i;
        }
        sum += d;
        sum_sq += d * d;
    }

    if (n > 0) {
        r.mean_abs_error = sum / static_cast<double>(n);
        const double mse = sum_sq / static_cast<double>(n);
        r.rmse = std::sqrt(mse);
        r.psnr = mse == 0.0 ? kInf : (std::isinf(mse) ? -kInf : 10.0 * std::log10(1.0 / mse));
        r.failing_fraction = static_cast<double>(r.failing_values) / static_cast<double>(n);
    }
    if (worst < n) {
        const std::size_t c = static_cast<std::size_t>(r.channels);
        const std::size_t pixel = worst / c;
        r.worst_channel = static_cast<int>(worst % c);
        r.worst_x = static_cast<int>(pixel % static_cast<std::size_t>(r.width));
        r.worst_y = static_cast<int>(pixel / static_cast<std::size_t>(r.width));
        r.worst_actual = actual.pixels[worst];
        r.worst_expected = expected.pixels[worst];
    }
    r.passed = !(r.failing_fraction > settings.fail_fraction) && r.hard_failing_values == 0;
    return r;
}

std::string CompareReport::to_string() const {
    std::string verdict;
    if (passed) {
        verdict = "PASS";
    } else {
        std::string reasons;
        auto add = [&reasons](const std::string& s) { reasons += (reasons.empty() ? "" : "; ") + s; };
        if (failing_fraction > settings.fail_fraction)
            add(percent(failing_fraction) + " of the values fail, more than the " + percent(settings.fail_fraction) +
                " allowed");
        if (hard_failing_values > 0)
            add(std::to_string(hard_failing_values) + " value" + (hard_failing_values == 1 ? "" : "s") +
                " beyond the hard limit " + num(settings.hard_fail_threshold));
        if (nan_values > 0)
            add(std::to_string(nan_values) + " NaN value" + (nan_values == 1 ? "" : "s"));
        verdict = "FAIL: " + reasons;
    }
    std::string s = verdict + "\n";
    s += "  " + std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(channels) + " = " +
         std::to_string(values_compared) + " values; " + std::to_string(failing_values) + " (" +
         percent(failing_fraction) + ") differ by more than " + num(settings.fail_threshold) + " (allowed: " +
         percent(settings.fail_fraction) + "), " + std::to_string(hard_failing_values) + " by more than " +
         num(settings.hard_fail_threshold) + " (hard limit)";
    if (nan_values > 0) s += ", " + std::to_string(nan_values) + " NaN";
    s += "\n";
    if (worst_x >= 0) {
        s += "  worst: x " + std::to_string(worst_x) + ", y " + std::to_string(worst_y) + ", channel " +
             std::to_string(worst_channel) + ": actual " + num(worst_actual) + ", expected " + num(worst_expected) +
             "\n";
    } else {
        s += "  worst: none (no value differs)\n";
    }
    s += "  max |diff| " + num(max_abs_error) + ", mean |diff| " + num(mean_abs_error) + ", RMSE " + num(rmse) +
         ", PSNR " + num(psnr) + " dB";
    return s;
}

}  // namespace mipraster
