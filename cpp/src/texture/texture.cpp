#include "mipraster/texture/texture.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <stdexcept>
#include <vector>

#include <glm/vec3.hpp>

#include "mipraster/core/colour.hpp"
#include "mipraster/core/constants.hpp"
#include "mipraster/core/memory_limit.hpp"

namespace mipraster {

namespace detail {

constexpr int kMaxLevels = 32;

struct TextureData {
    TextureLevel base;
    std::string name;
    int level_count = 1;

    // Derived data: owned under `mutex`, published through the atomics so lookups read a
    // built level without locking. Only an unpinned texture's derived data is ever freed.
    mutable std::mutex mutex;
    int pins = 0;
    std::uint64_t last_pinned = 0;
    std::array<std::unique_ptr<TextureLevel>, kMaxLevels> owned_levels;
    std::array<std::atomic<const TextureLevel*>, kMaxLevels> levels{};
    std::unique_ptr<SummedAreaTable> owned_table;
    std::atomic<const SummedAreaTable*> table{nullptr};
    int table_level = 0;
    std::size_t derived_bytes = 0;  // guarded by mutex

    ~TextureData() {
        if (derived_bytes) TextureCache::global().release(derived_bytes);
    }

    // Frees all derived data if no view pins it; returns the bytes freed. Caller holds `mutex`.
    std::size_t drop_derived() {
        if (pins || !derived_bytes) return 0;
        for (int k = 1; k < kMaxLevels; ++k) {
            levels[k].store(nullptr, std::memory_order_relaxed);
            owned_levels[k].reset();
        }
        table.store(nullptr, std::memory_order_relaxed);
        owned_table.reset();
        const std::size_t freed = derived_bytes;
        derived_bytes = 0;
        return freed;
    }
};

}  // namespace detail

using detail::TextureData;

namespace {

void check_size(int width, int height, int channels, const std::string& name) {
    if (width < 1 || height < 1)
        throw std::invalid_argument("texture '" + name + "': size " + std::to_string(width) + "x" +
                                    std::to_string(height) + " is empty; expected at least 1x1");
    if (width > kMaxTextureDimension || height > kMaxTextureDimension)
        throw std::invalid_argument("texture '" + name + "': size " + std::to_string(width) + "x" +
                                    std::to_string(height) + " exceeds the limit of " +
                                    std::to_string(kMaxTextureDimension) + " per side");
    const std::uint64_t bytes = std::uint64_t(width) * std::uint64_t(height) * sizeof(glm::vec4);
    if (bytes > kMaxTextureBytes)
        throw std::invalid_argument("texture '" + name + "': " + std::to_string(width) + "x" + std::to_string(height) +
                                    " needs " + std::to_string(bytes >> 20) + " MiB as RGBA float; the limit is " +
                                    std::to_string(kMaxTextureBytes >> 20) + " MiB");
    if (channels < 1 || channels > 4)
        throw std::invalid_argument("texture '" + name + "': " + std::to_string(channels) +
                                    " channels; expected 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA)");
    // Level 0 plus, when minified, its mip chain (at most a third more).
    check_memory(bytes + bytes / 3, "texture '" + name + "' (" + std::to_string(width) + "x" + std::to_string(height) +
                                        ", RGBA float with its mip chain)");
}

// Expands 1–4 channels to premultiplied RGBA. `colour(i)` and `alpha(i)` decode raw value i.
template <typename Decode, typename Alpha>
TextureLevel expand(int width, int height, int channels, bool premultiply, Decode colour, Alpha alpha) {
    TextureLevel level(width, height);
    const std::size_t n = level.texels.size();
    for (std::size_t p = 0; p < n; ++p) {
        const std::size_t i = p * static_cast<std::size_t>(channels);
        glm::vec4 t;
        if (channels <= 2) {
            t = glm::vec4(colour(i), colour(i), colour(i), channels == 2 ? alpha(i + 1) : 1.0f);
        } else {
            t = glm::vec4(colour(i), colour(i + 1), colour(i + 2), channels == 4 ? alpha(i + 3) : 1.0f);
        }
        if (premultiply) t = glm::vec4(glm::vec3(t) * t.a, t.a);
        level.texels[p] = t;
    }
    return level;
}

std::uint64_t tick() {
    static std::atomic<std::uint64_t> clock{0};
    return ++clock;
}

// The error for channel c of texel i (row-major, `width` a row) of texture `name`: its value v is
// not finite or beyond ±kMaxTexelMagnitude, or (given its alpha) v × alpha is.
[[noreturn]] void bad_texel(const std::string& name, int width, std::size_t i, int c, float v,
                            const float* alpha = nullptr) {
    char what[160] = " is not finite";
    if (std::isfinite(v) && std::fabs(v) > kMaxTexelMagnitude)
        std::snprintf(what, sizeof what,
                      " is %g; texel values must lie within ±%g so that the filters' sums stay finite", double(v),
                      double(kMaxTexelMagnitude));
    else if (alpha)
        std::snprintf(what, sizeof what, " is %g, times its alpha %g beyond ±%g (texels are premultiplied)", double(v),
                      double(*alpha), double(kMaxTexelMagnitude));
    throw std::invalid_argument("texture '" + name + "': texel (" + std::to_string(i % width) + ", " +
                                std::to_string(i / width) + ") channel " + std::to_string(c) + what);
}

}  // namespace

// ---- Texture -----------------------------------------------------------------------------------

Texture::Texture(TextureLevel level0, std::string name) {
    check_size(level0.width, level0.height, 4, name);
    if (level0.texels.size() != static_cast<std::size_t>(level0.width) * level0.height)
        throw std::invalid_argument("texture '" + name + "': " + std::to_string(level0.texels.size()) +
                                    " texels for a " + std::to_string(level0.width) + "x" +
                                    std::to_string(level0.height) + " level");
    for (std::size_t i = 0; i < level0.texels.size(); ++i)
        for (int c = 0; c < 4; ++c)
            if (!(std::fabs(level0.texels[i][c]) <= kMaxTexelMagnitude))
                bad_texel(name, level0.width, i, c, level0.texels[i][c]);
    data_ = std::make_shared<TextureData>();
    data_->level_count = mip_level_count(level0.width, level0.height);
    data_->base = std::move(level0);
    data_->name = std::move(name);
    TextureCache::global().register_texture(data_);
}

Texture Texture::from_8bit(const std::uint8_t* texels, int width, int height, int channels, bool srgb,
                           std::string name) {
    check_size(width, height, channels, name);
    std::array<float, 256> decode;
    for (int c = 0; c < 256; ++c) decode[c] = srgb ? srgb_to_linear(c / 255.0f) : c / 255.0f;
    return Texture(expand(width, height, channels, true, [&](std::size_t i) { return decode[texels[i]]; },
                          [&](std::size_t i) { return texels[i] / 255.0f; }),
                   std::move(name));
}

Texture Texture::from_16bit(const std::uint16_t* texels, int width, int height, int channels, bool srgb,
                            std::string name) {
    check_size(width, height, channels, name);
    std::vector<float> decode(65536);
    for (int c = 0; c < 65536; ++c) decode[c] = srgb ? srgb_to_linear(c / 65535.0f) : c / 65535.0f;
    return Texture(expand(width, height, channels, true, [&](std::size_t i) { return decode[texels[i]]; },
                          [&](std::size_t i) { return texels[i] / 65535.0f; }),
                   std::move(name));
}

Texture Texture::from_float(const float* texels, int width, int height, int channels, bool premultiplied,
                            std::string name) {
    check_size(width, height, channels, name);
    if (!premultiplied && channels % 2 == 0) {
        // The values as given, then their products with alpha: the constructor sees only the
        // products, and called one that overflowed "not finite" though every value given is finite.
        for (std::size_t p = 0; p < static_cast<std::size_t>(width) * static_cast<std::size_t>(height); ++p) {
            const float* const t = texels + p * static_cast<std::size_t>(channels);
            for (int c = 0; c < channels; ++c)  // (the last is alpha: channel 3 of the texture)
                if (!(std::fabs(t[c]) <= kMaxTexelMagnitude))
                    bad_texel(name, width, p, c == channels - 1 ? 3 : c, t[c]);
            for (int c = 0; c + 1 < channels; ++c)
                if (!(std::fabs(t[c] * t[channels - 1]) <= kMaxTexelMagnitude))
                    bad_texel(name, width, p, c, t[c], &t[channels - 1]);
        }
    }
    auto value = [&](std::size_t i) { return texels[i]; };
    return Texture(expand(width, height, channels, !premultiplied, value, value), std::move(name));
}

Texture Texture::from_image(const Image& image, std::string name) {
    check_size(image.width, image.height, image.channels, name);
    return from_float(image.pixels.data(), image.width, image.height, image.channels, true, std::move(name));
}

int Texture::width() const { return data_ ? data_->base.width : 0; }
int Texture::height() const { return data_ ? data_->base.height : 0; }
int Texture::level_count() const { return data_ ? data_->level_count : 0; }

const std::string& Texture::name() const {
    static const std::string none;
    return data_ ? data_->name : none;
}

const TextureLevel& Texture::base_level() const {
    if (!data_) throw std::logic_error("empty texture");
    return data_->base;
}

int Texture::built_levels() const {
    if (!data_) return 0;
    std::lock_guard<std::mutex> lock(data_->mutex);
    int n = 0;
    for (int k = 1; k < data_->level_count; ++k) n += data_->owned_levels[k] != nullptr;
    return n;
}

bool Texture::has_summed_area_table() const {
    if (!data_) return false;
    std::lock_guard<std::mutex> lock(data_->mutex);
    return data_->owned_table != nullptr;
}

std::size_t Texture::derived_bytes() const {
    if (!data_) return 0;
    std::lock_guard<std::mutex> lock(data_->mutex);
    return data_->derived_bytes;
}

std::string Texture::to_string() const {
    if (!data_) return "Texture(empty)";
    return "Texture('" + data_->name + "', " + std::to_string(width()) + "x" + std::to_string(height()) + ", " +
           std::to_string(level_count()) + " levels, " + std::to_string(built_levels()) + " built)";
}

// ---- TextureView -------------------------------------------------------------------------------

TextureView::TextureView(const Texture& texture) : data_(texture.data_.get()) {
    if (!data_) throw std::invalid_argument("TextureView: the texture is empty");
    std::lock_guard<std::mutex> lock(data_->mutex);
    ++data_->pins;
    data_->last_pinned = tick();
    base_ = &data_->base;
    published_ = data_->levels.data();
    width_ = data_->base.width;
    height_ = data_->base.height;
    levels_ = data_->level_count;
}

TextureView::TextureView(TextureView&& other) noexcept
    : data_(other.data_), base_(other.base_), published_(other.published_), width_(other.width_),
      height_(other.height_), levels_(other.levels_) {
    other.data_ = nullptr;
}

TextureView::~TextureView() {
    if (!data_) return;
    {
        std::lock_guard<std::mutex> lock(data_->mutex);
        --data_->pins;
    }
    TextureCache::global().evict_if_over_budget();  // what this view pinned may now go
}

const TextureLevel& TextureView::build_level(int k) const {
    if (k < 0 || k >= levels_)
        throw std::out_of_range("texture '" + data_->name + "': level " + std::to_string(k) + " does not exist (0.." +
                                std::to_string(levels_ - 1) + ")");
    if (k == 0) return data_->base;
    if (const TextureLevel* built = data_->levels[k].load(std::memory_order_acquire)) return *built;
    std::size_t added = 0;
    int built = 0;
    {
        std::lock_guard<std::mutex> lock(data_->mutex);
        // Build every missing level from the finest built one down to k.
        for (int j = 1; j <= k; ++j) {
            if (data_->owned_levels[j]) continue;
            const TextureLevel& source = j == 1 ? data_->base : *data_->owned_levels[j - 1];
            data_->owned_levels[j] = std::make_unique<TextureLevel>(downsample(source));
            data_->levels[j].store(data_->owned_levels[j].get(), std::memory_order_release);
            added += data_->owned_levels[j]->bytes();
            ++built;
        }
        data_->derived_bytes += added;
    }
    if (built) TextureCache::global().charge(added, built, 0);
    return *data_->levels[k].load(std::memory_order_acquire);
}

int TextureView::summed_area_table_level() const {
    int k = 0;
    while (k + 1 < levels_ && summed_area_table_bytes(std::max(1, width_ >> k), std::max(1, height_ >> k)) >
                                  kMaxSummedAreaTableBytes)
        ++k;
    return k;
}

const SummedAreaTable& TextureView::summed_area_table() const {
    if (const SummedAreaTable* built = data_->table.load(std::memory_order_acquire)) return *built;
    const int k = summed_area_table_level();
    const TextureLevel& source = level(k);
    std::size_t added = 0;
    {
        std::lock_guard<std::mutex> lock(data_->mutex);
        if (!data_->owned_table) {
            data_->owned_table = std::make_unique<SummedAreaTable>(source);
            data_->table_level = k;
            data_->table.store(data_->owned_table.get(), std::memory_order_release);
            added = data_->owned_table->bytes();
            data_->derived_bytes += added;
        }
    }
    if (added) TextureCache::global().charge(added, 0, 1);
    return *data_->table.load(std::memory_order_acquire);
}

// ---- TextureCache ------------------------------------------------------------------------------

struct TextureCache::Impl {
    std::mutex mutex;
    std::size_t budget = std::size_t{1} << 30;
    std::atomic<std::size_t> derived_bytes{0};
    std::uint64_t levels_built = 0, tables_built = 0, evictions = 0;
    std::atomic<std::size_t> budget_now{std::size_t{1} << 30};  // `budget`, readable without the lock
    std::vector<std::weak_ptr<TextureData>> live;
    std::size_t live_after_prune = 64;
    std::map<std::string, std::weak_ptr<TextureData>> keyed;

    // Drops the derived data of least recently pinned, unpinned textures until within budget.
    // Caller holds `mutex`.
    void evict_to_budget() {
        live.erase(std::remove_if(live.begin(), live.end(), [](const auto& w) { return w.expired(); }), live.end());
        while (derived_bytes.load() > budget) {
            std::shared_ptr<TextureData> victim;
            std::uint64_t oldest = ~std::uint64_t{0};
            for (const auto& weak : live) {
                std::shared_ptr<TextureData> d = weak.lock();
                if (!d) continue;
                std::lock_guard<std::mutex> lock(d->mutex);
                if (d->pins == 0 && d->derived_bytes && d->last_pinned < oldest) {
                    oldest = d->last_pinned;
                    victim = d;
                }
            }
            if (!victim) return;  // everything left is pinned: over budget until a render ends
            std::size_t freed;
            {
                std::lock_guard<std::mutex> lock(victim->mutex);
                freed = victim->drop_derived();
            }
            derived_bytes -= freed;
            if (freed) ++evictions;
        }
    }
};

TextureCache& TextureCache::global() {
    static TextureCache cache;
    return cache;
}

TextureCache::Impl& TextureCache::impl() const {
    static Impl instance;
    return instance;
}

void TextureCache::set_budget(std::size_t bytes) {
    std::lock_guard<std::mutex> lock(impl().mutex);
    impl().budget = bytes;
    impl().budget_now = bytes;
    impl().evict_to_budget();
}

TextureCacheStats TextureCache::stats() const {
    Impl& m = impl();
    std::lock_guard<std::mutex> lock(m.mutex);
    TextureCacheStats s;
    s.budget_bytes = m.budget;
    s.derived_bytes = m.derived_bytes.load();
    s.levels_built = m.levels_built;
    s.tables_built = m.tables_built;
    s.evictions = m.evictions;
    for (const auto& entry : m.keyed) s.keyed_textures += !entry.second.expired();
    return s;
}

Texture TextureCache::get_or_load(const std::string& key, const std::function<Texture()>& load) {
    Impl& m = impl();
    {
        std::lock_guard<std::mutex> lock(m.mutex);
        auto it = m.keyed.find(key);
        if (it != m.keyed.end()) {
            if (std::shared_ptr<TextureData> d = it->second.lock()) {
                Texture t;
                t.data_ = std::move(d);
                return t;
            }
        }
    }
    Texture t = load();  // outside the lock: loading may take long and may itself use the cache
    if (!t) throw std::invalid_argument("texture cache: loading '" + key + "' gave an empty texture");
    std::lock_guard<std::mutex> lock(m.mutex);
    std::weak_ptr<TextureData>& slot = m.keyed[key];
    if (std::shared_ptr<TextureData> d = slot.lock()) {  // another thread loaded it meanwhile
        Texture shared;
        shared.data_ = std::move(d);
        return shared;
    }
    slot = t.data_;
    return t;
}

void TextureCache::clear() {
    Impl& m = impl();
    std::lock_guard<std::mutex> lock(m.mutex);
    m.keyed.clear();
    const std::size_t budget = m.budget;
    const std::uint64_t evictions = m.evictions;
    m.budget = 0;
    m.evict_to_budget();
    m.budget = budget;
    m.evictions = evictions;  // a clear is not an eviction
}

void TextureCache::register_texture(const std::shared_ptr<TextureData>& data) {
    Impl& m = impl();
    std::lock_guard<std::mutex> lock(m.mutex);
    // Forget dead textures whenever the list has doubled, so it stays proportional to the live ones.
    if (m.live.size() >= 2 * m.live_after_prune) {
        m.live.erase(std::remove_if(m.live.begin(), m.live.end(), [](const auto& w) { return w.expired(); }),
                     m.live.end());
        m.live_after_prune = std::max<std::size_t>(m.live.size(), 64);
    }
    m.live.push_back(data);
}

void TextureCache::evict_if_over_budget() {
    Impl& m = impl();
    if (m.derived_bytes.load() <= m.budget_now.load()) return;
    std::lock_guard<std::mutex> lock(m.mutex);
    m.evict_to_budget();
}

void TextureCache::charge(std::size_t bytes, int levels, int tables) {
    Impl& m = impl();
    std::lock_guard<std::mutex> lock(m.mutex);
    m.derived_bytes += bytes;
    m.levels_built += static_cast<std::uint64_t>(levels);
    m.tables_built += static_cast<std::uint64_t>(tables);
    m.evict_to_budget();
}

void TextureCache::release(std::size_t bytes) { impl().derived_bytes -= bytes; }

}  // namespace mipraster
