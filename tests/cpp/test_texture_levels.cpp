// Mip levels, LOD selection and sRGB decoding (DESIGN.md §1 mip levels / LOD / colour, §2.7):
// level sizes follow max(1, ⌊w/2^k⌋); downsampling is the 2×2 box for even sizes and exactly
// area-weighted for odd ones (every source texel contributes), so every level keeps the mean;
// λ = log2 ρ with bias and clamps; nearest-mip picks ⌈λ + ½⌉ − 1 (GL); trilinear blends by
// frac(λ); 8-bit sRGB is decoded (and alpha premultiplied) in linear space before filtering, so
// a black/white checker reduces to sRGB8 188. Oracles: texture_oracle.hpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "mipraster/core/colour.hpp"
#include "mipraster/texture/sample.hpp"
#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture.hpp"
#include "mipraster/texture/texture_level.hpp"
#include "texture_oracle.hpp"

namespace {

namespace mr = mipraster;
namespace to = tex_oracle;

const std::vector<std::pair<int, int>> kChainSizes = {{1, 1}, {1, 7}, {7, 1}, {3, 5}, {5, 3}, {2, 9},
                                                      {17, 9}, {37, 23}, {64, 64}, {65, 31}, {100, 1}};

// ---- Level sizes -------------------------------------------------------------------------------

// Level k is max(1, ⌊w/2^k⌋)×max(1, ⌊h/2^k⌋) down to 1×1: the count and every level's size.
TEST(TextureLevels, LevelCountAndSizesFollowFloorHalving) {
    for (int w = 1; w <= 70; ++w)
        for (int h = 1; h <= 70; ++h) ASSERT_EQ(mr::mip_level_count(w, h), to::level_count(w, h)) << w << "x" << h;
    for (auto [w, h] : std::vector<std::pair<int, int>>{{65536, 1}, {1, 65536}, {1000, 3}, {4097, 4095}, {2048, 2048}})
        EXPECT_EQ(mr::mip_level_count(w, h), to::level_count(w, h)) << w << "x" << h;
    EXPECT_EQ(mr::mip_level_count(1, 1), 1);
    EXPECT_EQ(mr::mip_level_count(256, 256), 9);
    EXPECT_EQ(mr::mip_level_count(3, 5), 3);  // 3×5 → 1×2 → 1×1
    for (auto [w, h] : kChainSizes) {
        mr::Texture tex(to::random_level(w, h, 5), "random");
        mr::TextureView view(tex);
        ASSERT_EQ(view.level_count(), to::level_count(w, h));
        for (int k = 0; k < view.level_count(); ++k) {
            EXPECT_EQ(view.level(k).width, std::max(1, w >> k)) << w << "x" << h << " level " << k;
            EXPECT_EQ(view.level(k).height, std::max(1, h >> k)) << w << "x" << h << " level " << k;
        }
        EXPECT_EQ(view.level(view.level_count() - 1).texels.size(), 1u);
    }
}

// ---- Downsampling ------------------------------------------------------------------------------

// Even sizes: each output texel is the plain mean of its 2×2 block.
TEST(TextureLevels, DownsampleOfEvenSizeIsTwoByTwoBox) {
    for (auto [w, h] : std::vector<std::pair<int, int>>{{2, 2}, {16, 8}, {6, 10}, {64, 2}}) {
        const mr::TextureLevel src = to::random_level(w, h, 17 + w);
        const mr::TextureLevel out = mr::downsample(src);
        ASSERT_EQ(out.width, w / 2);
        ASSERT_EQ(out.height, h / 2);
        for (int y = 0; y < h / 2; ++y)
            for (int x = 0; x < w / 2; ++x) {
                const glm::dvec4 box = 0.25 * (glm::dvec4(src.at(2 * x, 2 * y)) + glm::dvec4(src.at(2 * x + 1, 2 * y)) +
                                               glm::dvec4(src.at(2 * x, 2 * y + 1)) +
                                               glm::dvec4(src.at(2 * x + 1, 2 * y + 1)));
                for (int c = 0; c < 4; ++c)
                    ASSERT_EQ(out.at(x, y)[c], float(box[c])) << w << "x" << h << " texel " << x << "," << y;
            }
    }
}

// Odd (and 1-wide) sizes: output texel i covers [i·n/m, (i+1)·n/m) of the source; weights are
// the exact overlaps (oracle with integer arithmetic). Matches to the float rounding of the output.
TEST(TextureLevels, DownsampleOfOddSizeIsAreaWeighted) {
    double worst = 0.0;
    for (auto [w, h] : std::vector<std::pair<int, int>>{{3, 5}, {7, 7}, {17, 9}, {1, 7}, {7, 1}, {5, 2}, {9, 1}, {3, 3}, {101, 33}}) {
        const mr::TextureLevel src = to::random_level(w, h, 31 + w * h);
        const mr::TextureLevel out = mr::downsample(src);
        const to::DLevel expected = to::downsample(to::to_double(src));
        ASSERT_EQ(out.width, expected.width);
        ASSERT_EQ(out.height, expected.height);
        for (int y = 0; y < out.height; ++y)
            for (int x = 0; x < out.width; ++x)
                for (int c = 0; c < 4; ++c) {
                    const double err = std::abs(out.at(x, y)[c] - expected.at(x, y)[c]);
                    worst = std::max(worst, err);
                    ASSERT_LE(err, 6e-8) << w << "x" << h << " texel " << x << "," << y;
                }
    }
    std::cout << "odd-size downsample vs rational area weights: worst abs error " << worst << "\n";
}

// Every source texel contributes, in proportion to its area: downsampling a unit impulse at any
// texel gives a total of (m/n)·(m'/n') over the output (each texel's weights sum to m/n per axis).
TEST(TextureLevels, EverySourceTexelContributesByArea) {
    for (auto [w, h] : std::vector<std::pair<int, int>>{{3, 5}, {7, 3}, {9, 9}, {1, 5}, {6, 7}}) {
        const int m = std::max(1, w / 2), mh = std::max(1, h / 2);
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i) {
                const mr::TextureLevel impulse =
                    to::make_level(w, h, [&](int x, int y) { return glm::vec4(x == i && y == j ? 1.0f : 0.0f); });
                const mr::TextureLevel out = mr::downsample(impulse);
                double total = 0.0;
                for (const glm::vec4& t : out.texels) total += t.x;
                EXPECT_NEAR(total, double(m) * mh / (double(w) * h), 1e-7) << w << "x" << h << " texel " << i << "," << j;
            }
    }
}

// The mean of every level equals the mean of level 0 (the area weights partition each source
// texel), up to the float rounding of each stored level.
TEST(TextureLevels, EveryLevelKeepsTheMean) {
    double worst = 0.0;
    for (auto [w, h] : kChainSizes) {
        mr::Texture tex(to::random_level(w, h, 77 + w), "random");
        mr::TextureView view(tex);
        const glm::dvec4 m0 = to::mean(to::to_double(view.level(0)));
        for (int k = 1; k < view.level_count(); ++k) {
            const glm::dvec4 mk = to::mean(to::to_double(view.level(k)));
            for (int c = 0; c < 4; ++c) {
                const double err = std::abs(mk[c] - m0[c]);
                worst = std::max(worst, err);
                EXPECT_LE(err, 2e-7) << w << "x" << h << " level " << k << " channel " << c;
            }
        }
    }
    std::cout << "level mean vs level-0 mean: worst abs difference " << worst << "\n";
}

// Whole chains (1×1, 1×N, 3×5, 17×9, …) against the oracle chain kept in double from level 0.
TEST(TextureLevels, ChainsMatchDoublePrecisionOracle) {
    double worst = 0.0;
    for (auto [w, h] : kChainSizes) {
        mr::Texture tex(to::random_level(w, h, 99 + h), "random");
        mr::TextureView view(tex);
        to::DLevel expected = to::to_double(view.level(0));
        for (int k = 1; k < view.level_count(); ++k) {
            expected = to::downsample(expected);
            const mr::TextureLevel& got = view.level(k);
            ASSERT_EQ(got.width, expected.width);
            ASSERT_EQ(got.height, expected.height);
            for (int y = 0; y < got.height; ++y)
                for (int x = 0; x < got.width; ++x)
                    for (int c = 0; c < 4; ++c) {
                        const double err = std::abs(got.at(x, y)[c] - expected.at(x, y)[c]);
                        worst = std::max(worst, err);
                        ASSERT_LE(err, 3e-7) << w << "x" << h << " level " << k << " texel " << x << "," << y;
                    }
        }
    }
    std::cout << "mip chains vs double oracle: worst abs error " << worst << "\n";
}

// A constant level reduces to the same constant bit for bit at every size.
TEST(TextureLevels, ConstantLevelReducesToItselfExactly) {
    const glm::vec4 c(0.1f, 1.0f / 3.0f, 0.7f, 0.99f);
    for (auto [w, h] : kChainSizes) {
        mr::Texture tex(to::make_level(w, h, [&](int, int) { return c; }), "constant");
        mr::TextureView view(tex);
        for (int k = 1; k < view.level_count(); ++k)
            for (const glm::vec4& t : view.level(k).texels) ASSERT_EQ(t, c) << w << "x" << h << " level " << k;
    }
}

// The largest texture the issue names: 16384² (4 GiB of RGBA float at level 0, 1.3 GiB of levels).
// A checker of 2048-texel squares has exact box means at every level: level k ≤ 11 is a checker of
// 2048/2^k-texel squares, levels 12 and finer-than-a-square average to 0.5 exactly.
TEST(TextureLevels, A16384SquareTextureBuildsEveryLevelExactly) {
    constexpr int n = 16384, square = 2048;
    mr::TextureLevel level0(n, n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) level0.at(x, y) = glm::vec4(float((x / square + y / square) % 2));
    mr::Texture tex(std::move(level0), "checker 16384");
    mr::TextureView view(tex);
    ASSERT_EQ(view.level_count(), 15);
    for (int k = 1; k < view.level_count(); ++k) {
        const mr::TextureLevel& level = view.level(k);
        ASSERT_EQ(level.width, n >> k);
        const int side = square >> k;  // squares at level k, in texels (0 once they are smaller)
        for (int y = 0; y < level.height; y += std::max(1, level.height / 64))
            for (int x = 0; x < level.width; x += std::max(1, level.width / 64)) {
                const float expected = side >= 1 ? float((x / side + y / side) % 2) : 0.5f;
                ASSERT_EQ(level.at(x, y).r, expected) << "level " << k << " texel " << x << "," << y;
            }
    }
    // Trilinear half-way between levels 12 and 13 (both uniformly 0.5) is 0.5.
    const mr::Sampler s = mr::Sampler::from_filter_name("trilinear");
    const float d = std::ldexp(1.0f, 12) * std::sqrt(2.0f) / n;
    EXPECT_EQ(mr::sample_texture(view, s, {0.3f, 0.7f}, {d, 0.0f}, {0.0f, d}).r, 0.5f);
}

// ---- LOD selection -----------------------------------------------------------------------------

mr::Texture random_texture(int w, int h, std::uint64_t seed) { return mr::Texture(to::random_level(w, h, seed), "random"); }

// With ∂uv/∂x = 2^k texels per pixel, λ = log2 ρ = k exactly (clamped to the last level), for
// either derivative, non-square textures, and ρ taken as the longer derivative.
TEST(TextureLod, LodIsLog2OfPowerOfTwoScale) {
    // Power-of-two sizes: 2^k / w is exact in float, so ρ is exactly 2^k.
    for (auto [w, h] : std::vector<std::pair<int, int>>{{256, 256}, {64, 16}, {128, 2}}) {
        mr::Texture tex = random_texture(w, h, 1);
        mr::TextureView view(tex);
        const int last = view.level_count() - 1;
        const mr::Sampler s = mr::Sampler::from_filter_name("trilinear");
        for (int k = -3; k <= 12; ++k) {
            const float t = std::ldexp(1.0f, k);
            const double expected = std::clamp(double(k), 0.0, double(last));
            EXPECT_EQ(mr::texture_lod(view, s, {t / w, 0.0f}, {0.0f, 0.0f}), expected) << w << "x" << h << " k " << k;
            EXPECT_EQ(mr::texture_lod(view, s, {0.0f, 0.0f}, {0.0f, t / h}), expected) << w << "x" << h << " k " << k;
            // The longer of the two derivatives sets ρ.
            EXPECT_EQ(mr::texture_lod(view, s, {0.25f * t / w, 0.0f}, {0.0f, -t / h}), expected);
            // A 3-4-5 vector of length 2^k texels.
            EXPECT_EQ(mr::texture_lod(view, s, {0.6f * t / w, 0.8f * t / h}, {0.0f, 0.0f}),
                      to::isotropic_lod(w, h, view.level_count(), s, {0.6f * t / w, 0.8f * t / h}, {0.0f, 0.0f}));
        }
    }
}

// Trilinear at ρ = 2^(k+½) is the 50/50 blend of the bilinear lookups on levels k and k+1 (the
// levels' texels from view.level, the blend and bilinear from the oracle).
TEST(TextureLod, TrilinearAtHalfLevelIsEvenBlendOfLevels) {
    mr::Texture tex = random_texture(128, 64, 2);
    mr::TextureView view(tex);
    mr::Sampler s = mr::Sampler::from_filter_name("trilinear");
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> d(-1.0f, 2.0f);
    for (int k = 0; k + 1 < view.level_count(); ++k) {
        const float rho = std::exp2(k + 0.5f);
        const glm::vec2 dx(rho / 128, 0.0f), dy(0.0f, 0.0f);
        EXPECT_NEAR(mr::texture_lod(view, s, dx, dy), k + 0.5, 1e-6);
        for (int i = 0; i < 50; ++i) {
            const glm::vec2 uv(d(rng), d(rng));
            const glm::dvec4 a = to::bilinear(view.level(k), uv.x, uv.y, s), b = to::bilinear(view.level(k + 1), uv.x, uv.y, s);
            const glm::dvec4 expected = 0.5 * (a + b);
            const glm::vec4 got = mr::sample_texture(view, s, uv, dx, dy);
            // λ is k + ½ to float precision of ρ (≈ 1e-7), so the blend is within ~1e-7·|a − b|.
            for (int c = 0; c < 4; ++c) ASSERT_NEAR(got[c], expected[c], 1e-6) << "level " << k << " uv " << uv.x << "," << uv.y;
        }
    }
}

// Nearest-mip picks level ⌈λ + ½⌉ − 1 (GL): λ = k + 0.49 stays on level k, k + 0.51 moves to
// k + 1, and λ ≤ ½ stays on level 0.
TEST(TextureLod, NearestMipPicksGlLevel) {
    mr::Texture tex = random_texture(64, 64, 4);
    mr::TextureView view(tex);
    mr::Sampler s;
    s.mip_filter = mr::MipFilter::nearest;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> d(0.0f, 1.0f);
    for (int k = 0; k + 1 < view.level_count(); ++k)
        for (double frac : {0.2, 0.49, 0.51, 0.9}) {
            const double lambda = k + frac;
            const int expected_level = int(std::ceil(lambda + 0.5)) - 1;
            const glm::vec2 dx(float(std::exp2(lambda) / 64), 0.0f);
            for (int i = 0; i < 20; ++i) {
                const glm::vec2 uv(d(rng), d(rng));
                const glm::dvec4 expected = to::bilinear(view.level(expected_level), uv.x, uv.y, s);
                const glm::vec4 got = mr::sample_texture(view, s, uv, dx, {0.0f, 0.0f});
                for (int c = 0; c < 4; ++c) ASSERT_NEAR(got[c], expected[c], 2e-7) << "lambda " << lambda;
            }
        }
}

// lod_bias adds to λ; min_lod and max_lod clamp it (GL: a min_lod above 0 minifies even with zero
// derivatives); λ never leaves [0, levels − 1]; NaN or infinite derivatives give the coarsest
// level allowed by max_lod (the documented choice).
TEST(TextureLod, BiasAndClampsApply) {
    mr::Texture tex = random_texture(64, 32, 6);
    mr::TextureView view(tex);
    const int last = view.level_count() - 1;  // 6
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    mr::Sampler s = mr::Sampler::from_filter_name("trilinear");
    const glm::vec2 four(4.0f / 64, 0.0f), zero(0.0f);  // ρ = 4, λ = 2
    EXPECT_EQ(mr::texture_lod(view, s, four, zero), 2.0);
    s.lod_bias = 1.5f;
    EXPECT_EQ(mr::texture_lod(view, s, four, zero), 3.5);
    s.lod_bias = -5.0f;
    EXPECT_EQ(mr::texture_lod(view, s, four, zero), 0.0);
    s.lod_bias = 10.0f;
    EXPECT_EQ(mr::texture_lod(view, s, four, zero), double(last));
    s = mr::Sampler::from_filter_name("trilinear");
    s.min_lod = 2.0f;
    EXPECT_EQ(mr::texture_lod(view, s, zero, zero), 2.0);
    s.min_lod = 0.0f;
    s.max_lod = 1.25f;
    EXPECT_EQ(mr::texture_lod(view, s, {1e6f, 0.0f}, zero), 1.25);
    EXPECT_EQ(mr::texture_lod(view, s, {nan, 0.0f}, zero), 1.25);
    s.max_lod = 1000.0f;
    EXPECT_EQ(mr::texture_lod(view, s, {nan, 0.0f}, zero), double(last));
    EXPECT_EQ(mr::texture_lod(view, s, zero, {inf, inf}), double(last));
    EXPECT_EQ(mr::texture_lod(view, s, zero, zero), 0.0);  // log2 0 = −∞ → 0
    s.min_lod = -4.0f;
    EXPECT_EQ(mr::texture_lod(view, s, zero, zero), 0.0);  // never below 0

    // The clamped λ is what the lookup uses: zero derivatives with min_lod 2 read level 2;
    // huge derivatives with max_lod 1.25 blend levels 1 and 2 by ¼.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<float> d(0.0f, 1.0f);
    const to::LevelFn level = [&](int k) -> const mr::TextureLevel& { return view.level(k); };
    for (int i = 0; i < 50; ++i) {
        const glm::vec2 uv(d(rng), d(rng));
        mr::Sampler a = mr::Sampler::from_filter_name("trilinear");
        a.min_lod = 2.0f;
        const glm::dvec4 e2 = to::bilinear(view.level(2), uv.x, uv.y, a);
        const glm::vec4 g2 = mr::sample_texture(view, a, uv, zero, zero);
        for (int c = 0; c < 4; ++c) ASSERT_NEAR(g2[c], e2[c], 2e-7);
        mr::Sampler b = mr::Sampler::from_filter_name("trilinear");
        b.max_lod = 1.25f;
        const glm::dvec4 e = 0.75 * to::bilinear(view.level(1), uv.x, uv.y, b) + 0.25 * to::bilinear(view.level(2), uv.x, uv.y, b);
        const glm::vec4 g = mr::sample_texture(view, b, uv, {1e6f, 0.0f}, zero);
        for (int c = 0; c < 4; ++c) ASSERT_NEAR(g[c], e[c], 2e-7);
        mr::Sampler bias = mr::Sampler::from_filter_name("trilinear");
        bias.lod_bias = 0.75f;
        const glm::dvec4 eb = to::mip_lookup(level, view.level_count(), uv.x, uv.y, 2.75, bias);
        const glm::vec4 gb = mr::sample_texture(view, bias, uv, four, zero);
        for (int c = 0; c < 4; ++c) ASSERT_NEAR(gb[c], eb[c], 2e-7);
    }
}

// Sampler fields at the edge of what validate() accepts (max_anisotropy 1e30, min_lod −3e38,
// max_lod 3e38, bias ±3e38) give a λ in [0, levels − 1] and finite results; the anisotropic probe
// count follows ⌈Pmax/Pmin⌉ when that is below max_anisotropy.
TEST(TextureLod, ExtremeSamplerFieldsStayInRange) {
    mr::Texture tex = random_texture(17, 9, 8);
    mr::TextureView view(tex);
    const int levels = view.level_count();
    for (const char* name : {"nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"}) {
        mr::Sampler s = mr::Sampler::from_filter_name(name);
        s.max_anisotropy = 1e30f;
        s.min_lod = -3e38f;
        s.max_lod = 3e38f;
        EXPECT_NO_THROW(s.validate());
        for (float bias : {0.0f, 3e38f, -3e38f}) {
            s.lod_bias = bias;
            for (auto [dx, dy] : std::vector<std::pair<glm::vec2, glm::vec2>>{
                     {{0.5f, 0.0f}, {0.0f, 1e-3f}}, {{0.0f, 0.0f}, {0.0f, 0.0f}}, {{1e30f, 0.0f}, {0.0f, 1e30f}}}) {
                const double lambda = mr::texture_lod(view, s, dx, dy);
                EXPECT_GE(lambda, 0.0) << name;
                EXPECT_LE(lambda, levels - 1.0) << name;
                const glm::vec4 v = mr::sample_texture(view, s, {0.3f, 0.7f}, dx, dy);
                for (int c = 0; c < 4; ++c) {
                    EXPECT_TRUE(std::isfinite(v[c])) << name;
                    EXPECT_GE(v[c], 0.0f) << name;
                    EXPECT_LE(v[c], 1.0f) << name;
                }
            }
        }
    }
    // Pmax = 8.5 texels, Pmin = 0.009: ⌈Pmax/Pmin⌉ = 945 probes at λ = log2(8.5/945) < 0 → 0.
    mr::Sampler an = mr::Sampler::from_filter_name("anisotropic");
    an.max_anisotropy = 1e30f;
    EXPECT_EQ(to::aniso_plan(17, 9, levels, an, {0.5f, 0.0f}, {0.0f, 1e-3f}).n, 945);
    EXPECT_EQ(mr::texture_lod(view, an, {0.5f, 0.0f}, {0.0f, 1e-3f}), 0.0);
}

// ---- sRGB ---------------------------------------------------------------------------------------

// §2.7: a 2×2 black/white checker in sRGB8 (0/255) reduces to linear 0.5, which encodes to 188,
// not 128; the same through a trilinear lookup at λ = 1, and for 1-, 3- and 4-channel input.
TEST(TextureSrgb, CheckerReducesTo188) {
    for (int channels : {1, 3, 4}) {
        std::vector<std::uint8_t> px;
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i)
                for (int c = 0; c < channels; ++c) px.push_back(c == 3 ? 255 : ((i + j) % 2 ? 255 : 0));
        mr::Texture tex = mr::Texture::from_8bit(px.data(), 2, 2, channels, true, "checker");
        mr::TextureView view(tex);
        ASSERT_EQ(view.level_count(), 2);
        const glm::vec4 mean = view.level(1).at(0, 0);
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(mean[c], 0.5f) << channels << " channels";
            EXPECT_EQ(mr::linear_to_srgb8(mean[c]), 188) << channels << " channels";
        }
        EXPECT_EQ(mean.a, 1.0f);
        // λ = 1 (ρ = 2 texels): the 1×1 level.
        const glm::vec4 got = mr::sample_texture(view, mr::Sampler::from_filter_name("trilinear"), {0.3f, 0.6f},
                                                 {1.0f, 0.0f}, {0.0f, 1.0f});
        EXPECT_EQ(mr::linear_to_srgb8(got.r), 188);
    }
    // A larger 1-texel checker: every level beyond 0 is linear 0.5 → 188.
    std::vector<std::uint8_t> big(64 * 64);
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 64; ++i) big[j * 64 + i] = (i + j) % 2 ? 255 : 0;
    mr::Texture tex = mr::Texture::from_8bit(big.data(), 64, 64, 1, true, "checker64");
    mr::TextureView view(tex);
    for (int k = 1; k < view.level_count(); ++k)
        for (const glm::vec4& t : view.level(k).texels) ASSERT_EQ(mr::linear_to_srgb8(t.r), 188) << "level " << k;
}

// All 256 codes decode to the sRGB curve (double oracle) and encode back to the same code.
TEST(TextureSrgb, AllCodesRoundTripThroughLevelZero) {
    std::vector<std::uint8_t> codes(256);
    for (int i = 0; i < 256; ++i) codes[i] = std::uint8_t(i);
    mr::Texture tex = mr::Texture::from_8bit(codes.data(), 256, 1, 1, true, "codes");
    mr::Texture lin = mr::Texture::from_8bit(codes.data(), 256, 1, 1, false, "codes-linear");
    double worst = 0.0;
    for (int i = 0; i < 256; ++i) {
        const glm::vec4 t = tex.base_level().at(i, 0);
        EXPECT_EQ(int(mr::linear_to_srgb8(t.r)), i) << "code " << i;
        EXPECT_EQ(t.r, t.g);
        EXPECT_EQ(t.r, t.b);
        EXPECT_EQ(t.a, 1.0f);
        const double expected = to::srgb_to_linear(i / 255.0);
        worst = std::max(worst, std::abs(t.r - expected));
        EXPECT_NEAR(t.r, expected, 1e-6 * expected + 1e-9) << "code " << i;
        // Data textures: code / 255.
        EXPECT_NEAR(lin.base_level().at(i, 0).r, i / 255.0, 6e-8) << "code " << i;
    }
    std::cout << "sRGB8 decode vs double formula: worst abs error " << worst << "\n";
}

// Alpha is linear and colour is premultiplied after decoding: sRGB RGBA (200, 100, 50, 128)
// stores decode(200/255)·128/255, not decode(200/255·128/255). Grey+alpha and linear input too.
TEST(TextureSrgb, AlphaIsPremultipliedInLinearSpace) {
    const std::uint8_t rgba[] = {200, 100, 50, 128, 255, 255, 255, 0, 10, 20, 30, 255};
    mr::Texture tex = mr::Texture::from_8bit(rgba, 3, 1, 4, true, "rgba");
    for (int p = 0; p < 3; ++p) {
        const double a = rgba[p * 4 + 3] / 255.0;
        const glm::vec4 t = tex.base_level().at(p, 0);
        EXPECT_NEAR(t.a, a, 6e-8);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(t[c], to::srgb_to_linear(rgba[p * 4 + c] / 255.0) * a, 2e-7) << "texel " << p << " channel " << c;
    }
    // A half-transparent sRGB 200 is not the sRGB code of the premultiplied value (why the order matters).
    EXPECT_GT(std::abs(to::srgb_to_linear(200.0 / 255.0) * 128.0 / 255.0 - to::srgb_to_linear(200.0 / 255.0 * 128.0 / 255.0)), 0.05);

    const std::uint8_t ga[] = {128, 64, 255, 255};
    mr::Texture grey = mr::Texture::from_8bit(ga, 2, 1, 2, true, "grey-alpha");
    const glm::vec4 g0 = grey.base_level().at(0, 0);
    EXPECT_NEAR(g0.r, to::srgb_to_linear(128 / 255.0) * 64 / 255.0, 2e-7);
    EXPECT_EQ(g0.r, g0.g);
    EXPECT_EQ(g0.r, g0.b);
    EXPECT_NEAR(g0.a, 64 / 255.0, 6e-8);
    EXPECT_EQ(grey.base_level().at(1, 0), glm::vec4(1.0f));

    mr::Texture data = mr::Texture::from_8bit(rgba, 3, 1, 4, false, "rgba-linear");
    EXPECT_NEAR(data.base_level().at(0, 0).r, (200 / 255.0) * (128 / 255.0), 2e-7);

    // from_float: premultiplied = false multiplies colour by alpha, true keeps it.
    const float f[] = {0.8f, 0.4f, 0.2f, 0.5f};
    EXPECT_EQ(mr::Texture::from_float(f, 1, 1, 4, false, "straight").base_level().at(0, 0), glm::vec4(0.4f, 0.2f, 0.1f, 0.5f));
    EXPECT_EQ(mr::Texture::from_float(f, 1, 1, 4, true, "premultiplied").base_level().at(0, 0), glm::vec4(0.8f, 0.4f, 0.2f, 0.5f));
}

// Level generation works on linear premultiplied texels: a texel of opaque white next to a fully
// transparent one averages to (½, ½, ½, ½) premultiplied, i.e. white at half coverage, not grey.
TEST(TextureSrgb, LevelsAverageLinearPremultipliedTexels) {
    const std::uint8_t px[] = {255, 255, 255, 255, 0, 0, 0, 0};
    mr::Texture tex = mr::Texture::from_8bit(px, 2, 1, 4, true, "white+clear");
    mr::TextureView view(tex);
    EXPECT_EQ(view.level(1).at(0, 0), glm::vec4(0.5f));
}

}  // namespace
