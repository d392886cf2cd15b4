#pragma once
// Textures: level 0 as given, mip levels and summed-area tables built lazily the first time a
// lookup needs them, under a process-wide byte budget with least-recently-used eviction.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "mipraster/core/image.hpp"
#include "mipraster/texture/summed_area_table.hpp"
#include "mipraster/texture/texture_level.hpp"

namespace mipraster {

/// Largest texture width or height.
inline constexpr int kMaxTextureDimension = 1 << 16;
/// Largest level 0 in bytes (RGBA float): 16384² fits, with room for non-square shapes.
inline constexpr std::uint64_t kMaxTextureBytes = std::uint64_t{8} << 30;
/// A summed-area table is built on the finest level whose table fits in this many bytes, so a
/// 2048² texture gets an exact level-0 table and a 16384² one a table of level 3.
inline constexpr std::size_t kMaxSummedAreaTableBytes = std::size_t{256} << 20;

namespace detail {
struct TextureData;
}

/// A shared, immutable texture: copies refer to the same texels and the same lazily built
/// levels. Level 0 holds linear, premultiplied RGBA floats.
class Texture {
public:
    Texture() = default;
    /// From linear premultiplied texels. `name` identifies the texture in messages.
    Texture(TextureLevel level0, std::string name);

    /// From 8-bit texels, (height, width, channels) row-major with channels 1 (grey), 2 (grey,
    /// alpha), 3 (RGB) or 4 (RGBA). Colour is decoded from sRGB when `srgb` (else code/255),
    /// alpha is linear (straight), and colour is premultiplied after decoding.
    static Texture from_8bit(const std::uint8_t* texels, int width, int height, int channels, bool srgb,
                             std::string name);
    /// From 16-bit texels with the same layouts: colour is decoded from sRGB when `srgb` (else
    /// code/65535), alpha is code/65535 (straight), and colour is premultiplied after decoding.
    static Texture from_16bit(const std::uint16_t* texels, int width, int height, int channels, bool srgb,
                              std::string name);
    /// From linear float texels with the same channel layouts. `premultiplied` says whether
    /// colour already includes alpha. Throws for a non-finite texel, naming it.
    static Texture from_float(const float* texels, int width, int height, int channels, bool premultiplied,
                              std::string name);
    /// From an image as read_image returns it (linear, premultiplied).
    static Texture from_image(const Image& image, std::string name);

    explicit operator bool() const { return data_ != nullptr; }
    int width() const;
    int height() const;
    int level_count() const;
    const std::string& name() const;
    /// Level 0 (always present).
    const TextureLevel& base_level() const;
    /// How many levels beyond 0 are built now, and the bytes they and the table hold.
    int built_levels() const;
    bool has_summed_area_table() const;
    std::size_t derived_bytes() const;

    std::string to_string() const;

private:
    friend class TextureView;
    friend class TextureCache;
    std::shared_ptr<detail::TextureData> data_;
};

/// A pinned texture: while a view exists its derived levels are not evicted, and level(k)
/// builds a missing level (thread-safe; concurrent lookups wait for one build).
class TextureView {
public:
    explicit TextureView(const Texture& texture);
    ~TextureView();
    TextureView(const TextureView&) = delete;
    TextureView& operator=(const TextureView&) = delete;
    TextureView(TextureView&& other) noexcept;
    TextureView& operator=(TextureView&&) = delete;

    int width() const { return width_; }
    int height() const { return height_; }
    int level_count() const { return levels_; }
    /// Level k, 0 ≤ k < level_count() (else std::out_of_range); built (with the levels above it)
    /// on first use. Inline for built levels: lookups ask for a level or two each.
    const TextureLevel& level(int k) const {
        if (k == 0) return *base_;
        if (k > 0 && k < levels_)
            if (const TextureLevel* built = published_[k].load(std::memory_order_acquire)) return *built;
        return build_level(k);
    }
    /// Level k if it exists and is built, else null (builds nothing).
    const TextureLevel* built_level(int k) const {
        if (k == 0) return base_;
        return k > 0 && k < levels_ ? published_[k].load(std::memory_order_acquire) : nullptr;
    }
    /// The summed-area table and the level it was built on.
    const SummedAreaTable& summed_area_table() const;
    int summed_area_table_level() const;

private:
    const TextureLevel& build_level(int k) const;  // builds level k, or throws for a bad k

    detail::TextureData* data_;
    const TextureLevel* base_;
    const std::atomic<const TextureLevel*>* published_;  // the data's built levels (null: not yet)
    int width_, height_, levels_;
};

struct TextureCacheStats {
    std::size_t budget_bytes = 0;
    std::size_t derived_bytes = 0;       ///< mip levels ≥ 1 and tables held now, all textures
    std::uint64_t levels_built = 0;      ///< since start
    std::uint64_t tables_built = 0;
    std::uint64_t evictions = 0;         ///< textures whose derived data was dropped
    std::size_t keyed_textures = 0;      ///< live textures reachable through get_or_load
};

/// The process-wide cache. Its budget bounds the derived data (levels ≥ 1 and summed-area tables)
/// of textures not pinned by a view; level 0 belongs to the texture. When a build pushes the
/// total over the budget, the derived data of the least recently pinned unpinned textures is
/// dropped (it is rebuilt identically if needed again).
class TextureCache {
public:
    static TextureCache& global();

    void set_budget(std::size_t bytes);
    TextureCacheStats stats() const;

    /// The live texture stored under `key`, or `load()`'s result, stored under it. Lets draws
    /// and materials that name the same file share one texture.
    Texture get_or_load(const std::string& key, const std::function<Texture()>& load);

    /// Drops the derived data of every unpinned texture and forgets the keys.
    void clear();

    // Used by textures.
    void register_texture(const std::shared_ptr<detail::TextureData>& data);
    void charge(std::size_t bytes, int levels, int tables);
    void release(std::size_t bytes);
    void evict_if_over_budget();

private:
    TextureCache() = default;
    struct Impl;
    Impl& impl() const;
};

}  // namespace mipraster
