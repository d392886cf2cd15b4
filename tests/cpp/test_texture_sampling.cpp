// Texture lookups (DESIGN.md §1 texture coordinates / LOD, §2.6 sampling contract): every filter
// returns a constant texture bit-exactly for every footprint, wrap mode and size; a non-finite uv
// returns the border colour; nearest, bilinear and trilinear match the notes' formulas on random
// points (oracles in texture_oracle.hpp); huge coordinates neither crash nor give NaN.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "mipraster/texture/sample.hpp"
#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture.hpp"
#include "texture_oracle.hpp"

namespace {

namespace mr = mipraster;
namespace to = tex_oracle;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kMaxF = std::numeric_limits<float>::max();

struct NamedSampler {
    std::string name;
    mr::Sampler sampler;
};

// Every filter configuration the library offers.
std::vector<NamedSampler> all_filters() {
    std::vector<NamedSampler> out;
    for (const char* n : {"nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"})
        out.push_back({n, mr::Sampler::from_filter_name(n)});
    mr::Sampler s;
    s.mip_filter = mr::MipFilter::nearest;
    out.push_back({"bilinear+nearest-mip", s});
    s.min_filter = s.mag_filter = mr::TexelFilter::nearest;
    out.push_back({"nearest+nearest-mip", s});
    s.mip_filter = mr::MipFilter::linear;
    out.push_back({"nearest+linear-mip", s});
    for (float a : {1.0f, 4.0f, 16.0f}) {
        mr::Sampler an = mr::Sampler::from_filter_name("anisotropic");
        an.max_anisotropy = a;
        out.push_back({"anisotropic x" + std::to_string(int(a)), an});
    }
    for (float a : {1.0f, 4.0f}) {
        mr::Sampler e = mr::Sampler::from_filter_name("ewa");
        e.max_anisotropy = a;
        out.push_back({"ewa x" + std::to_string(int(a)), e});
    }
    return out;
}

std::vector<std::pair<glm::vec2, glm::vec2>> special_footprints() {
    using V = glm::vec2;
    return {
        {V(0.0f), V(0.0f)},                                   // zero
        {V(1e-30f, 0.0f), V(0.0f, 1e-30f)},                   // tiny
        {V(1e-45f, 1e-45f), V(-1e-45f, 1e-45f)},              // denormal
        {V(1e30f, 0.0f), V(0.0f, 1e30f)},                     // huge
        {V(kMaxF, kMaxF), V(-kMaxF, kMaxF)},                  // largest float
        {V(kInf, 0.0f), V(0.0f, kInf)},                       // infinite
        {V(-kInf, -kInf), V(kInf, -kInf)},                    //
        {V(kNaN, kNaN), V(kNaN, kNaN)},                       // NaN
        {V(0.01f, 0.0f), V(kInf, 0.0f)},                      // mixed finite / infinite
        {V(kNaN, 0.0f), V(0.0f, 0.0f)},                       // mixed NaN / zero
        {V(0.02f, kNaN), V(0.0f, 0.02f)},                     //
        {V(0.1f, 0.05f), V(0.1f, 0.05f)},                     // parallel (equal)
        {V(0.5f, 0.5f), V(-0.5f, -0.5f)},                     // antiparallel
        {V(0.3f, 0.0f), V(0.0f, 0.0f)},                       // one zero derivative
        {V(0.0f, 0.0f), V(0.0f, 7.0f)},                       //
        {V(0.2f, 0.001f), V(-0.0005f, 0.003f)},               // strongly anisotropic
        {V(1e-30f, 0.0f), V(0.0f, 1e30f)},                    // ratio 1e60
        {V(1e4f, 3e3f), V(-2e3f, 5e3f)},                      // thousands of periods
        {V(0.03f, 0.04f), V(-0.04f, 0.03f)},                  // plain minification
        {V(1.0f, 0.0f), V(0.0f, 1.0f)},                       // one texture per pixel
    };
}

std::vector<std::pair<glm::vec2, glm::vec2>> random_footprints(std::mt19937_64& rng, int n) {
    std::uniform_real_distribution<float> expo(-6.0f, 4.0f), sign(-1.0f, 1.0f);
    std::vector<std::pair<glm::vec2, glm::vec2>> out;
    for (int i = 0; i < n; ++i) {
        auto c = [&] { return sign(rng) * std::pow(10.0f, expo(rng)); };
        out.push_back({glm::vec2(c(), c()), glm::vec2(c(), c())});
    }
    return out;
}

std::vector<glm::vec2> test_uvs(std::mt19937_64& rng, int n_random) {
    std::vector<glm::vec2> out = {{0.0f, 0.0f},   {1.0f, 1.0f},  {0.5f, 0.5f},       {-1.0f, 2.0f},   {0.999999f, 1e-7f},
                                  {-1e-7f, -0.0f}, {1e4f, -1e4f}, {1e8f, 3e7f},       {-1e30f, 1e30f}, {kMaxF, -kMaxF},
                                  {1e-45f, 0.25f}};
    std::uniform_real_distribution<float> wide(-40.0f, 40.0f), unit(-0.5f, 1.5f);
    for (int i = 0; i < n_random; ++i) out.push_back(i % 2 ? glm::vec2(wide(rng), wide(rng)) : glm::vec2(unit(rng), unit(rng)));
    return out;
}

bool bitwise_equal(glm::vec4 a, glm::vec4 b) {
    for (int c = 0; c < 4; ++c)
        if (!(a[c] == b[c]) || std::signbit(a[c]) != std::signbit(b[c])) return false;
    return true;
}

std::string str(glm::vec4 v) {
    std::ostringstream o;
    o.precision(9);
    o << "(" << v.x << ", " << v.y << ", " << v.z << ", " << v.w << ")";
    return o.str();
}

std::string str(glm::vec2 v) {
    std::ostringstream o;
    o.precision(9);
    o << "(" << v.x << ", " << v.y << ")";
    return o.str();
}

// §2.6: every filter returns a constant texture unchanged for every footprint (zero, tiny, huge,
// infinite, NaN, mixed, degenerate, random), every wrap mode (border colour = the constant) and
// odd, non-power-of-two and 1×N sizes. Bitwise equality: the lookups sum in double and round once.
TEST(TextureSampling, ConstantTextureIsReturnedBitExactlyByEveryFilter) {
    const std::vector<std::pair<int, int>> sizes = {{1, 1}, {1, 7}, {7, 1}, {3, 5}, {17, 9}, {16, 16}, {64, 32}, {5, 64}};
    const std::vector<glm::vec4> constants = {glm::vec4(0.3f, 0.7f, 1.0f / 3.0f, 0.9f),
                                              glm::vec4(123.456f, 1e-3f, 0.0f, 7e30f)};
    const std::vector<std::pair<mr::WrapMode, mr::WrapMode>> wraps = {
        {mr::WrapMode::repeat, mr::WrapMode::repeat}, {mr::WrapMode::clamp, mr::WrapMode::clamp},
        {mr::WrapMode::mirror, mr::WrapMode::mirror}, {mr::WrapMode::border, mr::WrapMode::border},
        {mr::WrapMode::repeat, mr::WrapMode::mirror}, {mr::WrapMode::clamp, mr::WrapMode::border},
        {mr::WrapMode::border, mr::WrapMode::repeat}};
    std::mt19937_64 rng(20240601);
    auto footprints = special_footprints();
    const auto extra = random_footprints(rng, 12);
    footprints.insert(footprints.end(), extra.begin(), extra.end());
    const std::vector<glm::vec2> uvs = test_uvs(rng, 12);
    const auto filters = all_filters();
    long checked = 0, failures = 0;
    for (const glm::vec4& c : constants)
        for (const auto& [w, h] : sizes) {
            mr::Texture tex(to::make_level(w, h, [&](int, int) { return c; }), "constant");
            mr::TextureView view(tex);
            for (const auto& [wu, wv] : wraps)
                for (const NamedSampler& f : filters) {
                    mr::Sampler s = f.sampler;
                    s.wrap_u = wu;
                    s.wrap_v = wv;
                    s.border_color = c;
                    for (const auto& [dx, dy] : footprints)
                        for (const glm::vec2 uv : uvs) {
                            const glm::vec4 got = mr::sample_texture(view, s, uv, dx, dy);
                            ++checked;
                            if (!bitwise_equal(got, c) && ++failures <= 20)
                                ADD_FAILURE() << f.name << " " << w << "x" << h << " wrap " << to::wrap_name(wu) << "/"
                                              << to::wrap_name(wv) << " uv " << str(uv) << " dx " << str(dx) << " dy "
                                              << str(dy) << ": got " << str(got) << ", expected " << str(c);
                        }
                }
        }
    std::cout << "constant-texture lookups checked: " << checked << ", failures: " << failures << "\n";
    EXPECT_EQ(failures, 0);
}

// A constant texture stays exact with LOD bias and min/max LOD clamps too (other level paths).
TEST(TextureSampling, ConstantTextureIsExactUnderLodBiasAndClamps) {
    const glm::vec4 c(0.1f, 0.2f, 0.3f, 0.4f);
    mr::Texture tex(to::make_level(37, 23, [&](int, int) { return c; }), "constant");
    mr::TextureView view(tex);
    std::mt19937_64 rng(7);
    const auto footprints = special_footprints();
    const auto uvs = test_uvs(rng, 6);
    for (const NamedSampler& f : all_filters())
        for (float bias : {-3.0f, 0.5f, 4.0f})
            for (auto [lo, hi] : {std::pair<float, float>{0.0f, 1000.0f}, {2.0f, 2.0f}, {0.5f, 1.5f}, {10.0f, 20.0f}}) {
                mr::Sampler s = f.sampler;
                s.lod_bias = bias;
                s.min_lod = lo;
                s.max_lod = hi;
                for (const auto& [dx, dy] : footprints)
                    for (const glm::vec2 uv : uvs) {
                        const glm::vec4 got = mr::sample_texture(view, s, uv, dx, dy);
                        ASSERT_TRUE(bitwise_equal(got, c)) << f.name << " bias " << bias << " lod [" << lo << ", "
                                                           << hi << "] uv " << str(uv) << " dx " << str(dx) << " dy "
                                                           << str(dy) << ": got " << str(got);
                    }
            }
}

// §2.6: a non-finite uv (NaN or ±inf in either component) returns the border colour, for every
// filter and footprint, both the default (transparent black) and a set one.
TEST(TextureSampling, NonFiniteUvReturnsBorderColour) {
    mr::Texture tex(to::random_level(13, 6, 99), "random");
    mr::TextureView view(tex);
    const std::vector<glm::vec2> bad = {{kNaN, 0.5f}, {0.5f, kNaN}, {kNaN, kNaN},  {kInf, 0.5f},
                                        {0.5f, -kInf}, {-kInf, kInf}, {kInf, kNaN}};
    const auto footprints = special_footprints();
    for (const NamedSampler& f : all_filters())
        for (const glm::vec4 border : {glm::vec4(0.0f), glm::vec4(0.25f, 0.5f, 0.75f, 1.0f)})
            for (mr::WrapMode wrap : to::kAllWraps) {
                mr::Sampler s = f.sampler;
                s.border_color = border;
                s.wrap_u = s.wrap_v = wrap;
                for (const glm::vec2 uv : bad)
                    for (const auto& [dx, dy] : footprints) {
                        const glm::vec4 got = mr::sample_texture(view, s, uv, dx, dy);
                        ASSERT_TRUE(bitwise_equal(got, border))
                            << f.name << " wrap " << to::wrap_name(wrap) << " uv " << str(uv) << ": got " << str(got)
                            << ", expected border " << str(border);
                    }
            }
}

// The notes' nearest rule i = ⌊u·w⌋ with every wrap mode, on random points far outside [0, 1]
// and on exact texel edges; the result is a texel, so equality is exact.
TEST(TextureSampling, NearestMatchesFloorRuleWithEveryWrapMode) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> d(-8.0f, 9.0f);
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{{17, 9}, {16, 8}, {3, 5}, {1, 4}}) {
        mr::Texture tex(to::random_level(w, h, 1000 + w), "random");
        mr::TextureView view(tex);
        for (mr::WrapMode wu : to::kAllWraps)
            for (mr::WrapMode wv : to::kAllWraps) {
                mr::Sampler s = mr::Sampler::from_filter_name("nearest");
                s.wrap_u = wu;
                s.wrap_v = wv;
                s.border_color = glm::vec4(-1.0f, -2.0f, -3.0f, -4.0f);
                std::vector<glm::vec2> uvs;
                for (int i = 0; i < 400; ++i) uvs.push_back({d(rng), d(rng)});
                // Exact texel edges (w power of two: i/w is exact; others: the float nearest it).
                for (int i = -2 * w; i <= 2 * w; ++i) uvs.push_back({float(i) / w, float(-i) / h});
                for (const glm::vec2 uv : uvs) {
                    const glm::vec4 expected(to::nearest(view.level(0), uv.x, uv.y, s));
                    const glm::vec4 got = mr::sample_texture(view, s, uv, glm::vec2(0.0f), glm::vec2(0.0f));
                    ASSERT_TRUE(bitwise_equal(got, expected))
                        << w << "x" << h << " wrap " << to::wrap_name(wu) << "/" << to::wrap_name(wv) << " uv "
                        << str(uv) << ": got " << str(got) << ", expected " << str(expected);
                }
            }
    }
}

// Hand-computed bilinear values on the 2×2 texture [[0, 1], [2, 3]] (row 0 = v ∈ [0, ½)).
TEST(TextureSampling, BilinearMatchesHandComputedValues) {
    mr::Texture tex(to::make_level(2, 2, [](int i, int j) { return glm::vec4(float(i + 2 * j)); }), "ramp");
    mr::TextureView view(tex);
    mr::Sampler s = mr::Sampler::from_filter_name("bilinear");
    auto at = [&](float u, float v, mr::WrapMode wrap) {
        s.wrap_u = s.wrap_v = wrap;
        s.border_color = glm::vec4(10.0f);
        return mr::sample_texture(view, s, {u, v}, glm::vec2(0.0f), glm::vec2(0.0f)).x;
    };
    // Texel centres return the texel.
    EXPECT_EQ(at(0.25f, 0.25f, mr::WrapMode::repeat), 0.0f);
    EXPECT_EQ(at(0.75f, 0.25f, mr::WrapMode::repeat), 1.0f);
    EXPECT_EQ(at(0.25f, 0.75f, mr::WrapMode::repeat), 2.0f);
    EXPECT_EQ(at(0.75f, 0.75f, mr::WrapMode::repeat), 3.0f);
    // The middle: U − ½ = ½ in both axes → the mean 1.5.
    EXPECT_EQ(at(0.5f, 0.5f, mr::WrapMode::clamp), 1.5f);
    // u = 0.375: U − ½ = 0.25 → i = 0, s = 0.25 along the top row (t = 0): 0.75·0 + 0.25·1.
    EXPECT_EQ(at(0.375f, 0.25f, mr::WrapMode::clamp), 0.25f);
    // uv (0, 0): U − ½ = −½ → i = −1, s = ½ in both axes.
    EXPECT_EQ(at(0.0f, 0.0f, mr::WrapMode::repeat), 1.5f);   // ¼(3 + 2 + 1 + 0)
    EXPECT_EQ(at(0.0f, 0.0f, mr::WrapMode::clamp), 0.0f);    // all four are texel (0,0)
    EXPECT_EQ(at(0.0f, 0.0f, mr::WrapMode::mirror), 0.0f);   // index −1 mirrors to 0
    EXPECT_EQ(at(0.0f, 0.0f, mr::WrapMode::border), 7.5f);   // ¼(0 + 10 + 10 + 10)
    // uv (1, 0.25): between texel 1 and the next copy's texel 0 (repeat) or texel 1 mirrored.
    EXPECT_EQ(at(1.0f, 0.25f, mr::WrapMode::repeat), 0.5f);
    EXPECT_EQ(at(1.0f, 0.25f, mr::WrapMode::mirror), 1.0f);
    EXPECT_EQ(at(1.0f, 0.25f, mr::WrapMode::border), 5.5f);  // ½(1 + 10)
}

// Bilinear matches the notes' formula (i = ⌊u·w − ½⌋, s = u·w − (i + ½)) on random points with
// every wrap-mode pair, to the one float rounding of the result.
TEST(TextureSampling, BilinearMatchesNotesFormulaOnRandomPoints) {
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<float> d(-5.0f, 6.0f);
    double worst = 0.0;
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{{17, 9}, {32, 16}, {3, 5}, {1, 6}, {1, 1}}) {
        mr::Texture tex(to::random_level(w, h, 2000 + w * h), "random");
        mr::TextureView view(tex);
        for (mr::WrapMode wu : to::kAllWraps)
            for (mr::WrapMode wv : to::kAllWraps) {
                mr::Sampler s = mr::Sampler::from_filter_name("bilinear");
                s.wrap_u = wu;
                s.wrap_v = wv;
                s.border_color = glm::vec4(0.9f, 0.1f, 0.5f, 0.3f);
                for (int i = 0; i < 500; ++i) {
                    const glm::vec2 uv(d(rng), d(rng));
                    // Derivatives of a minified footprint: bilinear (mip none) ignores them.
                    const glm::vec2 dx(i % 3 ? 0.0f : 0.5f, 0.0f), dy(0.0f, i % 3 ? 0.0f : 0.7f);
                    const glm::dvec4 expected = to::bilinear(view.level(0), uv.x, uv.y, s);
                    const glm::vec4 got = mr::sample_texture(view, s, uv, dx, dy);
                    for (int c = 0; c < 4; ++c) {
                        const double err = std::abs(got[c] - expected[c]);
                        worst = std::max(worst, err);
                        ASSERT_LE(err, 2e-7) << w << "x" << h << " wrap " << to::wrap_name(wu) << "/"
                                             << to::wrap_name(wv) << " uv " << str(uv) << " channel " << c;
                    }
                }
            }
    }
    std::cout << "bilinear vs notes' formula: worst abs error " << worst << "\n";
}

// Trilinear = lerp of the bilinear lookups on levels ⌊λ⌋ and ⌊λ⌋+1 by λ − ⌊λ⌋ (the notes),
// with λ = log2 max(‖∂uv/∂x‖, ‖∂uv/∂y‖) in texels; levels come from view.level(k) (their
// generation is tested in test_texture_levels).
TEST(TextureSampling, TrilinearIsLerpOfAdjacentLevelsBilinear) {
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<float> d(-2.0f, 3.0f), ang(0.0f, 6.2831853f), lg(-1.0f, 7.5f), ratio(0.2f, 1.0f);
    double worst = 0.0;
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{{64, 32}, {37, 23}, {128, 128}}) {
        mr::Texture tex(to::random_level(w, h, 3000 + w), "random");
        mr::TextureView view(tex);
        const int levels = to::level_count(w, h);
        const to::LevelFn level = [&](int k) -> const mr::TextureLevel& { return view.level(k); };
        for (mr::WrapMode wrap : to::kAllWraps) {
            mr::Sampler s = mr::Sampler::from_filter_name("trilinear");
            s.wrap_u = s.wrap_v = wrap;
            s.border_color = glm::vec4(0.2f);
            for (int i = 0; i < 1000; ++i) {
                const glm::vec2 uv(d(rng), d(rng));
                const float rho = std::exp2(lg(rng)), a = ang(rng);
                const glm::vec2 dx(rho * std::cos(a) / w, rho * std::sin(a) / h);
                const float r2 = rho * ratio(rng), a2 = ang(rng);
                const glm::vec2 dy(r2 * std::cos(a2) / w, r2 * std::sin(a2) / h);
                const double lambda = to::isotropic_lod(w, h, levels, s, dx, dy);
                const glm::dvec4 expected = to::mip_lookup(level, levels, uv.x, uv.y, lambda, s);
                const glm::vec4 got = mr::sample_texture(view, s, uv, dx, dy);
                for (int c = 0; c < 4; ++c) {
                    const double err = std::abs(got[c] - expected[c]);
                    worst = std::max(worst, err);
                    ASSERT_LE(err, 1e-6) << w << "x" << h << " wrap " << to::wrap_name(wrap) << " uv " << str(uv)
                                         << " dx " << str(dx) << " dy " << str(dy) << " lambda " << lambda;
                }
            }
        }
    }
    std::cout << "trilinear vs lerp of levels' bilinear: worst abs error " << worst << "\n";
}

// Nearest-texel filters inside mip levels (nearest+linear-mip): each level's nearest texel,
// lerped by frac(λ).
TEST(TextureSampling, NearestTexelLinearMipMatchesOracle) {
    std::mt19937_64 rng(14);
    std::uniform_real_distribution<float> d(-2.0f, 3.0f), lg(-1.0f, 6.0f);
    mr::Texture tex(to::random_level(48, 40, 3333), "random");
    mr::TextureView view(tex);
    const int levels = to::level_count(48, 40);
    const to::LevelFn level = [&](int k) -> const mr::TextureLevel& { return view.level(k); };
    mr::Sampler s;
    s.min_filter = s.mag_filter = mr::TexelFilter::nearest;
    for (mr::WrapMode wrap : to::kAllWraps) {
        s.wrap_u = s.wrap_v = wrap;
        for (int i = 0; i < 1000; ++i) {
            const glm::vec2 uv(d(rng), d(rng));
            const float rho = std::exp2(lg(rng));
            const glm::vec2 dx(rho / 48, 0.0f), dy(0.0f, 0.5f * rho / 40);
            const double lambda = to::isotropic_lod(48, 40, levels, s, dx, dy);
            const glm::dvec4 expected = to::mip_lookup(level, levels, uv.x, uv.y, lambda, s);
            const glm::vec4 got = mr::sample_texture(view, s, uv, dx, dy);
            for (int c = 0; c < 4; ++c) ASSERT_NEAR(got[c], expected[c], 1e-6) << "uv " << str(uv) << " rho " << rho;
        }
    }
}

// Large coordinates with repeat: no crash, no NaN, and the result stays within the texel range.
// Two figures are printed per filter and magnitude: (a) periodicity, the difference from the same
// lookup at the float u's exact reduction u − ⌊u⌋ (asserted ≤ 1e-5 up to 10⁸: repeat reduces
// exactly in double); (b) the precision loss, the difference from the lookup at the intended
// position (a double M + δ, δ ∈ [0, 1), reduced before rounding to float). A float near 10⁴ has a
// spacing of 2⁻¹⁰ (¼ texel of a 256-wide texture); near 10⁸ the spacing is 8 (whole periods), so
// (b) is then as large as the texture's contrast. (b) is documented, not asserted.
TEST(TextureSampling, LargeCoordinatesWithRepeatStayFiniteAndPeriodic) {
    mr::Texture tex(to::random_level(256, 256, 4444), "random");
    mr::TextureView view(tex);
    std::mt19937_64 rng(15);
    std::uniform_real_distribution<double> frac(0.0, 1.0);
    for (const char* name : {"nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"}) {
        const mr::Sampler s = mr::Sampler::from_filter_name(name);
        for (double magnitude : {1e4, -1e4, 1e8, -1e8, 1e20, -3e38}) {
            double periodic = 0.0, loss_max = 0.0, loss_sum = 0.0;
            constexpr int kN = 200;
            for (int i = 0; i < kN; ++i) {
                const double du = frac(rng), dv = frac(rng);
                const glm::vec2 uv(float(magnitude + du), float(0.5 * magnitude + dv));
                const glm::vec2 dx(i % 2 ? 0.0f : 0.01f, 0.0f), dy(0.0f, i % 2 ? 0.0f : 0.002f);
                const glm::vec4 got = mr::sample_texture(view, s, uv, dx, dy);
                for (int c = 0; c < 4; ++c) {
                    ASSERT_TRUE(std::isfinite(got[c])) << name << " uv " << str(uv);
                    ASSERT_GE(got[c], 0.0f);
                    ASSERT_LE(got[c], 1.0f);
                }
                // (a) u − ⌊u⌋ of the float u, exact in double and representable as a float.
                const glm::vec2 reduced(float(double(uv.x) - std::floor(double(uv.x))),
                                        float(double(uv.y) - std::floor(double(uv.y))));
                const glm::vec4 ref = mr::sample_texture(view, s, reduced, dx, dy);
                // (b) the intended position, reduced in double before any float rounding. M is a whole
                // number of periods for every magnitude used (10⁴, 10⁸, 10²⁰ and 3·10³⁸ are integers).
                const glm::vec2 intended(float(du), float(std::fmod(0.5 * magnitude, 1.0) + dv));
                const glm::vec4 ideal = mr::sample_texture(view, s, intended, dx, dy);
                for (int c = 0; c < 4; ++c) {
                    periodic = std::max(periodic, double(std::abs(got[c] - ref[c])));
                    const double l = std::abs(got[c] - ideal[c]);
                    loss_max = std::max(loss_max, l);
                    loss_sum += l / 4.0;
                }
            }
            std::cout << name << " u ~ " << magnitude << ": periodicity error " << periodic
                      << "; precision loss vs intended uv: mean " << loss_sum / kN << ", max " << loss_max << "\n";
            // Beyond 2^24 a float has no fraction left and an anisotropic probe offset u + o·du is
            // lost in the rounding of u itself, so periodicity is asserted only up to 10⁸.
            if (std::abs(magnitude) <= 1e8) {
                EXPECT_LE(periodic, 1e-5) << name << " at " << magnitude;
            }
        }
    }
}

}  // namespace
