// Tests for mipraster/core/colour.hpp: sRGB transfer functions and 8- and 16-bit encoding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "mipraster/core/colour.hpp"
#include "mipraster/core/image.hpp"

namespace mr = mipraster;

TEST(Colour, LinearToSrgbRoundTripsOverASweep) {
    constexpr int steps = 10000;
    for (int i = 0; i <= steps; ++i) {
        const float x = static_cast<float>(i) / steps;
        const float back = mr::srgb_to_linear(mr::linear_to_srgb(x));
        EXPECT_NEAR(back, x, 1e-6f + 4e-6f * x) << "x = " << x;
    }
}

TEST(Colour, SrgbToLinearRoundTripsOverASweep) {
    constexpr int steps = 10000;
    for (int i = 0; i <= steps; ++i) {
        const float e = static_cast<float>(i) / steps;
        EXPECT_NEAR(mr::linear_to_srgb(mr::srgb_to_linear(e)), e, 1e-6f + 4e-6f * e) << "encoded = " << e;
    }
}

TEST(Colour, LinearHalfEncodesTo188) {
    EXPECT_EQ(mr::linear_to_srgb8(0.5f), 188);
    EXPECT_EQ(mr::linear_to_srgb8(0.0f), 0);
    EXPECT_EQ(mr::linear_to_srgb8(1.0f), 255);
}

TEST(Colour, OutOfRangeAndNanClamp) {
    EXPECT_EQ(mr::linear_to_srgb(-1.0f), 0.0f);
    EXPECT_EQ(mr::linear_to_srgb(2.0f), 1.0f);
    EXPECT_EQ(mr::linear_to_srgb(std::numeric_limits<float>::quiet_NaN()), 0.0f);
    EXPECT_EQ(mr::linear_to_srgb(std::numeric_limits<float>::infinity()), 1.0f);
    EXPECT_EQ(mr::linear_to_srgb8(std::numeric_limits<float>::quiet_NaN()), 0);
    EXPECT_EQ(mr::srgb_to_linear(-0.5f), 0.0f);
    EXPECT_EQ(mr::srgb_to_linear(1.5f), 1.0f);
}

TEST(Colour, EightBitDecodeIsMonotonicAndRoundTripsEveryCode) {
    float previous = -1.0f;
    for (int code = 0; code < 256; ++code) {
        const float linear = mr::srgb_to_linear(static_cast<float>(code) / 255.0f);
        EXPECT_GT(linear, previous) << "code " << code;
        EXPECT_GE(linear, 0.0f);
        EXPECT_LE(linear, 1.0f);
        EXPECT_EQ(static_cast<int>(mr::linear_to_srgb8(linear)), code) << "code " << code << " linear " << linear;
        previous = linear;
    }
    EXPECT_EQ(mr::srgb_to_linear(0.0f), 0.0f);
    EXPECT_EQ(mr::srgb_to_linear(1.0f), 1.0f);
}

TEST(Colour, ToSrgb8UnpremultipliesColourAndKeepsAlphaLinear) {
    mr::Image img(3, 1, 4);
    // opaque linear 0.5 grey
    for (int c = 0; c < 3; ++c) img.at(0, 0, c) = 0.5f;
    img.at(0, 0, 3) = 1.0f;
    // half-transparent: premultiplied 0.25 with alpha 0.5 is straight 0.5
    for (int c = 0; c < 3; ++c) img.at(1, 0, c) = 0.25f;
    img.at(1, 0, 3) = 0.5f;
    // fully transparent stays black
    const std::vector<std::uint8_t> out = mr::to_srgb8(img);
    ASSERT_EQ(out.size(), 12u);
    const std::vector<std::uint8_t> expected = {188, 188, 188, 255, 188, 188, 188, 128, 0, 0, 0, 0};
    EXPECT_EQ(out, expected);
}

TEST(Colour, SixteenBitCodesAreTheExactEncodingRoundedWithinOneCode) {
    // linear_to_srgb16 against IEC 61966-2-1 in double, over a sweep and every 16-bit code's
    // decoded value (which must encode back to that code: the decode and encode are inverses
    // within float rounding); to_srgb16 is to_srgb8 with these codes.
    for (int i = 0; i <= 100000; ++i) {
        const double x = i / 100000.0;
        const double exact = x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
        const int code = mr::linear_to_srgb16(static_cast<float>(x));
        EXPECT_LE(std::abs(code - exact * 65535.0), 1.0) << "linear " << x;
    }
    int off = 0;
    for (int code = 0; code < 65536; code += 1) {
        const float linear = mr::srgb_to_linear(static_cast<float>(code) / 65535.0f);
        off += std::abs(static_cast<int>(mr::linear_to_srgb16(linear)) - code) > 1;
    }
    EXPECT_EQ(off, 0);
    EXPECT_EQ(mr::linear_to_srgb16(0.5f), 48192);
    EXPECT_EQ(mr::linear_to_srgb16(std::numeric_limits<float>::quiet_NaN()), 0);
    mr::Image img(2, 1, 4);
    for (int c = 0; c < 3; ++c) img.at(0, 0, c) = 0.25f, img.at(1, 0, c) = 2.0f;  // straight 0.5; over 1
    img.at(0, 0, 3) = 0.5f;
    img.at(1, 0, 3) = 1.0f;
    const std::vector<std::uint16_t> expected = {48192, 48192, 48192, 32768, 65535, 65535, 65535, 65535};
    EXPECT_EQ(mr::to_srgb16(img), expected);
}
