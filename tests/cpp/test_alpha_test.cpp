// Alpha testing (DrawState::alpha_cutoff, glTF alphaMode MASK): a textured quad drawn in front
// first, depth write on, then an opaque quad behind it. Where the front texture's alpha is below
// the cutoff the pixel must show the quad behind (no depth written); elsewhere the front texel's
// colour divided by its alpha, alpha 1. Nearest filtering with one texel per pixel makes every
// sample of a pixel read that pixel's texel, so the expected image follows from the texels alone.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "helpers.hpp"
#include "mipraster/pipeline/alpha_test.hpp"

namespace {

namespace mr = mipraster;
using helpers::fixed_to_ndc;
using helpers::identity_camera;
using helpers::make_draw;
using helpers::same_bits;

constexpr int kW = 64, kH = 64;  // four tiles, so that two threads split them
constexpr float kCutoff = 0.5f;
const glm::vec4 kBehind(0.1f, 0.2f, 0.3f, 1.0f);

// Alpha of texel (i, j): 8×8 squares that are all 1, all 0, or mixed values around the cutoff
// (whole squares exercise block skipping's depth bounds, the mixed ones the comparison).
float texel_alpha(int i, int j) {
    static const float mixed[] = {0.0f, 0.25f, 0.49f, 0.5f, 0.51f, 0.75f, 1.0f, 0.4999f, 0.5001f};
    switch ((i / 8 + 2 * (j / 8)) % 3) {
        case 0: return 1.0f;
        case 1: return 0.0f;
        default: return mixed[(i + 3 * j) % 9];
    }
}

// kW × kH premultiplied texels: straight colour varying with (i, j), times the alpha above.
mr::Texture mask_texture() {
    std::vector<float> texels;
    for (int j = 0; j < kH; ++j)
        for (int i = 0; i < kW; ++i) {
            const float a = texel_alpha(i, j);
            const glm::vec3 straight((i + 1) / float(kW), (j + 1) / float(kH), 0.5f + 0.25f * float((i + j) % 2));
            texels.insert(texels.end(), {straight.r * a, straight.g * a, straight.b * a, a});
        }
    return mr::Texture::from_float(texels.data(), kW, kH, 4, /*premultiplied=*/true, "alpha mask");
}

// A quad over the whole viewport at NDC depth z (identity camera, OpenGL convention: smaller is
// nearer), uv (0, 0) at its top-left corner: pixel (i, j)'s samples all lie in texel (i, j).
mr::Mesh screen_quad(float z, bool uvs) {
    mr::Mesh m;
    const float X = 256.0f * kW, Y = 256.0f * kH;
    m.positions = {{0, 0, z}, {X, 0, z}, {X, Y, z}, {0, Y, z}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    if (uvs) m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    return m;
}

mr::Sampler nearest_sampler() {
    mr::Sampler s;
    s.mag_filter = mr::TexelFilter::nearest;
    s.min_filter = mr::TexelFilter::nearest;
    s.mip_filter = mr::MipFilter::none;
    s.wrap_u = s.wrap_v = mr::WrapMode::clamp;
    return s;
}

// The expected colour of pixel (i, j), from the stored texel: the oracle of the test (the texel
// read back, divided by its alpha, is what MASK means; it does not come from the renderer).
glm::vec4 expected_pixel(const mr::Texture& texture, float cutoff, int i, int j) {
    const glm::vec4 t = texture.base_level().texels[static_cast<std::size_t>(j) * kW + static_cast<std::size_t>(i)];
    if (!(t.a >= cutoff)) return kBehind;
    return glm::vec4(t.r / t.a, t.g / t.a, t.b / t.a, 1.0f);
}

struct MaskScene {
    mr::Texture texture = mask_texture();
    mr::Mesh front = screen_quad(-0.5f, true), back = screen_quad(0.5f, false);

    std::vector<mr::Draw> draws(float cutoff) const {
        mr::DrawState masked;
        masked.alpha_cutoff = cutoff;
        mr::Draw f = make_draw(front, fixed_to_ndc(kW, kH), masked);
        f.texture = texture;
        f.sampler = nearest_sampler();
        return {f, make_draw(back, fixed_to_ndc(kW, kH), mr::DrawState(), kBehind)};
    }
};

mr::RenderResult render_mask(const MaskScene& scene, int samples, mr::AntiAliasing aa, int threads,
                             float cutoff = kCutoff) {
    mr::RenderSettings s = helpers::settings(kW, kH, samples);
    s.anti_aliasing = aa;
    s.threads = threads;
    return mr::render(scene.draws(cutoff), identity_camera(), s);
}

// Every sample of the framebuffer against expected_pixel, and the depth: the front quad's where
// it survived, the back quad's elsewhere.
void expect_mask_image(const MaskScene& scene, const mr::RenderResult& r, float cutoff, const std::string& what) {
    const mr::Framebuffer& fb = r.framebuffer;
    ASSERT_EQ(fb.width, kW);
    int bad = 0, kept = 0;
    for (int j = 0; j < kH; ++j)
        for (int i = 0; i < kW; ++i) {
            const glm::vec4 want = expected_pixel(scene.texture, cutoff, i, j);
            const bool front = want != kBehind;
            kept += front;
            // OpenGL window depth of NDC z: z / 2 + 1 / 2.
            const float want_depth = front ? 0.25f : 0.75f;
            for (int s = 0; s < fb.samples; ++s) {
                const glm::vec4 got = helpers::sample_color(fb, i, j, s);
                const float depth = fb.depth[fb.sample_index(i, j, s)];
                if (got != want || depth != want_depth) {
                    if (++bad <= 8)
                        ADD_FAILURE() << what << ": pixel (" << i << ", " << j << ") sample " << s << ": got ("
                                      << got.r << ", " << got.g << ", " << got.b << ", " << got.a << ") depth " << depth
                                      << ", expected (" << want.r << ", " << want.g << ", " << want.b << ", " << want.a
                                      << ") depth " << want_depth;
                }
            }
        }
    EXPECT_EQ(bad, 0) << what << ": samples that differ";
    // Passed: the front quad's samples that survive the alpha test, then the back quad's where it
    // discarded them; a discarded sample is not counted (as an OpenGL occlusion query).
    EXPECT_EQ(r.stats.samples_passed, std::uint64_t{kW} * kH * fb.samples) << what;
    // The texture holds both kinds of pixel in numbers (not a vacuous pass).
    EXPECT_GT(kept, kW * kH / 4) << what;
    EXPECT_LT(kept, 3 * kW * kH / 4) << what;
}

TEST(AlphaTest, OracleValuesAroundTheCutoff) {
    // The oracle's reading of the cutoff: at it kept, just below it discarded.
    glm::vec4 at(0.25f, 0.125f, 0.0f, 0.5f), below(0.2f, 0.1f, 0.0f, 0.4999f), zero(0.0f);
    EXPECT_TRUE(mr::alpha_test(at, 0.5f));
    EXPECT_EQ(at, glm::vec4(0.5f, 0.25f, 0.0f, 1.0f));
    EXPECT_FALSE(mr::alpha_test(below, 0.5f));
    EXPECT_TRUE(mr::alpha_test(zero, 0.0f));  // cutoff 0 keeps alpha 0, black and opaque
    EXPECT_EQ(zero, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    glm::vec4 nan(0.0f, 0.0f, 0.0f, std::numeric_limits<float>::quiet_NaN());
    EXPECT_FALSE(mr::alpha_test(nan, 0.0f));
}

TEST(AlphaTest, DiscardedFragmentsWriteNoDepthOneSample) {
    const MaskScene scene;
    expect_mask_image(scene, render_mask(scene, 1, mr::AntiAliasing::ssaa, 2), kCutoff, "1 sample");
}

TEST(AlphaTest, DiscardedFragmentsWriteNoDepthMsaa4) {
    const MaskScene scene;
    expect_mask_image(scene, render_mask(scene, 4, mr::AntiAliasing::msaa, 2), kCutoff, "MSAA 4x");
}

TEST(AlphaTest, DiscardedFragmentsWriteNoDepthSsaa4) {
    const MaskScene scene;
    expect_mask_image(scene, render_mask(scene, 4, mr::AntiAliasing::ssaa, 2), kCutoff, "SSAA 4x");
}

TEST(AlphaTest, OtherCutoffs) {
    const MaskScene scene;
    for (float cutoff : {0.25f, 0.75f})
        expect_mask_image(scene, render_mask(scene, 4, mr::AntiAliasing::msaa, 2, cutoff), cutoff,
                          "MSAA 4x, cutoff " + std::to_string(cutoff));
}

TEST(AlphaTest, OneAndTwoThreadsAgreeBitForBit) {
    const MaskScene scene;
    for (const auto& [samples, aa] : {std::pair{1, mr::AntiAliasing::ssaa}, std::pair{4, mr::AntiAliasing::msaa},
                                      std::pair{4, mr::AntiAliasing::ssaa}}) {
        const mr::RenderResult one = render_mask(scene, samples, aa, 1), two = render_mask(scene, samples, aa, 2);
        EXPECT_TRUE(same_bits(one.color.pixels, two.color.pixels)) << samples << " samples";
        EXPECT_TRUE(same_bits(one.framebuffer.color, two.framebuffer.color)) << samples << " samples";
        EXPECT_TRUE(same_bits(one.framebuffer.depth, two.framebuffer.depth)) << samples << " samples";
    }
}

TEST(AlphaTest, AlphaTestedRenderIsNotDeferred) {
    // Two screen-sized quads are overdraw 2: without the cutoff the tiles are deferred.
    const MaskScene scene;
    std::vector<mr::Draw> draws = scene.draws(kCutoff);
    mr::RenderSettings s = helpers::settings(kW, kH, 1);
    EXPECT_EQ(mr::render(draws, identity_camera(), s).stats.tiles_deferred, 0u);
    draws[0].state.alpha_cutoff.reset();
    EXPECT_GT(mr::render(draws, identity_camera(), s).stats.tiles_deferred, 0u);
}

TEST(AlphaTest, UntexturedDrawTestsTheColourAlpha) {
    // Without a texture the alpha is the draw colour's × the vertex colours': vertex alphas 0.2 on
    // the left edge and 1 on the right, screen interpolation; columns whose alpha is below 0.5 show
    // the back quad.
    mr::Mesh front = screen_quad(-0.5f, false), back = screen_quad(0.5f, false);
    const float a0 = 0.2f, a1 = 1.0f;
    front.colors = {{0.6f * a0, 0.4f * a0, 0.2f * a0, a0}, {0.6f * a1, 0.4f * a1, 0.2f * a1, a1},
                    {0.6f * a1, 0.4f * a1, 0.2f * a1, a1}, {0.6f * a0, 0.4f * a0, 0.2f * a0, a0}};
    mr::DrawState masked;
    masked.alpha_cutoff = 0.5f;
    masked.interpolation = mr::Interpolation::screen;
    const std::vector<mr::Draw> draws = {make_draw(front, fixed_to_ndc(kW, kH), masked),
                                         make_draw(back, fixed_to_ndc(kW, kH), mr::DrawState(), kBehind)};
    for (int samples : {1, 4}) {
        mr::RenderSettings s = helpers::settings(kW, kH, samples);
        s.anti_aliasing = mr::AntiAliasing::msaa;
        const mr::RenderResult r = mr::render(draws, identity_camera(), s);
        for (int j = 0; j < kH; ++j)
            for (int i = 0; i < kW; ++i) {
                // Alpha at the pixel centre (MSAA shades there): linear in x across the quad.
                const double a = a0 + (a1 - a0) * (i + 0.5) / kW;
                const glm::vec4 got = helpers::sample_color(r.framebuffer, i, j, 0);
                if (std::abs(a - 0.5) < 1e-3) continue;  // too near the cutoff for a double oracle
                if (a < 0.5) {
                    EXPECT_EQ(got, kBehind) << "pixel (" << i << ", " << j << ")";
                } else {
                    EXPECT_NEAR(got.r, 0.6f, 1e-6f) << "pixel (" << i << ", " << j << ")";
                    EXPECT_NEAR(got.g, 0.4f, 1e-6f);
                    EXPECT_NEAR(got.b, 0.2f, 1e-6f);
                    EXPECT_EQ(got.a, 1.0f);
                }
            }
    }
}

TEST(AlphaTest, NoCutoffLeavesTheFrontQuadOpaque) {
    // The same scene without alpha_cutoff: the front quad's premultiplied texels everywhere (the
    // behaviour the cutoff changes).
    const MaskScene scene;
    std::vector<mr::Draw> draws = scene.draws(kCutoff);
    draws[0].state.alpha_cutoff.reset();
    const mr::RenderResult r = mr::render(draws, identity_camera(), helpers::settings(kW, kH, 1));
    for (int j = 0; j < kH; j += 7)
        for (int i = 0; i < kW; i += 5)
            EXPECT_EQ(helpers::sample_color(r.framebuffer, i, j, 0),
                      scene.texture.base_level().texels[static_cast<std::size_t>(j) * kW + i]);
}

TEST(AlphaTest, BadCutoffIsAnErrorNamingIt) {
    const MaskScene scene;
    for (float bad : {std::numeric_limits<float>::quiet_NaN(), -0.1f, 1.5f}) {
        std::vector<mr::Draw> draws = scene.draws(kCutoff);
        draws[0].state.alpha_cutoff = bad;
        try {
            mr::render(draws, identity_camera(), helpers::settings(kW, kH, 1));
            ADD_FAILURE() << "no error for cutoff " << bad;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("draws[0].state.alpha_cutoff"), std::string::npos) << e.what();
        }
    }
}

TEST(AlphaTest, ToStringShowsTheCutoff) {
    mr::DrawState st;
    EXPECT_EQ(st.to_string().find("alpha_cutoff"), std::string::npos);
    st.alpha_cutoff = 0.3f;
    EXPECT_NE(st.to_string().find("alpha_cutoff=0.3"), std::string::npos) << st.to_string();
}

}  // namespace
