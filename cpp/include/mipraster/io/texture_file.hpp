#pragma once
// Textures from image files: decoded through read_image (OpenImageIO) into linear premultiplied
// RGBA and shared through TextureCache::global(), so that materials and scene files naming the
// same image get one texture. Part of mipraster_io.
#include <cstddef>
#include <string>

#include "mipraster/texture/texture.hpp"

namespace mipraster {

/// How an image file becomes a texture.
struct TextureFileOptions {
    /// 8- and 16-bit files hold sRGB-encoded colour (colour textures, DESIGN.md §1), else linear
    /// data (code / max code). Float files (EXR, HDR) are linear either way.
    bool srgb = true;
    /// Ignore the file's alpha: alpha 1 with the straight colour (for materials that are opaque
    /// whatever their texture's alpha says: glTF OPAQUE, opaque OBJ materials).
    bool ignore_alpha = false;

    std::string to_string() const;
};

/// The texture of the image file at `path` (any format read_image reads), named by the path.
/// Shared: the cache key is the absolute path, the options and the file's size and modification
/// time, so loading the same unchanged file again returns the same texture while a rewritten file
/// is read anew. Throws std::runtime_error naming the path for a missing, unreadable or corrupt
/// file, and std::invalid_argument for an image too large for a texture.
Texture load_texture(const std::string& path, const TextureFileOptions& options = {});

/// load_texture with only the colour space chosen (alpha kept).
inline Texture load_texture(const std::string& path, bool srgb) {
    TextureFileOptions options;
    options.srgb = srgb;
    return load_texture(path, options);
}

/// The texture of an image file held in memory (PNG, JPEG, ... as read_image_from_memory
/// recognizes them), named `name`. Shared by content: the cache key is a 64-bit FNV-1a hash of
/// the bytes with their length and the options. Throws std::runtime_error naming `name` for
/// bytes that do not decode.
Texture load_texture_from_memory(const void* bytes, std::size_t size, const std::string& name,
                                 const TextureFileOptions& options = {});

/// The texture that stands in for one that cannot be loaded: an 8×8 checker of magenta
/// (sRGB 255, 0, 255) and black 1×1-texel squares, opaque, named "error texture", so a missing
/// file is visible in the render instead of aborting it. Always the same shared texture.
Texture error_texture();

}  // namespace mipraster
