// Tests for mipraster/core/compare.hpp: error metrics against hand-computed values, the threshold
// semantics at their boundaries, NaN and infinity handling, size checks and the printed report.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "mipraster/core/compare.hpp"
#include "mipraster/core/image.hpp"

namespace mr = mipraster;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInfF = std::numeric_limits<float>::infinity();
constexpr double kInf = std::numeric_limits<double>::infinity();

mr::Image make(int w, int h, int c, std::vector<float> values) {
    mr::Image image(w, h, c);
    image.pixels.assign(values.begin(), values.end());
    return image;
}

mr::CompareSettings thresholds(double fail, double fraction, double hard) {
    mr::CompareSettings s;
    s.fail_threshold = fail;
    s.fail_fraction = fraction;
    s.hard_fail_threshold = hard;
    return s;
}

bool contains(const std::string& haystack, const std::string& needle) {
    return haystack.find(needle) != std::string::npos;
}

}  // namespace

TEST(Compare, DefaultsAreIdiffLike) {
    const mr::CompareSettings s;
    EXPECT_EQ(s.fail_threshold, 1.0 / 255);
    EXPECT_EQ(s.fail_fraction, 0.0);
    EXPECT_EQ(s.hard_fail_threshold, 1.0);
}

TEST(Compare, IdenticalImagesPassWithInfinitePsnrAndNoWorstValue) {
    const mr::Image a = make(2, 2, 1, {0.0f, 0.25f, 0.5f, 1.0f});
    const mr::CompareReport r = mr::compare_images(a, a);
    EXPECT_TRUE(r.passed);
    EXPECT_EQ(r.values_compared, 4u);
    EXPECT_EQ(r.max_abs_error, 0.0);
    EXPECT_EQ(r.mean_abs_error, 0.0);
    EXPECT_EQ(r.rmse, 0.0);
    EXPECT_EQ(r.psnr, kInf);
    EXPECT_EQ(r.failing_values, 0u);
    EXPECT_EQ(r.worst_x, -1);
    EXPECT_EQ(r.worst_y, -1);
    EXPECT_EQ(r.worst_channel, -1);
    const std::string text = r.to_string();
    EXPECT_EQ(text.rfind("PASS", 0), 0u) << text;
    EXPECT_TRUE(contains(text, "PSNR inf dB")) << text;
    EXPECT_TRUE(contains(text, "no value differs")) << text;
}

TEST(Compare, MetricsMatchHandComputedValues) {
    // 2x1 pixels, 2 channels; errors 0, 0.25, 0.25, 0.125 (all exact in binary).
    const mr::Image actual = make(2, 1, 2, {0.5f, 0.25f, 1.0f, 0.0f});
    const mr::Image expected = make(2, 1, 2, {0.5f, 0.5f, 0.75f, 0.125f});
    const mr::CompareReport r = mr::compare_images(actual, expected, thresholds(0.125, 0.5, 1.0));
    EXPECT_EQ(r.width, 2);
    EXPECT_EQ(r.height, 1);
    EXPECT_EQ(r.channels, 2);
    EXPECT_EQ(r.values_compared, 4u);
    EXPECT_EQ(r.max_abs_error, 0.25);
    EXPECT_EQ(r.mean_abs_error, 0.625 / 4);                      // (0 + 0.25 + 0.25 + 0.125) / 4
    EXPECT_EQ(r.rmse, 0.1875);                                   // sqrt(0.140625 / 4) = 3/16
    EXPECT_NEAR(r.psnr, 10.0 * std::log10(4.0 / 0.140625), 1e-12);  // 14.5400 dB
    EXPECT_NEAR(r.psnr, 14.5400, 1e-4);
    EXPECT_EQ(r.failing_values, 2u);                             // 0.125 is not > 0.125
    EXPECT_EQ(r.failing_fraction, 0.5);
    EXPECT_EQ(r.hard_failing_values, 0u);
    EXPECT_TRUE(r.passed);                                       // 0.5 is not > 0.5
    // the first of the two largest errors: pixel (0, 0), channel 1
    EXPECT_EQ(r.worst_x, 0);
    EXPECT_EQ(r.worst_y, 0);
    EXPECT_EQ(r.worst_channel, 1);
    EXPECT_EQ(r.worst_actual, 0.25f);
    EXPECT_EQ(r.worst_expected, 0.5f);
}

TEST(Compare, WorstValueReportsItsColumnRowAndChannel) {
    mr::Image expected(3, 2, 4);
    mr::Image actual = expected;
    actual.at(2, 1, 3) = 0.75f;  // x 2, y 1, alpha
    actual.at(0, 1, 0) = 0.5f;
    const mr::CompareReport r = mr::compare_images(actual, expected, thresholds(0.0, 1.0, 1.0));
    EXPECT_EQ(r.worst_x, 2);
    EXPECT_EQ(r.worst_y, 1);
    EXPECT_EQ(r.worst_channel, 3);
    EXPECT_EQ(r.worst_actual, 0.75f);
    EXPECT_EQ(r.worst_expected, 0.0f);
    EXPECT_EQ(r.failing_values, 2u);
    EXPECT_TRUE(contains(r.to_string(), "worst: x 2, y 1, channel 3: actual 0.75, expected 0")) << r.to_string();
}

TEST(Compare, FailThresholdIsStrict) {
    const mr::Image expected = make(1, 1, 1, {0.5f});
    const mr::CompareSettings s = thresholds(0.25, 0.0, 1.0);
    const mr::CompareReport at = mr::compare_images(make(1, 1, 1, {0.75f}), expected, s);  // |d| = 0.25
    EXPECT_EQ(at.failing_values, 0u);
    EXPECT_TRUE(at.passed);
    const mr::CompareReport below = mr::compare_images(make(1, 1, 1, {0.25f}), expected, s);  // sign does not matter
    EXPECT_TRUE(below.passed);
    const float above_value = std::nextafter(0.75f, 1.0f);
    const mr::CompareReport above = mr::compare_images(make(1, 1, 1, {above_value}), expected, s);
    EXPECT_EQ(above.failing_values, 1u);
    EXPECT_EQ(above.failing_fraction, 1.0);
    EXPECT_FALSE(above.passed);
    EXPECT_TRUE(contains(above.to_string(), "FAIL: 100% of the values fail, more than the 0% allowed"))
        << above.to_string();
}

TEST(Compare, FailFractionIsStrict) {
    // 1 of 4 values differs by 0.5 > 0.25: the failing fraction is exactly 0.25.
    const mr::Image expected = make(2, 2, 1, {0.0f, 0.0f, 0.0f, 0.0f});
    const mr::Image actual = make(2, 2, 1, {0.0f, 0.5f, 0.0f, 0.0f});
    const mr::CompareReport at = mr::compare_images(actual, expected, thresholds(0.25, 0.25, 1.0));
    EXPECT_EQ(at.failing_fraction, 0.25);
    EXPECT_TRUE(at.passed);
    const mr::CompareReport over =
        mr::compare_images(actual, expected, thresholds(0.25, std::nextafter(0.25, 0.0), 1.0));
    EXPECT_FALSE(over.passed);
    // the default fraction (0): any failing value fails the comparison
    mr::CompareSettings defaults;
    defaults.fail_threshold = 0.25;
    EXPECT_FALSE(mr::compare_images(actual, expected, defaults).passed);
}

TEST(Compare, HardThresholdIsStrictAndOverridesTheFraction) {
    const mr::Image expected = make(4, 1, 1, {0.0f, 0.0f, 0.0f, 0.0f});
    const mr::CompareSettings lenient = thresholds(0.0, 1.0, 0.5);  // every value may fail, none past 0.5
    const mr::CompareReport at = mr::compare_images(make(4, 1, 1, {0.5f, 0.5f, 0.0f, 0.0f}), expected, lenient);
    EXPECT_EQ(at.hard_failing_values, 0u);
    EXPECT_TRUE(at.passed);
    const float past = std::nextafter(0.5f, 1.0f);
    const mr::CompareReport r = mr::compare_images(make(4, 1, 1, {0.0f, 0.0f, past, 0.0f}), expected, lenient);
    EXPECT_EQ(r.hard_failing_values, 1u);
    EXPECT_EQ(r.failing_values, 1u);
    EXPECT_FALSE(r.passed);
    EXPECT_TRUE(contains(r.to_string(), "FAIL: 1 value beyond the hard limit 0.5")) << r.to_string();
    // a hard threshold of +inf disables it
    EXPECT_TRUE(mr::compare_images(make(4, 1, 1, {0.0f, 0.0f, 1e30f, 0.0f}), expected, thresholds(0.0, 1.0, kInf))
                    .passed);
}

TEST(Compare, NaNInEitherImageFailsHardWhateverTheThresholds) {
    const mr::CompareSettings anything = thresholds(kInf, 1.0, kInf);
    const mr::Image finite = make(2, 1, 1, {0.5f, 0.25f});
    const std::vector<std::pair<mr::Image, mr::Image>> cases = {
        {make(2, 1, 1, {0.5f, kNaN}), finite},                 // NaN in actual
        {finite, make(2, 1, 1, {0.5f, kNaN})},                 // NaN in expected
        {make(2, 1, 1, {0.5f, kNaN}), make(2, 1, 1, {0.5f, kNaN})},  // NaN in both: still no match
    };
    for (const auto& [actual, expected] : cases) {
        for (const mr::CompareSettings& s : {mr::CompareSettings{}, anything}) {
            const mr::CompareReport r = mr::compare_images(actual, expected, s);
            EXPECT_FALSE(r.passed);
            EXPECT_EQ(r.nan_values, 1u);
            EXPECT_EQ(r.failing_values, 1u);
            EXPECT_EQ(r.hard_failing_values, 1u);
            EXPECT_EQ(r.max_abs_error, kInf);
            EXPECT_EQ(r.mean_abs_error, kInf);
            EXPECT_EQ(r.rmse, kInf);
            EXPECT_EQ(r.psnr, -kInf);
            EXPECT_EQ(r.worst_x, 1);
            EXPECT_EQ(r.worst_channel, 0);
            const std::string text = r.to_string();
            EXPECT_TRUE(contains(text, "1 NaN value")) << text;
            EXPECT_TRUE(contains(text, "nan")) << text;
        }
    }
}

TEST(Compare, EqualInfinitiesMatchAndAnInfiniteErrorFailsHard) {
    const mr::Image inf = make(1, 1, 1, {kInfF});
    const mr::CompareReport same = mr::compare_images(inf, inf);
    EXPECT_TRUE(same.passed);
    EXPECT_EQ(same.max_abs_error, 0.0);
    const mr::CompareReport other = mr::compare_images(inf, make(1, 1, 1, {1.0f}));
    EXPECT_FALSE(other.passed);
    EXPECT_EQ(other.max_abs_error, kInf);
    EXPECT_EQ(other.hard_failing_values, 1u);
    EXPECT_EQ(other.nan_values, 0u);
    EXPECT_FALSE(mr::compare_images(inf, make(1, 1, 1, {-kInfF})).passed);
}

TEST(Compare, SizeMismatchNamesBothSizes) {
    const mr::Image a(4, 3, 4), b(4, 2, 4), c(4, 3, 3);
    try {
        mr::compare_images(a, b);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "compare_images: the images differ in size: actual is 4x3 with 4 channels, "
                               "expected is 4x2 with 4 channels");
    }
    try {
        mr::compare_images(a, c);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_TRUE(contains(e.what(), "actual is 4x3 with 4 channels, expected is 4x3 with 3 channels")) << e.what();
    }
    mr::Image broken(2, 2, 1);
    broken.pixels.pop_back();
    EXPECT_THROW(mr::compare_images(broken, mr::Image(2, 2, 1)), std::invalid_argument);
}

TEST(Compare, InvalidSettingsNameTheSetting) {
    const mr::Image a(1, 1, 1);
    auto message = [&](const mr::CompareSettings& s) -> std::string {
        try {
            mr::compare_images(a, a, s);
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "no exception";
    };
    EXPECT_TRUE(contains(message(thresholds(-1.0, 0.0, 1.0)), "fail_threshold: expected a threshold >= 0, got -1"));
    EXPECT_TRUE(contains(message(thresholds(std::nan(""), 0.0, 1.0)), "fail_threshold"));
    EXPECT_TRUE(contains(message(thresholds(0.0, 0.0, -0.5)), "hard_fail_threshold"));
    EXPECT_TRUE(contains(message(thresholds(0.0, 1.5, 1.0)), "fail_fraction: expected a fraction in [0, 1], got 1.5"));
    EXPECT_TRUE(contains(message(thresholds(0.0, std::nan(""), 1.0)), "fail_fraction"));
    EXPECT_NO_THROW(mr::compare_images(a, a, thresholds(kInf, 1.0, kInf)));
}

TEST(Compare, EmptyImagesPass) {
    const mr::CompareReport r = mr::compare_images(mr::Image(0, 0, 4), mr::Image(0, 0, 4));
    EXPECT_TRUE(r.passed);
    EXPECT_EQ(r.values_compared, 0u);
    EXPECT_EQ(r.failing_fraction, 0.0);
    EXPECT_EQ(r.psnr, kInf);
}

TEST(Compare, ReportsPrint) {
    EXPECT_EQ(mr::CompareSettings{}.to_string(),
              "CompareSettings(fail_threshold=0.00392157, fail_fraction=0, hard_fail_threshold=1)");
    const mr::Image actual = make(2, 1, 2, {0.5f, 0.25f, 1.0f, 0.0f});
    const mr::Image expected = make(2, 1, 2, {0.5f, 0.5f, 0.75f, 0.125f});
    const std::string text = mr::compare_images(actual, expected, thresholds(0.125, 0.25, 1.0)).to_string();
    EXPECT_EQ(text,
              "FAIL: 50% of the values fail, more than the 25% allowed\n"
              "  2x1x2 = 4 values; 2 (50%) differ by more than 0.125 (allowed: 25%), 0 by more than 1 (hard limit)\n"
              "  worst: x 0, y 0, channel 1: actual 0.25, expected 0.5\n"
              "  max |diff| 0.25, mean |diff| 0.15625, RMSE 0.1875, PSNR 14.54 dB");
}
