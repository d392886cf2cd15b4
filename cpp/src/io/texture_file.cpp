// Textures from image files: read_image / read_image_from_memory, shared through the texture cache.
#include "mipraster/io/texture_file.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <system_error>

#include "mipraster/io/image_io.hpp"

namespace mipraster {

namespace {

/// FNV-1a (64-bit): the content key of an embedded image.
std::uint64_t fnv1a(const unsigned char* bytes, std::size_t size) {
    std::uint64_t h = 14695981039346656037ull;
    for (std::size_t i = 0; i < size; ++i) {
        h ^= bytes[i];
        h *= 1099511628211ull;
    }
    return h;
}

std::string option_key(const TextureFileOptions& o) {
    return std::string(o.srgb ? "srgb" : "linear") + (o.ignore_alpha ? ",opaque" : "");
}

ImageReadOptions read_options(const TextureFileOptions& o) {
    ImageReadOptions r;
    r.srgb = o.srgb;
    r.ignore_alpha = o.ignore_alpha;
    return r;
}

}  // namespace

std::string TextureFileOptions::to_string() const {
    return std::string("TextureFileOptions(srgb=") + (srgb ? "true" : "false") +
           ", ignore_alpha=" + (ignore_alpha ? "true" : "false") + ")";
}

Texture load_texture(const std::string& path, const TextureFileOptions& options) {
    // Key: absolute path, options, and size + modification time so that a rewritten file is read again.
    std::error_code ec;
    std::filesystem::path absolute = std::filesystem::absolute(path, ec);
    if (ec) absolute = path;
    absolute = absolute.lexically_normal();
    std::string key = "file:" + absolute.string() + "|" + option_key(options);
    const auto size = std::filesystem::file_size(absolute, ec);
    if (!ec) key += "|" + std::to_string(size);
    const auto time = std::filesystem::last_write_time(absolute, ec);
    if (!ec) key += "|" + std::to_string(time.time_since_epoch().count());
    return TextureCache::global().get_or_load(key, [&] {
        return Texture::from_image(read_image(path, read_options(options)), path);
    });
}

Texture load_texture_from_memory(const void* bytes, std::size_t size, const std::string& name,
                                 const TextureFileOptions& options) {
    const auto* b = static_cast<const unsigned char*>(bytes);
    const std::string key = "memory:" + std::to_string(fnv1a(b, bytes ? size : 0)) + "|" + std::to_string(size) + "|" +
                            option_key(options);
    return TextureCache::global().get_or_load(key, [&] {
        return Texture::from_image(read_image_from_memory(bytes, size, name, read_options(options)), name);
    });
}

Texture error_texture() {
    return TextureCache::global().get_or_load("mipraster:error texture", [] {
        constexpr int kSize = 8;
        std::array<std::uint8_t, kSize * kSize * 4> texels{};
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                std::uint8_t* t = &texels[(y * kSize + x) * 4];
                const bool magenta = (x + y) % 2 == 0;
                t[0] = magenta ? 255 : 0;
                t[1] = 0;
                t[2] = magenta ? 255 : 0;
                t[3] = 255;
            }
        return Texture::from_8bit(texels.data(), kSize, kSize, 4, /*srgb=*/true, "error texture");
    });
}

}  // namespace mipraster
