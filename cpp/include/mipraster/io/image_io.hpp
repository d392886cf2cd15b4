#pragma once
// Image files: PNG (sRGB, 8 or 16 bits) and OpenEXR (linear float) output, and input from any format
// OpenImageIO reads. This is the only part of mipraster that depends on OpenImageIO; its header
// names no OpenImageIO type, so including it pulls in nothing from that library.
#include <cstddef>
#include <string>

#include "mipraster/core/image.hpp"

namespace mipraster {

/// How write_image stores an image.
struct ImageWriteOptions {
    int png_bits = 8;  ///< bits per channel of a PNG: 8 or 16 (other formats take only the default)
};

/// Writes `image` to `path`; the format follows the extension, compared case-insensitively:
///  - `.png`: 8 or 16 bits per channel (ImageWriteOptions::png_bits). A 4-channel image (linear,
///    premultiplied RGBA) is un-premultiplied and sRGB-encoded with `to_srgb8()` or
///    `to_srgb16()`, alpha stored linearly (straight alpha, as PNG defines it). A 3-channel image
///    (linear RGB, opaque) is sRGB-encoded the same way and written as RGB. A 1-channel image
///    (data such as depth or a mask) is written as plain grey: round(clamp(v, 0, 1) · max code),
///    with no sRGB encoding. NaN and ±inf have no code: they are refused (below).
///  - `.exr`: 32-bit float, values written exactly as they are (linear; RGBA stays premultiplied,
///    as OpenEXR defines it); 1-channel images are stored as channel "Y".
/// Throws std::invalid_argument for another extension, a malformed image (channels other than 1,
/// 3 or 4, zero size, pixel count not width·height·channels), png_bits other than 8 or 16 (or
/// not 8 for an EXR) or a NaN or ±inf value in a PNG (naming the first pixel (x, y) and channel;
/// nothing is written), and std::runtime_error naming the path and OpenImageIO's message when the
/// file cannot be opened or written.
void write_image(const std::string& path, const Image& image, const ImageWriteOptions& options = {});

/// Reads any file OpenImageIO can read into a linear, premultiplied RGBA float image (C = 4,
/// row 0 at the top, pixels in stored order: an EXIF orientation tag is not applied).
/// Integer-typed files (8-bit PNG or JPEG, 16-bit PNG or TIFF, …) are taken as sRGB-encoded:
/// colour channels are decoded with `srgb_to_linear`, alpha is used linearly (code / max code),
/// and colour is then multiplied by alpha. Files whose colour is stored premultiplied (TIFF
/// with associated alpha, and WebP, which OpenImageIO premultiplies as it decodes) are divided
/// by alpha in their encoded space first. Float-typed files (EXR, HDR, float TIFF) are linear
/// and kept as they are, multiplied by alpha only when the file says it is unassociated.
/// Transfer-function metadata in the file (PNG gAMA, sRGB, iCCP; OpenImageIO's
/// "oiio:ColorSpace") is ignored: the sample type and `ImageReadOptions::srgb` decide.
/// Grey becomes (g, g, g, 1), grey+alpha (g, g, g, a), RGB gets alpha 1, palette images their
/// palette colours (and tRNS alpha); channels past the fourth are ignored. A 32-bit BMP whose
/// fourth byte is zero everywhere is opaque (that byte is padding). Only the first subimage and
/// MIP level is read.
/// Note: a 1-channel PNG from `write_image` holds plain (not sRGB) grey, but reading it back
/// decodes it as sRGB like any 8-bit file; store data images as EXR to read them back exactly.
/// Throws std::runtime_error naming the path when the file is missing, unreadable or corrupt
/// (truncated files too, including those OpenImageIO decodes with a warning).
Image read_image(const std::string& path);

/// How read_image decodes a file (the defaults are read_image(path)'s).
struct ImageReadOptions {
    /// Integer-typed files: colour is sRGB-encoded (decoded with `srgb_to_linear`), else linear
    /// data read as code / max code. Float files are linear whatever this says.
    bool srgb = true;
    /// Drop the alpha channel: every pixel gets alpha 1 and keeps its straight (un-premultiplied)
    /// colour, for materials that ignore texture alpha (glTF OPAQUE, opaque OBJ materials).
    bool ignore_alpha = false;
};

/// read_image with decoding options. Also throws std::runtime_error for an image of more than
/// 2^29 pixels (the largest texture).
Image read_image(const std::string& path, const ImageReadOptions& options);

/// Decodes an image file held in memory (e.g. embedded in a glTF file), like read_image. The
/// format is recognized from the first bytes: PNG, JPEG, OpenEXR, WebP, GIF, BMP, TIFF or
/// Radiance HDR. `name` identifies the image in messages. Throws std::runtime_error naming
/// `name` for empty, unrecognized or corrupt bytes.
Image read_image_from_memory(const void* bytes, std::size_t size, const std::string& name,
                             const ImageReadOptions& options = {});

}  // namespace mipraster
