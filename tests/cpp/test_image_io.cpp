// Tests for mipraster/io/image_io.hpp: PNG (sRGB8) and EXR (linear float) output and input.
// PNG bytes are read back with OpenImageIO directly, so the encoding is checked independently
// of read_image's decoding.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "mipraster/core/colour.hpp"
#include "mipraster/core/image.hpp"
#include "helpers.hpp"
#include "mipraster/io/image_io.hpp"
#include "test_output.hpp"

namespace fs = std::filesystem;
namespace mr = mipraster;
using helpers::thrown_message;

namespace {

std::string output_path(const std::string& name) { return test_output_path("image_io", name); }

// The raw 8-bit channels of a file as stored (straight alpha, no colour conversion).
struct RawBytes {
    int width = 0, height = 0, channels = 0;
    std::vector<std::uint8_t> bytes;
};

RawBytes read_raw_uint8(const std::string& path) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) throw std::runtime_error("test could not open " + path + ": " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    RawBytes raw{spec.width, spec.height, spec.nchannels, {}};
    raw.bytes.resize(static_cast<std::size_t>(raw.width) * raw.height * raw.channels);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT8) << path;
    if (!in->read_image(0, 0, 0, raw.channels, OIIO::TypeDesc::UINT8, raw.bytes.data()))
        throw std::runtime_error("test could not read " + path + ": " + in->geterror());
    return raw;
}

// A small premultiplied RGBA image with opaque, translucent and transparent pixels.
mr::Image sample_rgba() {
    mr::Image img(4, 3, 4);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float a = (x == 3) ? 0.0f : (y == 2 ? 0.5f : 1.0f);
            const float r = static_cast<float>(x) / 3.0f, g = static_cast<float>(y) / 2.0f, b = 0.25f;
            img.at(x, y, 0) = r * a;
            img.at(x, y, 1) = g * a;
            img.at(x, y, 2) = b * a;
            img.at(x, y, 3) = a;
        }
    // pixel (0, 0): opaque linear 0.5 grey
    for (int c = 0; c < 3; ++c) img.at(0, 0, c) = 0.5f;
    img.at(0, 0, 3) = 1.0f;
    return img;
}

}  // namespace

TEST(ImageIo, PngStoresStraightSrgb8) {
    const mr::Image img = sample_rgba();
    const std::string path = output_path("rgba.png");
    mr::write_image(path, img);

    const RawBytes raw = read_raw_uint8(path);
    ASSERT_EQ(raw.width, 4);
    ASSERT_EQ(raw.height, 3);
    ASSERT_EQ(raw.channels, 4);
    // linear 0.5 opaque grey → sRGB8 188
    EXPECT_EQ(raw.bytes[0], 188);
    EXPECT_EQ(raw.bytes[1], 188);
    EXPECT_EQ(raw.bytes[2], 188);
    EXPECT_EQ(raw.bytes[3], 255);
    // every byte is what to_srgb8 produces (no second un-premultiply or gamma step by the writer)
    EXPECT_EQ(raw.bytes, mr::to_srgb8(img));
}

TEST(ImageIo, PngRoundTripsWithinQuantization) {
    const mr::Image img = sample_rgba();
    const std::string path = output_path("roundtrip.png");
    mr::write_image(path, img);
    const mr::Image back = mr::read_image(path);
    ASSERT_EQ(back.width, img.width);
    ASSERT_EQ(back.height, img.height);
    ASSERT_EQ(back.channels, 4);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            EXPECT_NEAR(back.at(x, y, 3), img.at(x, y, 3), 0.5f / 255.0f + 1e-6f) << x << "," << y;
            for (int c = 0; c < 3; ++c)
                // one sRGB8 step is at most ~1.3% of linear range near white
                EXPECT_NEAR(back.at(x, y, c), img.at(x, y, c), 0.014f) << x << "," << y << "," << c;
        }
    // the 188 grey decodes to the exact linear value of code 188
    EXPECT_EQ(back.at(0, 0, 0), mr::srgb_to_linear(188.0f / 255.0f));
    EXPECT_EQ(back.at(0, 0, 3), 1.0f);
    // transparent pixels read back as zero (premultiplied)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(back.at(3, 1, c), 0.0f);
}

TEST(ImageIo, PngExtensionIsCaseInsensitive) {
    const std::string path = output_path("upper.PNG");
    mr::write_image(path, sample_rgba());
    EXPECT_EQ(read_raw_uint8(path).bytes, mr::to_srgb8(sample_rgba()));
}

TEST(ImageIo, OneChannelPngIsPlainGrey) {
    mr::Image img(5, 1, 1);
    const float values[5] = {-1.0f, 0.0f, 0.5f, 1.0f, 3.0f};
    for (int x = 0; x < 5; ++x) img.at(x, 0, 0) = values[x];
    const std::string path = output_path("grey.png");
    mr::write_image(path, img);
    const RawBytes raw = read_raw_uint8(path);
    ASSERT_EQ(raw.channels, 1);
    const std::vector<std::uint8_t> expected = {0, 0, 128, 255, 255};
    EXPECT_EQ(raw.bytes, expected);
}

TEST(ImageIo, ThreeChannelPngIsRgb) {
    mr::Image img(2, 1, 3);
    for (int c = 0; c < 3; ++c) img.at(0, 0, c) = 0.5f;
    img.at(1, 0, 0) = 1.0f;
    const std::string path = output_path("rgb.png");
    mr::write_image(path, img);
    const RawBytes raw = read_raw_uint8(path);
    ASSERT_EQ(raw.channels, 3);
    const std::vector<std::uint8_t> expected = {188, 188, 188, 255, 0, 0};
    EXPECT_EQ(raw.bytes, expected);
    const mr::Image back = mr::read_image(path);
    EXPECT_EQ(back.channels, 4);
    EXPECT_EQ(back.at(1, 0, 3), 1.0f);
}

TEST(ImageIo, ExrRoundTripIsBitExact) {
    mr::Image img(7, 5, 4);
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> dist(-2.0f, 8.0f);
    for (float& v : img.pixels) v = dist(rng);
    img.pixels[0] = 1e-30f;  // tiny (denormal-range in half, exact in float)
    img.pixels[1] = 65504.0f * 4.0f;  // beyond half range
    img.pixels[2] = 0.1f;
    const std::string path = output_path("linear.exr");
    mr::write_image(path, img);

    auto in = OIIO::ImageInput::open(path);
    ASSERT_TRUE(in) << OIIO::geterror();
    EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(in->spec().nchannels, 4);
    in->close();

    const mr::Image back = mr::read_image(path);
    ASSERT_EQ(back.width, img.width);
    ASSERT_EQ(back.height, img.height);
    ASSERT_EQ(back.channels, 4);
    ASSERT_EQ(back.pixels.size(), img.pixels.size());
    EXPECT_EQ(std::memcmp(back.pixels.data(), img.pixels.data(), img.pixels.size() * sizeof(float)), 0);
}

TEST(ImageIo, OneChannelExrRoundTripsAsGrey) {
    mr::Image img(3, 2, 1);
    for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = 0.123456789f * static_cast<float>(i) - 0.2f;
    const std::string path = output_path("depth.exr");
    mr::write_image(path, img);
    const mr::Image back = mr::read_image(path);
    ASSERT_EQ(back.channels, 4);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            for (int c = 0; c < 3; ++c) EXPECT_EQ(back.at(x, y, c), img.at(x, y, 0));
            EXPECT_EQ(back.at(x, y, 3), 1.0f);
        }
}

TEST(ImageIo, UnknownExtensionThrowsNamingPath) {
    const std::string path = output_path("picture.jpg");
    EXPECT_THROW(mr::write_image(path, sample_rgba()), std::invalid_argument);
    const std::string message = thrown_message([&] { mr::write_image(path, sample_rgba()); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(".png"), std::string::npos) << message;
    EXPECT_NE(message.find(".exr"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(path));

    const std::string no_ext = output_path("noextension");
    EXPECT_THROW(mr::write_image(no_ext, sample_rgba()), std::invalid_argument);
}

TEST(ImageIo, MalformedImageThrows) {
    mr::Image two(2, 2, 2);
    EXPECT_THROW(mr::write_image(output_path("two.png"), two), std::invalid_argument);
    mr::Image empty;
    EXPECT_THROW(mr::write_image(output_path("empty.exr"), empty), std::invalid_argument);
    mr::Image short_pixels(2, 2, 4);
    short_pixels.pixels.pop_back();
    const std::string path = output_path("short.exr");
    const std::string message = thrown_message([&] { mr::write_image(path, short_pixels); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
}

TEST(ImageIo, NonFinitePixelInPngThrowsNamingItAndExrKeepsIt) {
    // A PNG code has no NaN (written as 0) and ±inf only the clamp limit: a silent wrong image.
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    for (const float bad : {nan, inf, -inf}) {
        for (const int channels : {1, 3, 4}) {
            for (const int bits : {8, 16}) {
                mr::Image img(4, 3, channels);
                img.at(2, 1, channels - 1) = bad;
                const std::string path = output_path("non_finite.png");
                fs::remove(path);
                mr::ImageWriteOptions options;
                options.png_bits = bits;
                EXPECT_THROW(mr::write_image(path, img, options), std::invalid_argument);
                const std::string message = thrown_message([&] { mr::write_image(path, img, options); });
                const std::string where = "pixel (x=2, y=1) channel " + std::to_string(channels - 1) + " is " +
                                          (std::isnan(bad) ? "nan" : bad > 0 ? "inf" : "-inf");
                EXPECT_NE(message.find(where), std::string::npos) << message;
                EXPECT_NE(message.find(path), std::string::npos) << message;
                EXPECT_FALSE(fs::exists(path));
            }
        }
    }
    // An EXR is float: NaN and inf are stored as they are.
    mr::Image img(4, 3, 4);
    img.at(2, 1, 0) = nan;
    img.at(3, 2, 1) = inf;
    const std::string path = output_path("non_finite.exr");
    mr::write_image(path, img);
    const mr::Image back = mr::read_image(path);
    EXPECT_TRUE(std::isnan(back.at(2, 1, 0)));
    EXPECT_EQ(back.at(3, 2, 1), inf);
}

TEST(ImageIo, UnwritableLocationThrowsNamingPath) {
    const std::string path = output_path("no_such_dir/out.png");
    EXPECT_THROW(mr::write_image(path, sample_rgba()), std::runtime_error);
    const std::string message = thrown_message([&] { mr::write_image(path, sample_rgba()); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
}

TEST(ImageIo, MissingFileThrowsNamingPath) {
    const std::string path = output_path("does_not_exist.png");
    fs::remove(path);
    EXPECT_THROW(mr::read_image(path), std::runtime_error);
    const std::string message = thrown_message([&] { mr::read_image(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
}

TEST(ImageIo, CorruptFileThrowsNamingPath) {
    for (const char* name : {"corrupt.png", "corrupt.exr"}) {
        const std::string path = output_path(name);
        {
            std::ofstream f(path, std::ios::binary);
            f << "this is not an image file at all";
        }
        EXPECT_THROW(mr::read_image(path), std::runtime_error) << path;
        const std::string message = thrown_message([&] { mr::read_image(path); });
        EXPECT_NE(message.find(path), std::string::npos) << message;
    }
}
