// The texture cache (DESIGN.md §3 "Texture cache with mip levels", "mip levels that no lookup
// needs are never built"): levels and summed-area tables are built lazily, only when a lookup needs
// them; their bytes are accounted per texture and globally; a small budget evicts the derived data
// of unpinned textures (least recently pinned first) but never of a texture a TextureView pins;
// evicted data is rebuilt identically; get_or_load shares one texture per key; concurrent lookups
// on one texture from several threads give the same bits as sequential ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "mipraster/texture/sample.hpp"
#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture.hpp"
#include "texture_oracle.hpp"

namespace {

namespace mr = mipraster;
namespace to = tex_oracle;

constexpr std::size_t kDefaultBudget = std::size_t{1} << 30;

// Restores the global budget when a test ends, also when an assertion returns early.
struct BudgetGuard {
    ~BudgetGuard() { mr::TextureCache::global().set_budget(kDefaultBudget); }
};

// Bytes of levels 1..k of a w×h texture (RGBA float), from the size rule max(1, ⌊w/2^j⌋).
std::size_t level_bytes(int w, int h, int k) {
    std::size_t total = 0;
    for (int j = 1; j <= k; ++j) total += std::size_t(std::max(1, w >> j)) * std::size_t(std::max(1, h >> j)) * 16;
    return total;
}

mr::Texture random_texture(int w, int h, std::uint64_t seed) { return mr::Texture(to::random_level(w, h, seed), "random"); }

const glm::vec2 kZero(0.0f);

// A lookup that magnifies, or any lookup with mip filter none, builds no level and no table; a
// trilinear lookup at λ = 2.5 builds exactly levels 1–3; a minifying SAT lookup builds the table
// (on level 0 for a small texture) and no level.
TEST(TextureCache, LevelsAndTablesAreBuiltOnlyWhenALookupNeedsThem) {
    BudgetGuard guard;
    mr::TextureCache::global().set_budget(kDefaultBudget);
    mr::Texture tex = random_texture(64, 64, 1);
    const auto before = mr::TextureCache::global().stats();
    {
        mr::TextureView view(tex);
        for (const char* name : {"nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"}) {
            const mr::Sampler s = mr::Sampler::from_filter_name(name);
            mr::sample_texture(view, s, {0.3f, 0.4f}, kZero, kZero);                          // zero footprint
            mr::sample_texture(view, s, {0.3f, 0.4f}, {0.5f / 64, 0.0f}, {0.0f, 0.5f / 64});  // magnified
        }
        // Mip filter none never reads another level, however minified.
        for (const char* name : {"nearest", "bilinear"}) {
            const mr::Sampler s = mr::Sampler::from_filter_name(name);
            EXPECT_FALSE(s.uses_mip_levels()) << name;
            mr::sample_texture(view, s, {0.3f, 0.4f}, {1e3f, 0.0f}, {0.0f, 1e3f});
            mr::sample_texture(view, s, {0.3f, 0.4f}, {std::numeric_limits<float>::infinity(), 0.0f}, kZero);
        }
        EXPECT_EQ(tex.built_levels(), 0);
        EXPECT_FALSE(tex.has_summed_area_table());
        EXPECT_EQ(tex.derived_bytes(), 0u);

        // Trilinear at λ = 2.5 reads levels 2 and 3; the chain is built from level 1 down.
        const mr::Sampler tri = mr::Sampler::from_filter_name("trilinear");
        EXPECT_TRUE(tri.uses_mip_levels());
        mr::sample_texture(view, tri, {0.3f, 0.4f}, {std::exp2(2.5f) / 64, 0.0f}, kZero);
        EXPECT_EQ(tex.built_levels(), 3);
        EXPECT_EQ(tex.derived_bytes(), level_bytes(64, 64, 3));

        // SAT minified: the table of level 0, no further level.
        mr::sample_texture(view, mr::Sampler::from_filter_name("sat"), {0.3f, 0.4f}, {8.0f / 64, 0.0f}, kZero);
        EXPECT_TRUE(tex.has_summed_area_table());
        EXPECT_EQ(tex.built_levels(), 3);
        EXPECT_EQ(view.summed_area_table_level(), 0);
        EXPECT_EQ(tex.derived_bytes(), level_bytes(64, 64, 3) + mr::summed_area_table_bytes(64, 64));
        EXPECT_EQ(mr::summed_area_table_bytes(64, 64), std::size_t(65) * 65 * 32);
    }
    const auto after = mr::TextureCache::global().stats();
    EXPECT_EQ(after.levels_built - before.levels_built, 3u);
    EXPECT_EQ(after.tables_built - before.tables_built, 1u);
    EXPECT_EQ(after.derived_bytes - before.derived_bytes, tex.derived_bytes());
}

// Derived bytes are the sum of the built levels' and the table's bytes, in the texture and in the
// global total; destroying the texture gives them back.
TEST(TextureCache, DerivedBytesAreAccountedAndReleased) {
    BudgetGuard guard;
    mr::TextureCache::global().set_budget(kDefaultBudget);
    const std::size_t base = mr::TextureCache::global().stats().derived_bytes;
    std::size_t expected = 0;
    {
        mr::Texture tex = random_texture(37, 23, 2);  // 37×23 → 18×11 → 9×5 → 4×2 → 2×1 → 1×1
        {
            mr::TextureView view(tex);
            ASSERT_EQ(view.level_count(), 6);
            view.level(5);
            view.summed_area_table();
            expected = level_bytes(37, 23, 5) + mr::summed_area_table_bytes(37, 23);
            EXPECT_EQ(level_bytes(37, 23, 5), std::size_t(18 * 11 + 9 * 5 + 4 * 2 + 2 * 1 + 1) * 16);
        }
        EXPECT_EQ(tex.built_levels(), 5);
        EXPECT_EQ(tex.derived_bytes(), expected);
        EXPECT_EQ(mr::TextureCache::global().stats().derived_bytes - base, expected);
    }
    EXPECT_EQ(mr::TextureCache::global().stats().derived_bytes, base);
}

// A small budget drops the derived data of unpinned textures, least recently pinned first, and
// never that of a texture pinned by a live view (the total may then stay over budget); dropped
// levels are rebuilt bit for bit when needed again.
TEST(TextureCache, SmallBudgetEvictsUnpinnedNeverPinned) {
    BudgetGuard guard;
    mr::TextureCache& cache = mr::TextureCache::global();
    cache.set_budget(kDefaultBudget);
    const std::size_t per_texture = level_bytes(64, 64, 6);  // 21840 bytes
    mr::Texture a = random_texture(64, 64, 3), b = random_texture(64, 64, 4), c = random_texture(64, 64, 5);
    std::vector<glm::vec4> a_level2;
    {
        mr::TextureView va(a);
        va.level(6);
        a_level2 = va.level(2).texels;
    }
    { mr::TextureView(b).level(6); }
    ASSERT_EQ(a.built_levels(), 6);
    ASSERT_EQ(b.built_levels(), 6);
    const std::uint64_t evictions0 = cache.stats().evictions;

    // Room for about two textures' levels: building c's (pinned) evicts a, the least recently pinned.
    cache.set_budget(2 * per_texture + per_texture / 2);
    EXPECT_EQ(a.built_levels(), 6);  // within budget so far
    {
        mr::TextureView vc(c);
        vc.level(6);
        EXPECT_EQ(a.built_levels(), 0);
        EXPECT_EQ(a.derived_bytes(), 0u);
        EXPECT_EQ(b.built_levels(), 6);
        EXPECT_EQ(c.built_levels(), 6);
        EXPECT_EQ(cache.stats().evictions - evictions0, 1u);

        // Budget 0 while c is pinned: b goes, c stays, and its lookups keep working.
        const mr::Sampler tri = mr::Sampler::from_filter_name("trilinear");
        const glm::vec4 before = mr::sample_texture(vc, tri, {0.3f, 0.6f}, {0.1f, 0.0f}, kZero);
        cache.set_budget(0);
        EXPECT_EQ(b.built_levels(), 0);
        EXPECT_EQ(c.built_levels(), 6);
        EXPECT_GE(cache.stats().derived_bytes, per_texture);  // over budget: everything left is pinned
        EXPECT_EQ(mr::sample_texture(vc, tri, {0.3f, 0.6f}, {0.1f, 0.0f}, kZero), before);
    }
    // Unpinned now: the next eviction pass drops c too.
    cache.set_budget(0);
    EXPECT_EQ(c.built_levels(), 0);
    EXPECT_EQ(c.derived_bytes(), 0u);

    // Rebuilt identically.
    cache.set_budget(kDefaultBudget);
    mr::TextureView va(a);
    EXPECT_EQ(va.level(2).texels, a_level2);
    EXPECT_EQ(a.built_levels(), 2);
}

// A texture pinned by a view keeps its levels even when it is the only one over a zero budget,
// and building more of its levels under that budget evicts nothing of it.
TEST(TextureCache, PinnedTextureKeepsLevelsUnderZeroBudget) {
    BudgetGuard guard;
    mr::TextureCache& cache = mr::TextureCache::global();
    cache.set_budget(0);
    mr::Texture tex = random_texture(32, 16, 6);
    mr::TextureView view(tex);
    view.level(2);
    EXPECT_EQ(tex.built_levels(), 2);
    view.level(5);
    view.summed_area_table();
    EXPECT_EQ(tex.built_levels(), 5);
    EXPECT_TRUE(tex.has_summed_area_table());
    cache.set_budget(0);
    EXPECT_EQ(tex.built_levels(), 5);
}

// get_or_load returns the live texture stored under a key (loading once), so draws naming the
// same file share levels; another key loads another texture; once every copy is gone the key
// loads again; an empty load result is an error naming the key.
TEST(TextureCache, GetOrLoadSharesOneTexturePerKey) {
    mr::TextureCache& cache = mr::TextureCache::global();
    int loads = 0;
    auto load = [&] {
        ++loads;
        return random_texture(16, 16, 7);
    };
    {
        mr::Texture t1 = cache.get_or_load("test_texture_cache/shared", load);
        mr::Texture t2 = cache.get_or_load("test_texture_cache/shared", load);
        EXPECT_EQ(loads, 1);
        EXPECT_EQ(&t1.base_level(), &t2.base_level());
        { mr::TextureView(t1).level(3); }
        EXPECT_EQ(t2.built_levels(), 3);  // one texture: levels built through t1 are t2's
        mr::Texture other = cache.get_or_load("test_texture_cache/other", load);
        EXPECT_EQ(loads, 2);
        EXPECT_NE(&other.base_level(), &t1.base_level());
        EXPECT_GE(cache.stats().keyed_textures, 2u);
    }
    mr::Texture t3 = cache.get_or_load("test_texture_cache/shared", load);
    EXPECT_EQ(loads, 3);  // the earlier texture died with its last copy
    EXPECT_EQ(t3.built_levels(), 0);
    try {
        cache.get_or_load("test_texture_cache/empty", [] { return mr::Texture(); });
        ADD_FAILURE() << "an empty texture from load() was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("test_texture_cache/empty"), std::string::npos) << e.what();
    }
}

// Several threads asking for the same key at once all end up with one shared texture.
TEST(TextureCache, ConcurrentGetOrLoadSharesOneTexture) {
    mr::TextureCache& cache = mr::TextureCache::global();
    constexpr int kThreads = 8;
    std::vector<mr::Texture> got(kThreads);
    std::atomic<int> ready{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            ++ready;
            while (ready.load() < kThreads) std::this_thread::yield();
            got[t] = cache.get_or_load("test_texture_cache/concurrent", [] { return random_texture(64, 64, 8); });
        });
    for (std::thread& th : threads) th.join();
    for (int t = 1; t < kThreads; ++t) EXPECT_EQ(&got[t].base_level(), &got[0].base_level()) << "thread " << t;
}

// clear() forgets the keys and drops unpinned derived data; pinned textures keep theirs.
TEST(TextureCache, ClearForgetsKeysAndDropsUnpinnedData) {
    BudgetGuard guard;
    mr::TextureCache& cache = mr::TextureCache::global();
    cache.set_budget(kDefaultBudget);
    int loads = 0;
    auto load = [&] {
        ++loads;
        return random_texture(16, 16, 9);
    };
    mr::Texture keyed = cache.get_or_load("test_texture_cache/clear", load);
    mr::Texture pinned = random_texture(16, 16, 10);
    { mr::TextureView(keyed).level(4); }
    mr::TextureView view(pinned);
    view.level(4);
    cache.clear();
    EXPECT_EQ(keyed.built_levels(), 0);
    EXPECT_EQ(pinned.built_levels(), 4);
    mr::Texture again = cache.get_or_load("test_texture_cache/clear", load);
    EXPECT_EQ(loads, 2);
    EXPECT_NE(&again.base_level(), &keyed.base_level());
    EXPECT_EQ(cache.stats().budget_bytes, kDefaultBudget);  // clear keeps the budget
}

struct Query {
    int filter;
    glm::vec2 uv, dx, dy;
};

// Lookups from several threads on one fresh texture (levels and table built lazily while they
// race) give the same bits as the same lookups done sequentially on an identical texture, and
// each level and the table are built exactly once.
TEST(TextureCache, ConcurrentLookupsMatchSequential) {
    BudgetGuard guard;
    mr::TextureCache::global().set_budget(kDefaultBudget);
    const mr::TextureLevel level0 = to::random_level(128, 96, 11);
    std::vector<mr::Sampler> samplers;
    for (const char* name : {"trilinear", "anisotropic", "ewa", "sat", "bilinear"})
        samplers.push_back(mr::Sampler::from_filter_name(name));
    mr::Sampler nearest_mip;
    nearest_mip.mip_filter = mr::MipFilter::nearest;
    samplers.push_back(nearest_mip);

    std::mt19937_64 rng(12);
    std::uniform_real_distribution<float> d(-1.0f, 2.0f), lg(-2.0f, 7.0f), ang(0.0f, 6.2831853f);
    std::vector<Query> queries;
    for (int i = 0; i < 3000; ++i) {
        const float r1 = std::exp2(lg(rng)), r2 = std::exp2(lg(rng)), a = ang(rng), b = ang(rng);
        queries.push_back({i % int(samplers.size()), {d(rng), d(rng)}, {r1 * std::cos(a) / 128, r1 * std::sin(a) / 96},
                           {r2 * std::cos(b) / 128, r2 * std::sin(b) / 96}});
    }

    std::vector<glm::vec4> sequential(queries.size());
    {
        mr::Texture reference(level0, "sequential");
        mr::TextureView view(reference);
        for (std::size_t i = 0; i < queries.size(); ++i) {
            const Query& q = queries[i];
            sequential[i] = mr::sample_texture(view, samplers[q.filter], q.uv, q.dx, q.dy);
        }
    }

    mr::Texture shared(level0, "concurrent");
    const auto before = mr::TextureCache::global().stats();
    constexpr int kThreads = 4;
    std::vector<std::vector<glm::vec4>> results(kThreads, std::vector<glm::vec4>(queries.size()));
    std::atomic<int> ready{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            mr::TextureView view(shared);  // each thread pins it
            ++ready;
            while (ready.load() < kThreads) std::this_thread::yield();
            // Each thread walks the queries from a different start, so they race for different levels.
            for (std::size_t n = 0; n < queries.size(); ++n) {
                const std::size_t i = (n + t * queries.size() / kThreads) % queries.size();
                const Query& q = queries[i];
                results[t][i] = mr::sample_texture(view, samplers[q.filter], q.uv, q.dx, q.dy);
            }
        });
    for (std::thread& th : threads) th.join();
    const auto after = mr::TextureCache::global().stats();

    for (int t = 0; t < kThreads; ++t)
        for (std::size_t i = 0; i < queries.size(); ++i)
            ASSERT_EQ(std::memcmp(&results[t][i], &sequential[i], sizeof(glm::vec4)), 0) << "thread " << t << " query " << i;
    EXPECT_EQ(shared.built_levels(), shared.level_count() - 1);
    EXPECT_EQ(after.levels_built - before.levels_built, std::uint64_t(shared.level_count() - 1));
    EXPECT_EQ(after.tables_built - before.tables_built, 1u);
}

// Lookups racing with eviction: under a zero budget every released pin evicts the texture's
// derived data, while other threads pin the same textures, build their levels again and sample
// them. Every lookup gives the bits of the sequential reference, and nothing is left built.
TEST(TextureCache, ConcurrentLookupsAndEvictionMatchSequential) {
    BudgetGuard guard;
    constexpr int kTextures = 3, kThreads = 4, kRounds = 60;
    std::vector<mr::TextureLevel> levels;
    for (int i = 0; i < kTextures; ++i) levels.push_back(to::random_level(64 + 16 * i, 48, 40 + i));
    const mr::Sampler trilinear = mr::Sampler::from_filter_name("trilinear");
    const mr::Sampler sat = mr::Sampler::from_filter_name("sat");
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<float> d(-0.5f, 1.5f), lg(0.0f, 6.0f);
    std::vector<Query> queries;
    for (int i = 0; i < 64; ++i) {
        const float r = std::exp2(lg(rng)) / 64;
        queries.push_back({i % 2, {d(rng), d(rng)}, {r, 0.3f * r}, {-0.2f * r, r}});
    }
    auto lookup = [&](const mr::TextureView& view, const Query& q) {
        return mr::sample_texture(view, q.filter ? sat : trilinear, q.uv, q.dx, q.dy);
    };
    std::vector<std::vector<glm::vec4>> expected(kTextures);
    for (int i = 0; i < kTextures; ++i) {
        mr::Texture reference(levels[i], "reference");
        mr::TextureView view(reference);
        for (const Query& q : queries) expected[i].push_back(lookup(view, q));
    }

    std::vector<mr::Texture> shared;
    for (int i = 0; i < kTextures; ++i) shared.emplace_back(levels[i], "shared");
    mr::TextureCache::global().set_budget(0);
    const std::uint64_t evictions0 = mr::TextureCache::global().stats().evictions;
    std::atomic<int> mismatches{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            for (int round = 0; round < kRounds; ++round) {
                const int i = (t + round) % kTextures;
                mr::TextureView view(shared[i]);  // pins; its release evicts under the zero budget
                for (std::size_t k = 0; k < queries.size(); ++k) {
                    const glm::vec4 got = lookup(view, queries[k]);
                    if (std::memcmp(&expected[i][k], &got, sizeof got) != 0) ++mismatches;
                }
            }
        });
    for (std::thread& th : threads) th.join();
    EXPECT_EQ(mismatches.load(), 0);
    EXPECT_GT(mr::TextureCache::global().stats().evictions, evictions0);  // eviction did race the lookups
    for (const mr::Texture& tex : shared) EXPECT_EQ(tex.built_levels(), 0) << "unpinned under a zero budget";
}

}  // namespace
