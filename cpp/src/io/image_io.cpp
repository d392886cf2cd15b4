#include "mipraster/io/image_io.hpp"

#include "file_extension.hpp"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "mipraster/core/colour.hpp"
#include "mipraster/core/memory_limit.hpp"

namespace mipraster {
namespace {

/// Largest image read_image decodes, in pixels: 2^29 is the largest texture level 0 (8 GiB of
/// RGBA float, kMaxTextureBytes); a file claiming more is refused before anything is allocated.
constexpr std::uint64_t kMaxReadPixels = std::uint64_t{1} << 29;
static_assert(kMaxReadPixels * 16 <= (std::uint64_t{8} << 30), "read limit must fit the texture limit");

enum class FileKind { png, exr };

FileKind output_kind(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext == ".png") return FileKind::png;
    if (ext == ".exr") return FileKind::exr;
    const std::string what = ext.empty() ? "no file extension" : "unsupported extension '" + ext + "'";
    throw std::invalid_argument("write_image: cannot write '" + path + "': " + what +
                                " (supported: .png for sRGB 8 or 16 bits, .exr for linear float)");
}

void check_image(const std::string& path, const Image& image) {
    if (image.width <= 0 || image.height <= 0)
        throw std::invalid_argument("write_image: cannot write '" + path + "': image is empty (" +
                                    image.to_string() + ")");
    if (image.channels != 1 && image.channels != 3 && image.channels != 4)
        throw std::invalid_argument("write_image: cannot write '" + path + "': " + image.to_string() +
                                    " has " + std::to_string(image.channels) +
                                    " channels, expected 1 (grey/data), 3 (RGB) or 4 (premultiplied RGBA)");
    const std::size_t expected = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) *
                                 static_cast<std::size_t>(image.channels);
    if (image.pixels.size() != expected)
        throw std::invalid_argument("write_image: cannot write '" + path + "': " + image.to_string() + " holds " +
                                    std::to_string(image.pixels.size()) + " values, expected width*height*channels = " +
                                    std::to_string(expected));
}

// A PNG holds 8- or 16-bit codes of clamped values: NaN has none (the encoders map it to 0) and
// ±inf only the clamp limit, a silent wrong image. Refused here, at write_image, naming the first
// (the encoders themselves keep their clamping: to_srgb8 and grey_codes are total functions, and a
// render never holds NaN). An EXR stores the floats as they are, NaN and inf included.
void check_finite_for_png(const std::string& path, const Image& image) {
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        const float v = image.pixels[i];
        if (std::isfinite(v)) continue;
        const std::size_t channels = static_cast<std::size_t>(image.channels);
        const std::size_t pixel = i / channels, width = static_cast<std::size_t>(image.width);
        throw std::invalid_argument("write_image: cannot write '" + path + "': pixel (x=" +
                                    std::to_string(pixel % width) + ", y=" + std::to_string(pixel / width) +
                                    ") channel " + std::to_string(i % channels) + " is " +
                                    (std::isnan(v) ? "nan" : v > 0.0f ? "inf" : "-inf") +
                                    "; 8- and 16-bit codes need finite values (write .exr to keep NaN and inf)");
    }
}

// 1-channel PNG: plain grey, round(clamp(v, 0, 1) * max code) (NaN → 0, though write_image has
// refused non-finite values before this).
template <typename Code>
std::vector<Code> grey_codes(const Image& image) {
    std::vector<Code> out(image.pixels.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const float v = image.pixels[i];
        const float clamped = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;  // NaN fails v > 0
        out[i] = static_cast<Code>(std::lround(clamped * static_cast<float>(std::numeric_limits<Code>::max())));
    }
    return out;
}

// Step: open, write all scanlines, close — each failure reported with the path.
void write_pixels(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc format, const void* data) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw std::runtime_error("write_image: cannot create a writer for '" + path + "': " + OIIO::geterror());
    if (!out->open(path, spec))
        throw std::runtime_error("write_image: cannot open '" + path + "' for writing: " + out->geterror());
    if (!out->write_image(format, data)) {
        const std::string message = out->geterror();
        out->close();
        throw std::runtime_error("write_image: cannot write '" + path + "': " + message);
    }
    if (!out->close()) throw std::runtime_error("write_image: cannot finish '" + path + "': " + out->geterror());
}

// A PNG of `image` with Code (8- or 16-bit) channels.
template <typename Code>
void write_png(const std::string& path, const Image& image) {
    const OIIO::TypeDesc format = sizeof(Code) == 1 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16;
    if (image.channels == 1) {
        const std::vector<Code> codes = grey_codes<Code>(image);
        OIIO::ImageSpec spec(image.width, image.height, 1, format);
        spec.channelnames = {"Y"};
        write_pixels(path, spec, format, codes.data());
        return;
    }
    std::vector<Code> codes;  // straight-alpha sRGB RGBA
    if constexpr (sizeof(Code) == 1) codes = to_srgb8(image);
    else codes = to_srgb16(image);
    int channels = 4;
    if (image.channels == 3) {  // drop the (opaque) alpha that to_srgb8 adds
        const std::size_t n = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
        for (std::size_t p = 0; p < n; ++p)
            for (int c = 0; c < 3; ++c) codes[p * 3 + c] = codes[p * 4 + c];
        codes.resize(n * 3);
        channels = 3;
    }
    OIIO::ImageSpec spec(image.width, image.height, channels, format);
    spec.attribute("oiio:ColorSpace", "sRGB");
    // The codes already hold straight alpha; without this OpenImageIO would un-premultiply again.
    spec.attribute("oiio:UnassociatedAlpha", 1);
    write_pixels(path, spec, format, codes.data());
}

}  // namespace

void write_image(const std::string& path, const Image& image, const ImageWriteOptions& options) {
    const FileKind kind = output_kind(path);
    check_image(path, image);
    if (kind == FileKind::png && options.png_bits != 8 && options.png_bits != 16)
        throw std::invalid_argument("write_image: cannot write '" + path + "': bits " +
                                    std::to_string(options.png_bits) + " (a PNG has 8 or 16 bits per channel)");
    if (kind == FileKind::exr && options.png_bits != 8)
        throw std::invalid_argument("write_image: cannot write '" + path + "' with bits " +
                                    std::to_string(options.png_bits) +
                                    ": bits are for PNG files; .exr is always 32-bit float");

    if (kind == FileKind::exr) {
        OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
        if (image.channels == 1) spec.channelnames = {"Y"};
        spec.attribute("compression", "zip");  // lossless
        write_pixels(path, spec, OIIO::TypeDesc::FLOAT, image.pixels.data());
        return;
    }

    check_finite_for_png(path, image);
    if (options.png_bits == 16) write_png<std::uint16_t>(path, image);
    else write_png<std::uint8_t>(path, image);
}

namespace {

// Refuses an image of w × h pixels and nch channels above kMaxReadPixels, or whose decoding
// (the stored channels as float, and as bytes first for 8-bit files, then RGBA float) would
// exceed the memory limit.
void check_read_size(int w, int h, int nch, const std::string& name) {
    const std::uint64_t pixels = std::uint64_t(w) * std::uint64_t(h);
    if (pixels > kMaxReadPixels)
        throw std::runtime_error("read_image: '" + name + "' is too large (" + std::to_string(w) + "x" +
                                 std::to_string(h) + " pixels; at most " + std::to_string(kMaxReadPixels) + ")");
    check_memory(pixels * std::uint64_t(nch) * (sizeof(float) + 1) + pixels * 4 * sizeof(float),
                 "reading '" + name + "' (" + std::to_string(w) + "x" + std::to_string(h) + "x" +
                     std::to_string(nch) + ")");
}

// OpenImageIO's GIF reader decodes the first frame into a canvas of the logical screen's size
// as it opens the file, before its size can be checked: the size from the header first (bytes
// 6–9, little-endian), checked as for RGBA. `b`: the file's first `size` bytes.
void check_gif_header(const unsigned char* b, std::size_t size, const std::string& name) {
    if (size < 10 || std::memcmp(b, "GIF8", 4) != 0) return;
    check_read_size(b[6] | b[7] << 8, b[8] | b[9] << 8, 4, name);
}

enum class AlphaKind { none, straight, associated };

// How the reader hands over alpha. OpenImageIO's convention: colour is associated (premultiplied)
// unless the spec says "oiio:UnassociatedAlpha" (PNG, TGA and unassociated TIFF do, given the
// hint). Its BMP and GIF readers return the file's straight alpha without saying so; its WebP
// reader premultiplies the 8-bit codes itself and says nothing, and TIFFs with associated alpha
// (ExtraSamples 1, as oiiotool writes them) and EXR are premultiplied in the file.
AlphaKind alpha_kind(const OIIO::ImageInput& in, const OIIO::ImageSpec& spec) {
    if (spec.get_int_attribute("oiio:UnassociatedAlpha", 0) != 0) return AlphaKind::straight;
    const std::string format = in.format_name();
    if (format == "bmp" || format == "gif") return AlphaKind::straight;
    return AlphaKind::associated;
}

// Whether channel `c` of every pixel of `raw` (nch channels per pixel) is zero.
bool all_zero(const std::vector<float>& raw, int nch, int c) {
    for (std::size_t i = static_cast<std::size_t>(c); i < raw.size(); i += static_cast<std::size_t>(nch))
        if (raw[i] != 0.0f) return false;
    return true;
}

// Step: read every channel of an opened file, decode and premultiply (read_image's contract;
// `options` says how integer colour and alpha are taken). `name` is the path or the memory
// image's name, for messages.
Image decode_image(OIIO::ImageInput& in, const std::string& name, const ImageReadOptions& options) {
    const OIIO::ImageSpec spec = in.spec();
    const int w = spec.width, h = spec.height, nch = spec.nchannels;
    if (w <= 0 || h <= 0 || nch <= 0)
        throw std::runtime_error("read_image: '" + name + "' has no pixels (" + std::to_string(w) + "x" +
                                 std::to_string(h) + "x" + std::to_string(nch) + ")");
    check_read_size(w, h, nch, name);
    const std::uint64_t values = std::uint64_t(w) * std::uint64_t(h) * std::uint64_t(nch);

    // Read every channel as float in [0, 1] (integers) or as stored (floats).
    const OIIO::TypeDesc stored = spec.format;
    const bool is_float = stored.basetype == OIIO::TypeDesc::FLOAT || stored.basetype == OIIO::TypeDesc::HALF ||
                          stored.basetype == OIIO::TypeDesc::DOUBLE;
    const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    std::vector<float> raw(static_cast<std::size_t>(values));
    bool ok = true;
    if (stored == OIIO::TypeDesc::UINT8) {
        // 8-bit: convert code / 255 ourselves so that decoding is exact and independent of OIIO.
        std::vector<std::uint8_t> bytes(raw.size());
        ok = in.read_image(0, 0, 0, nch, OIIO::TypeDesc::UINT8, bytes.data());
        for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = static_cast<float>(bytes[i]) / 255.0f;
    } else {
        ok = in.read_image(0, 0, 0, nch, OIIO::TypeDesc::FLOAT, raw.data());
    }
    // Some readers return true with an error recorded: a truncated JPEG (libjpeg pads it with
    // grey) or TIFF (missing strips left as zeros). Those pixels are not the file's: refuse them.
    if (!ok || in.has_error())
        throw std::runtime_error("read_image: cannot read pixels of '" + name + "': " + in.geterror());
    in.close();

    // Pick the colour and alpha channels.
    int alpha = spec.alpha_channel;
    if (alpha < 0 || alpha >= nch) alpha = nch == 2 ? 1 : (nch >= 4 ? 3 : -1);
    if (nch == 1) alpha = -1;  // a single channel is grey, whatever it is named
    std::array<int, 3> colour{};
    int found = 0;
    for (int c = 0; c < nch && found < 3; ++c)
        if (c != alpha) colour[found++] = c;
    if (found < 3) colour = {colour[0], colour[0], colour[0]};  // grey (or grey + alpha)

    const AlphaKind kind = alpha < 0 ? AlphaKind::none : alpha_kind(in, spec);
    if (kind != AlphaKind::none && in.format_name() == std::string("bmp") && all_zero(raw, nch, alpha))
        alpha = -1;  // a 32-bit BMP whose fourth byte is padding, not alpha (as browsers and stb_image read it)

    // Per pixel: the straight colour (integer files: still encoded), then decode and premultiply in
    // linear. ignore_alpha: alpha 1 and the straight colour.
    Image image(w, h, 4);
    for (std::size_t p = 0; p < n; ++p) {
        const float* src = &raw[p * nch];
        float* dst = &image.pixels[p * 4];
        const float a = alpha >= 0 ? src[alpha] : 1.0f;
        const bool associated = alpha >= 0 && kind == AlphaKind::associated;
        for (int c = 0; c < 3; ++c) {
            const float v = src[colour[c]];
            if (is_float) {  // linear: associated alpha is kept as it is (an EXR's colour may exceed alpha)
                const float straight = associated ? (a > 0.0f ? v / a : v) : v;
                dst[c] = options.ignore_alpha ? straight : (associated ? v : v * a);
            } else {
                // Integer colour stored premultiplied was multiplied in its own (encoded) space.
                const float encoded = associated ? (a > 0.0f ? std::min(v / a, 1.0f) : 0.0f) : v;
                const float linear = options.srgb ? srgb_to_linear(encoded) : encoded;
                dst[c] = options.ignore_alpha ? linear : linear * a;
            }
        }
        dst[3] = options.ignore_alpha ? 1.0f : a;
    }
    return image;
}

// Opens and decodes with OpenImageIO, whose readers can fail by throwing (a corrupt header
// asking for an impossible allocation): their exceptions become read_image's runtime_error.
template <typename Open>
Image open_and_decode(Open&& open, const std::string& name, const ImageReadOptions& options) {
    try {
        std::unique_ptr<OIIO::ImageInput> in = open();
        return decode_image(*in, name, options);
    } catch (const std::bad_alloc&) {
        throw std::runtime_error("read_image: cannot read '" + name + "': the decoder ran out of memory");
    } catch (const std::length_error& e) {
        throw std::runtime_error("read_image: cannot read '" + name + "': corrupt (the decoder failed: " +
                                 e.what() + ")");
    }
}

// The file format's extension, from the first bytes (OpenImageIO picks its reader by name).
std::string sniff_extension(const unsigned char* b, std::size_t size) {
    auto starts = [&](const char* magic, std::size_t n) { return size >= n && std::memcmp(b, magic, n) == 0; };
    if (starts("\x89PNG\r\n\x1a\n", 8)) return ".png";
    if (starts("\xff\xd8\xff", 3)) return ".jpg";
    if (starts("v/1\x01", 4)) return ".exr";
    if (starts("RIFF", 4) && size >= 12 && std::memcmp(b + 8, "WEBP", 4) == 0) return ".webp";
    if (starts("GIF8", 4)) return ".gif";
    if (starts("BM", 2)) return ".bmp";
    if (starts("II*\0", 4) || starts("MM\0*", 4)) return ".tif";
    if (starts("#?RADIANCE", 10) || starts("#?RGBE", 6)) return ".hdr";
    return "";
}

}  // namespace

Image read_image(const std::string& path) { return read_image(path, ImageReadOptions{}); }

Image read_image(const std::string& path, const ImageReadOptions& options) {
    // A regular file only: on a device or a pipe (/dev/zero, a FIFO) OpenImageIO's readers searched
    // the endless bytes for a header and never returned, and opening a FIFO waits for a writer.
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
        throw std::runtime_error("read_image: cannot read '" + path + "': not a regular file (" +
                                 (std::filesystem::is_directory(status) ? "a directory" : "a device, pipe or socket") +
                                 ")");
    // Open, asking for the file's own (straight) alpha so that we premultiply in linear space.
    unsigned char header[10];
    std::size_t got = 0;
    if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
        got = std::fread(header, 1, sizeof header, f);
        std::fclose(f);
    }
    check_gif_header(header, got, path);
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    const auto open = [&] {
        auto in = OIIO::ImageInput::open(path, &config);
        if (!in) {
            std::string message = OIIO::geterror();
            std::error_code ec;
            if (!std::filesystem::exists(path, ec)) message = "no such file";
            throw std::runtime_error("read_image: cannot read '" + path + "': " + message);
        }
        return in;
    };
    return open_and_decode(open, path, options);
}

Image read_image_from_memory(const void* bytes, std::size_t size, const std::string& name,
                             const ImageReadOptions& options) {
    if (size == 0 || bytes == nullptr) throw std::runtime_error("read_image: '" + name + "' is empty (0 bytes)");
    const auto* b = static_cast<const unsigned char*>(bytes);
    const std::string ext = sniff_extension(b, size);
    if (ext.empty())
        throw std::runtime_error("read_image: cannot read '" + name +
                                 "': not a recognized image format (expected PNG, JPEG, EXR, WebP, GIF, BMP, TIFF or HDR)");
    check_gif_header(b, size, name);
    OIIO::Filesystem::IOMemReader proxy(b, size);
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    // The proxy goes in the configuration hints as well: OpenImageIO 2.4's readers take it from
    // there when open() is given hints (the open() argument alone is dropped).
    OIIO::Filesystem::IOProxy* proxy_pointer = &proxy;
    config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy_pointer);
    // The name only tells OpenImageIO the format; the bytes come from the proxy.
    const auto open = [&] {
        auto in = OIIO::ImageInput::open("memory" + ext, &config, &proxy);
        if (!in) throw std::runtime_error("read_image: cannot read '" + name + "': " + OIIO::geterror());
        return in;
    };
    return open_and_decode(open, name, options);
}

}  // namespace mipraster
