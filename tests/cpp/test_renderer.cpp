// The renderer as a whole: bit-identical output for any thread count (DESIGN.md §2.8), bad input
// rejected with std::invalid_argument naming it (§7) before anything large is allocated,
// non-finite triangles dropped and counted, and an empty draw list rendering the clear colour.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "helpers.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

// ---------------------------------------------------------------------------------------------
// Determinism
// ---------------------------------------------------------------------------------------------

/// `n` random triangles of size about `size` in the box [−2, 2]×[−1.5, 1.5]×[−2, 6] (the camera is
/// at z = 4, so some cross the near plane or lie behind it), with premultiplied vertex colours.
mr::Mesh random_triangles(std::size_t n, double size, std::uint64_t seed) {
    return helpers::random_triangles(n, size, seed, {-2.0, -1.5, -2.0}, {4.0, 3.0, 8.0});
}

// A render of more set-up triangles than kStreamedSetupBytes stores their records with streaming
// stores: 40,000 triangles on screen give the same image, depth and counters whether they are
// drawn alone (kept in the cache) or with 40,000 more that lie off the screen (streamed).
TEST(Renderer, SetUpRecordsStoredPastTheCacheGiveTheSameImage) {
    const int W = 160, H = 120;
    const std::size_t n = 40000;
    static_assert(40000 * sizeof(mr::SetupTriangle) <= mr::kStreamedSetupBytes &&
                  2 * 40000 * sizeof(mr::SetupTriangle) > mr::kStreamedSetupBytes);
    const mr::Camera cam =
        mr::Camera::look_at_perspective({0.3, 1.0, 4.0}, {0, 0, 0}, {0, 1, 0}, 1.0, double(W) / H, 0.05);
    const mr::Mesh on_screen = random_triangles(n, 0.15, 5), elsewhere = random_triangles(n, 0.15, 6);
    glm::dmat4 aside(1.0);
    aside[3] = glm::dvec4(1000.0, 0.0, 0.0, 1.0);
    for (int threads : {1, 2})
        for (int S : {1, 4}) {
            SCOPED_TRACE(std::to_string(threads) + " threads, " + std::to_string(S) + " samples");
            auto s = settings(W, H, S);
            s.threads = threads;
            const mr::Draw drawn = make_draw(on_screen, glm::dmat4(1.0), mr::DrawState{});
            const mr::RenderResult kept = mr::render({drawn}, cam, s);
            const mr::RenderResult streamed = mr::render({drawn, make_draw(elsewhere, aside, mr::DrawState{})}, cam, s);
            EXPECT_EQ(streamed.stats.triangles_outside, kept.stats.triangles_outside + n);
            EXPECT_GT(kept.stats.samples_passed, 10000u * S);
            EXPECT_TRUE(same_bits(streamed.color.pixels, kept.color.pixels)) << "resolved colour differs";
            EXPECT_TRUE(same_bits(streamed.framebuffer.color, kept.framebuffer.color)) << "samples differ";
            EXPECT_TRUE(same_bits(streamed.framebuffer.depth, kept.framebuffer.depth)) << "depth differs";
            EXPECT_EQ(streamed.stats.samples_passed, kept.stats.samples_passed);
            EXPECT_EQ(streamed.stats.shader_invocations, kept.stats.shader_invocations);
        }
}

// Draws of fewer triangles than a chunk's minimum share chunks (a tile's list then changes draw
// in runs): 200 three-triangle draws of mixed states (textured or not, replace or over, depth
// written or not, alpha-tested) give the bits and counters they give when each is padded with
// 300 triangles off the screen, which makes it a chunk of its own.
TEST(Renderer, SmallDrawsSharingChunksDrawAsDrawsOfTheirOwnChunks) {
    const int W = 96, H = 80;
    const std::size_t kDraws = 200, kPadding = 300;
    const mr::Mesh all = overlapping(3 * kDraws, 1.5, 21);
    const mr::Texture texture = checker_texture();
    std::vector<mr::Mesh> small(kDraws), padded(kDraws);
    for (std::size_t d = 0; d < kDraws; ++d) {
        for (std::size_t v = 9 * d; v < 9 * d + 9; ++v) {
            small[d].positions.push_back(all.positions[v]);
            small[d].colors.push_back(all.colors[v]);
            small[d].uvs.push_back(all.uvs[v]);
        }
        for (std::uint32_t t = 0; t < 3; ++t) add_triangle(small[d], 3 * t, 3 * t + 1, 3 * t + 2);
        padded[d] = small[d];
        for (std::size_t t = 0; t < kPadding; ++t) {
            const auto first = static_cast<std::uint32_t>(padded[d].positions.size());
            for (const glm::vec3& p : {glm::vec3(1000, 0, 0), glm::vec3(1001, 0, 0), glm::vec3(1000, 1, 0)}) {
                padded[d].positions.push_back(p);
                padded[d].colors.push_back(glm::vec4(1.0f));
                padded[d].uvs.push_back(glm::vec2(0.0f));
            }
            add_triangle(padded[d], first, first + 1, first + 2);
        }
    }
    const auto scene = [&](const std::vector<mr::Mesh>& meshes) {
        std::vector<mr::Draw> draws;
        for (std::size_t d = 0; d < kDraws; ++d) {
            mr::DrawState state;
            state.blend = d % 2 ? mr::BlendMode::over : mr::BlendMode::replace;
            state.depth_write = d % 7 != 3;
            if (d % 5 == 4) state.alpha_cutoff = 0.6f;
            draws.push_back(make_draw(meshes[d], glm::dmat4(1.0), state));
            if (d % 3 == 0) draws.back().texture = texture;
        }
        return draws;
    };
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    for (int threads : {1, 2})
        for (const auto& [samples, aa] : {std::pair{1, mr::AntiAliasing::ssaa}, std::pair{4, mr::AntiAliasing::msaa},
                                          std::pair{4, mr::AntiAliasing::ssaa}}) {
            SCOPED_TRACE(std::to_string(threads) + " threads, " + std::to_string(samples) + " " + mr::to_string(aa));
            auto s = settings(W, H, samples);
            s.anti_aliasing = aa;
            s.threads = threads;
            const mr::RenderResult shared = mr::render(scene(small), cam, s), own = mr::render(scene(padded), cam, s);
            expect_same_render(shared, own);
            EXPECT_EQ(own.stats.triangles_outside, shared.stats.triangles_outside + kDraws * kPadding);
            EXPECT_EQ(own.stats.tiles_deferred, shared.stats.tiles_deferred);
            EXPECT_GT(shared.stats.samples_passed, std::uint64_t{W} * H);
        }
}

TEST(Renderer, OneTwoAndFourThreadsGiveBitIdenticalColourAndDepthForEveryBlendModeSsaaAndMsaa) {
    const int W = 160, H = 120;
    const mr::Camera cam = mr::Camera::look_at_perspective({0.3, 1.0, 4.0}, {0, 0, 0}, {0, 1, 0}, 1.0, double(W) / H, 0.05);
    // A few thousand large overlapping triangles, then 40,000 small ones: more than 4096 per
    // thread, so the setup splits them into a different number of chunks for each thread count.
    const mr::Mesh large = random_triangles(3000, 1.5, 1), small = random_triangles(40000, 0.15, 2);
    for (mr::BlendMode blend : {mr::BlendMode::replace, mr::BlendMode::add, mr::BlendMode::over}) {
        for (int mode = 0; mode < 4; ++mode) {
            // SSAA and MSAA at 4 samples, MSAA at 16, and one sample per pixel.
            const mr::AntiAliasing aa = mode == 1 || mode == 2 ? mr::AntiAliasing::msaa : mr::AntiAliasing::ssaa;
            const int S = mode == 2 ? 16 : mode == 3 ? 1 : 4;
            SCOPED_TRACE(mr::to_string(blend) + ", " + mr::to_string(aa) + ", " + std::to_string(S) + " samples");
            mr::DrawState a;  // depth test and write, perspective-correct colours
            a.blend = blend;
            mr::DrawState b = a;
            b.interpolation = mr::Interpolation::screen;
            b.cull = mr::CullMode::back;
            const std::vector<mr::Draw> draws = {make_draw(large, glm::dmat4(1.0), a),
                                                 make_draw(small, glm::dmat4(1.0), b, glm::vec4(0.9f, 0.8f, 1.0f, 1.0f))};
            mr::RenderResult ref;
            for (int threads : {1, 2, 4}) {
                auto s = settings(W, H, S);
                s.anti_aliasing = aa;
                s.threads = threads;
                s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                mr::RenderResult r = mr::render(draws, cam, s);
                EXPECT_EQ(r.stats.threads, threads);
                if (threads == 1) {
                    ASSERT_TRUE(r.framebuffer.has_depth());
                    EXPECT_GT(r.stats.triangles_clipped, 0u);
                    EXPECT_GT(r.stats.samples_passed, 20000u * S);
                    ref = std::move(r);
                    continue;
                }
                EXPECT_TRUE(same_bits(r.color.pixels, ref.color.pixels)) << threads << " threads: resolved colour differs";
                EXPECT_TRUE(same_bits(r.framebuffer.color, ref.framebuffer.color)) << threads << " threads: samples differ";
                EXPECT_TRUE(same_bits(r.framebuffer.depth, ref.framebuffer.depth)) << threads << " threads: depth differs";
                EXPECT_EQ(r.stats.triangles_in, ref.stats.triangles_in);
                EXPECT_EQ(r.stats.triangles_clipped, ref.stats.triangles_clipped);
                EXPECT_EQ(r.stats.triangles_outside, ref.stats.triangles_outside);
                EXPECT_EQ(r.stats.triangles_backface, ref.stats.triangles_backface);
                EXPECT_EQ(r.stats.triangles_degenerate, ref.stats.triangles_degenerate);
                EXPECT_EQ(r.stats.triangles_rasterized, ref.stats.triangles_rasterized);
                EXPECT_EQ(r.stats.samples_covered, ref.stats.samples_covered);
                EXPECT_EQ(r.stats.samples_passed, ref.stats.samples_passed);
                EXPECT_EQ(r.stats.shader_invocations, ref.stats.shader_invocations);
            }
            // Without kept samples each tile works in a buffer of its own (at one sample per pixel,
            // straight in the image; 120 rows leave partial tiles at the bottom): the same image,
            // bit for bit, for every thread count.
            for (int threads : {1, 2, 4}) {
                auto s = settings(W, H, S);
                s.anti_aliasing = aa;
                s.threads = threads;
                s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                s.keep_samples = false;
                const mr::RenderResult r = mr::render(draws, cam, s);
                EXPECT_TRUE(r.framebuffer.color.empty());
                EXPECT_TRUE(same_bits(r.color.pixels, ref.color.pixels)) << threads << " threads, tile buffers: colour differs";
                EXPECT_EQ(r.stats.samples_passed, ref.stats.samples_passed);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

mr::Mesh small_mesh() {
    mr::Mesh m;
    for (int i = 0; i < 10; ++i) m.positions.push_back(glm::vec3(0.1f * i - 0.5f, 0.05f * (i % 3), 0.0f));
    for (std::uint32_t i = 0; i + 2 < 10; ++i) add_triangle(m, i, i + 1, i + 2);
    return m;
}

/// Runs the render and returns the std::invalid_argument message ("" and a failure otherwise).
std::string invalid_argument_message(const std::vector<mr::Draw>& draws, const mr::RenderSettings& s,
                                     const mr::Camera& cam = identity_camera()) {
    try {
        mr::render(draws, cam, s);
    } catch (const std::invalid_argument& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "threw something other than std::invalid_argument: " << e.what();
        return "";
    }
    ADD_FAILURE() << "did not throw";
    return "";
}

#define EXPECT_MESSAGE_HAS(message, part) \
    EXPECT_NE((message).find(part), std::string::npos) << "message: \"" << (message) << "\" lacks \"" << (part) << "\""

TEST(Renderer, NonFiniteVertexPositionThrowsNamingTheVertex) {
    for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                      -std::numeric_limits<float>::infinity()}) {
        mr::Mesh m = small_mesh();
        m.positions[7].y = bad;
        const std::string msg = invalid_argument_message({make_draw(m, glm::dmat4(1.0), no_depth())}, settings(8, 8));
        EXPECT_MESSAGE_HAS(msg, "positions[7]");
        EXPECT_MESSAGE_HAS(msg, "draws[0]");
    }
}

TEST(Renderer, IndexOutOfRangeThrowsNamingTheTriangle) {
    mr::Mesh m = small_mesh();
    m.triangles[5] = glm::uvec3(0, 10, 2);  // 10 vertices: index 10 is one past the end
    const mr::Mesh ok = small_mesh();
    const std::string msg = invalid_argument_message(
        {make_draw(ok, glm::dmat4(1.0), no_depth()), make_draw(m, glm::dmat4(1.0), no_depth())}, settings(8, 8));
    EXPECT_MESSAGE_HAS(msg, "triangles[5]");
    EXPECT_MESSAGE_HAS(msg, "draws[1]");
}

// Mesh::validate checks all components at once before it looks for the first bad one: on random
// meshes, one non-finite component anywhere (positions, colours or uvs) or one index past the
// last vertex is named, and the finite extremes (±float max, the smallest subnormal, −0) and the
// last vertex's index pass.
TEST(Renderer, MeshValidationNamesEveryBadEntryAndPassesTheFiniteExtremes) {
    std::mt19937_64 rng(47);
    const float kInf = std::numeric_limits<float>::infinity();
    const float bad[] = {std::numeric_limits<float>::quiet_NaN(), kInf, -kInf};
    const float extreme[] = {std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                             std::numeric_limits<float>::denorm_min(), -0.0f};
    const char* const axis = "xyz", *const channel = "rgba", *const uv = "uv";
    for (int trial = 0; trial < 300; ++trial) {
        const std::size_t n = 1 + rng() % 200;
        mr::Mesh m = helpers::random_triangles(n, 0.5, rng(), {-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0});
        m.uvs.assign(m.positions.size(), glm::vec2(0.5f));
        const std::size_t v = rng() % m.positions.size(), t = rng() % m.triangles.size();
        const int k = static_cast<int>(rng() % 3);
        m.positions[v][k] = extreme[rng() % 4];
        m.colors[v][3 - k] = extreme[rng() % 4];
        m.triangles[t][k] = static_cast<std::uint32_t>(m.positions.size() - 1);
        EXPECT_NO_THROW(m.validate("mesh")) << "trial " << trial;
        mr::Mesh broken = m;
        std::string expected;
        const std::string at = "[" + std::to_string(v) + "].";
        switch (trial % 4) {
            case 0: broken.positions[v][k] = bad[rng() % 3], expected = ".positions" + at + axis[k]; break;
            case 1: {  // (any of the four channels)
                const int c = (k + trial / 4) % 4;
                broken.colors[v][c] = bad[rng() % 3], expected = ".colors" + at + channel[c];
                break;
            }
            case 2: broken.uvs[v][k % 2] = bad[rng() % 3], expected = ".uvs" + at + uv[k % 2]; break;
            default:
                broken.triangles[t][k] = static_cast<std::uint32_t>(m.positions.size() + rng() % 3);
                expected = ".triangles[" + std::to_string(t) + "][" + std::to_string(k) + "]";
        }
        try {
            broken.validate("mesh");
            ADD_FAILURE() << "trial " << trial << ": " << expected << " not refused";
        } catch (const std::invalid_argument& e) {
            EXPECT_MESSAGE_HAS(std::string(e.what()), expected);
        }
    }
}

TEST(Renderer, ColourArrayOfTheWrongSizeThrowsNamingIt) {
    mr::Mesh m = small_mesh();
    m.colors.assign(9, glm::vec4(1.0f));
    const std::string msg = invalid_argument_message({make_draw(m, glm::dmat4(1.0), no_depth())}, settings(8, 8));
    EXPECT_MESSAGE_HAS(msg, "colors");
    EXPECT_MESSAGE_HAS(msg, "9");
    EXPECT_MESSAGE_HAS(msg, "10");
}

TEST(Renderer, NonFiniteVertexColourOrDrawColourThrowsNamingIt) {
    mr::Mesh m = small_mesh();
    m.colors.assign(10, glm::vec4(1.0f));
    m.colors[3].a = std::numeric_limits<float>::quiet_NaN();
    EXPECT_MESSAGE_HAS(invalid_argument_message({make_draw(m, glm::dmat4(1.0), no_depth())}, settings(8, 8)), "colors[3]");
    const mr::Mesh ok = small_mesh();
    const std::string msg = invalid_argument_message(
        {make_draw(ok, glm::dmat4(1.0), no_depth(), glm::vec4(1, std::numeric_limits<float>::infinity(), 1, 1))},
        settings(8, 8));
    EXPECT_MESSAGE_HAS(msg, "color");
    EXPECT_MESSAGE_HAS(msg, "draws[0]");
}

TEST(Renderer, NullMeshThrowsNamingTheDraw) {
    const mr::Mesh ok = small_mesh();
    mr::Draw null_draw = make_draw(ok, glm::dmat4(1.0), no_depth());
    null_draw.mesh = nullptr;
    const std::string msg =
        invalid_argument_message({make_draw(ok, glm::dmat4(1.0), no_depth()), null_draw}, settings(8, 8));
    EXPECT_MESSAGE_HAS(msg, "draws[1]");
    EXPECT_MESSAGE_HAS(msg, "mesh");
}

TEST(Renderer, BadResolutionThrowsNamingTheDimensionBeforeAllocating) {
    const mr::Mesh ok = small_mesh();
    const std::vector<mr::Draw> draws = {make_draw(ok, glm::dmat4(1.0), mr::DrawState{})};
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(0, 8)), "width");
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(-3, 8)), "width");
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(8, 0)), "height");
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(8, -1)), "height");
    // Absurd: 100000 × 100000 exceeds the largest dimension; the message names the limit.
    const std::string big = invalid_argument_message(draws, settings(100000, 100000));
    EXPECT_MESSAGE_HAS(big, "width");
    EXPECT_MESSAGE_HAS(big, "32768");
    // ... and the memory it would need: 10^10 pixels × (16 B colour + 4 B depth) = 190734 MiB.
    EXPECT_MESSAGE_HAS(big, "190734 MiB");
    // Within the dimension limit but beyond the default memory limit (the kept samples alone are
    // 32768² × 64 samples × 20 bytes = 1.25 TiB): refused with the memory it would need, not a
    // std::bad_alloc or a crash.
    const std::string huge = invalid_argument_message(draws, settings(32768, 32768, 64));
    EXPECT_MESSAGE_HAS(huge, "a render of 32768x32768 pixels at 64 samples per pixel needs 1.27 TiB");
    EXPECT_MESSAGE_HAS(huge, "the memory limit is 16.0 GiB");
}

TEST(Renderer, BadSampleCountsAndPatternsThrowNamingThem) {
    const mr::Mesh ok = small_mesh();
    const std::vector<mr::Draw> draws = {make_draw(ok, glm::dmat4(1.0), no_depth())};
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(8, 8, 0)), "samples");
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(8, 8, 65)), "samples");
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(8, 8, 9, mr::PatternKind::rotated)), "rotated");
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(8, 8, 4, mr::PatternKind::center)), "center");
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, settings(8, 8, 65, mr::PatternKind::grid)), "65");
    auto s = settings(8, 8);
    s.threads = -1;
    EXPECT_MESSAGE_HAS(invalid_argument_message(draws, s), "threads");
}

// ---------------------------------------------------------------------------------------------
// Non-finite transforms and empty input
// ---------------------------------------------------------------------------------------------

TEST(Renderer, TrianglesMadeNonFiniteByTheModelMatrixAreDroppedCountedAndDrawNothing) {
    const int W = 16, H = 16;
    mr::Mesh big;
    big.positions = {{-4096, -4096, 0}, {8192, -4096, 0}, {-4096, 8192, 0}, {100, 100, 0}, {3000, 200, 0}, {900, 3500, 0}};
    add_triangle(big, 0, 1, 2);
    add_triangle(big, 3, 4, 5);
    for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        glm::dmat4 model = fixed_to_ndc(W, H);
        model[0][0] = bad;
        const mr::RenderResult r =
            mr::render({make_draw(big, model, mr::DrawState{})}, identity_camera(), settings(W, H, 4));
        EXPECT_EQ(r.stats.triangles_in, 2u);
        EXPECT_EQ(r.stats.triangles_nonfinite, 2u);
        EXPECT_EQ(r.stats.triangles_rasterized, 0u);
        EXPECT_EQ(r.stats.samples_covered, 0u);
        EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(W * H * 4, 0.0f), 0, "red"));
        EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(W * H * 4, 0.0f), 3, "alpha"));
    }
    // Next to a valid draw, only the bad one is dropped; the valid one draws what the oracle says.
    glm::dmat4 nan_model = fixed_to_ndc(W, H);
    nan_model[3][1] = std::numeric_limits<double>::quiet_NaN();
    mr::Mesh one;
    one.positions = {{100, 100, 0}, {3000, 200, 0}, {900, 3500, 0}};
    add_triangle(one, 0, 1, 2);
    const mr::RenderResult r = mr::render({make_draw(big, nan_model, no_depth(mr::BlendMode::add)),
                                           make_draw(one, fixed_to_ndc(W, H), no_depth(mr::BlendMode::add))},
                                          identity_camera(), settings(W, H, 4, mr::PatternKind::rotated));
    EXPECT_EQ(r.stats.triangles_nonfinite, 2u);
    EXPECT_EQ(r.stats.triangles_rasterized, 1u);
    std::vector<int> counts(W * H * 4, 0);
    oracle::accumulate_coverage(snapped_triangle(one, 0), W, H, oracle::rotated_pattern(), counts);
    EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(counts.begin(), counts.end()), 0, "coverage"));
}

TEST(Renderer, ZeroThreadsMeansEveryHardwareThread) {
    auto s = settings(8, 8);
    s.threads = 0;
    const mr::RenderResult r = mr::render({}, identity_camera(), s);
    const unsigned hw = std::thread::hardware_concurrency();
    EXPECT_EQ(r.stats.threads, hw == 0 ? 1 : static_cast<int>(hw));
}

TEST(Renderer, EmptyDrawListRendersTheClearColour) {
    for (int S : {1, 4, 16}) {
        auto s = settings(7, 5, S);
        s.clear_color = glm::vec4(0.125f, 0.25f, 0.5f, 0.75f);
        const mr::RenderResult r = mr::render({}, identity_camera(), s);
        ASSERT_EQ(r.color.width, 7);
        ASSERT_EQ(r.color.height, 5);
        ASSERT_EQ(r.color.channels, 4);
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 7; ++x)
                for (int c = 0; c < 4; ++c) EXPECT_EQ(r.color.at(x, y, c), s.clear_color[c]);
        EXPECT_FALSE(r.framebuffer.has_depth());
        EXPECT_EQ(r.stats.triangles_in, 0u);
        EXPECT_EQ(r.stats.samples_covered, 0u);
        // A draw with an empty mesh is the same.
        const mr::Mesh empty;
        const mr::RenderResult e = mr::render({make_draw(empty, glm::dmat4(1.0), no_depth())}, identity_camera(), s);
        EXPECT_EQ(e.color.pixels, r.color.pixels);
    }
}

}  // namespace

namespace {

TEST(Renderer, ProgressReportsEveryTileOnceInIncreasingOrderEndingAtTheTotal) {
    const mr::Mesh ok = small_mesh();
    // Every tile drawn; half of them masked out; a few pixels listed (most tiles have none).
    for (int part : {0, 1, 2}) {
        for (int threads : {1, 3}) {
            SCOPED_TRACE(std::to_string(part) + ", " + std::to_string(threads) + " threads");
            auto s = settings(100, 70, 4);  // 4 × 3 tiles of 32 px, the last ones partial
            s.threads = threads;
            if (part == 1) s.tile_mask = {1, 0, 1, 0, 0, 1, 0, 1, 1, 0, 1, 0};
            if (part == 2) s.keep_samples = false, s.pixels = {0, 5, 3 * 100 + 40};
            std::vector<std::pair<std::size_t, std::size_t>> calls;
            s.progress = [&](std::size_t done, std::size_t total) { calls.emplace_back(done, total); };
            mr::render({make_draw(ok, glm::dmat4(1.0), mr::DrawState{})}, mr::Camera{}, s);
            ASSERT_EQ(calls.size(), 12u) << threads;
            for (std::size_t i = 0; i < calls.size(); ++i) {
                EXPECT_EQ(calls[i].first, i + 1);
                EXPECT_EQ(calls[i].second, 12u);
            }
        }
    }
}

// The colour image starts unwritten (Image::unfilled): every path must write each pixel. Freed heap
// memory is filled with a poison first, so a pixel left unwritten keeps it. The poison is the byte
// 0xbe, which is also what AddressSanitizer writes into the first 4 KiB of every allocation.
constexpr unsigned char kPoisonByte = 0xbe;

bool holds_poison(const float* values, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t bits;
        std::memcpy(&bits, values + i, sizeof bits);
        if (bits == 0xbebebebeu) return true;
    }
    return false;
}

// Leaves freed, poisoned heap blocks of `bytes` each behind (below the mmap threshold, so the next
// allocations of that size come from them); the returned guard keeps the heap from trimming them.
TEST(Renderer, ImagesStartOnACacheLine) {
    // Tiles of one render write the colour image from several threads; with the image on a
    // cache line (and rows a multiple of 64 bytes) no line straddles two tiles.
    const auto aligned = [](const mr::Image& image) {
        return reinterpret_cast<std::uintptr_t>(image.pixels.data()) % 64 == 0;
    };
    for (auto [w, h, c] : {std::array<int, 3>{1, 1, 1}, {3, 5, 4}, {1920, 1080, 4}, {640, 7, 1}}) {
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + "x" + std::to_string(c));
        std::vector<char> odd(13);  // (so the allocator's next block is not aligned by chance alone)
        EXPECT_TRUE(aligned(mr::Image::unfilled(w, h, c)));
        EXPECT_TRUE(aligned(mr::Image(w, h, c)));
    }
    const mr::Mesh mesh = random_triangles(50, 1.0, 9);
    const mr::Camera cam = mr::Camera::look_at_perspective({0.3, 1.0, 4.0}, {0, 0, 0}, {0, 1, 0}, 1.0, 33.0 / 21, 0.05);
    const mr::RenderResult r = mr::render({make_draw(mesh, glm::dmat4(1.0), mr::DrawState{})}, cam, settings(33, 21, 1));
    EXPECT_TRUE(aligned(r.color));
}

std::vector<char> poison_the_heap(std::size_t bytes) {
    std::vector<std::vector<char>> blocks;
    for (int i = 0; i < 16; ++i) blocks.emplace_back(bytes, static_cast<char>(kPoisonByte));
    std::vector<char> guard(64);
    return guard;
}

TEST(Renderer, EveryPathWritesEveryPixelOfTheUnfilledColourImage) {
    const int W = 100, H = 70;  // 112,000-byte image: from the heap, with partial tiles
    const std::size_t bytes = std::size_t{W} * H * 4 * sizeof(float);
    {
        const std::vector<char> guard = poison_the_heap(bytes);
        const mr::Image control = mr::Image::unfilled(W, H, 4);
        ASSERT_TRUE(holds_poison(control.pixels.data(), control.pixels.size()))
            << "the poison does not reach a new image here, so this test could not see an unwritten pixel";
    }
    const mr::Mesh mesh = helpers::random_triangles(300, 0.8, 7, {-1.5, -1.2, -1.0}, {3.0, 2.4, 2.0});
    const mr::Camera cam = mr::Camera::look_at_perspective({0.0, 0.0, 4.0}, {0, 0, 0}, {0, 1, 0}, 0.8, double(W) / H, 0.1);
    struct Case {
        const char* name;
        int samples;
        mr::AntiAliasing aa;
        void (*adjust)(mr::RenderSettings&);
    };
    const Case cases[] = {
        {"1 sample", 1, mr::AntiAliasing::ssaa, [](mr::RenderSettings&) {}},
        {"SSAA 4", 4, mr::AntiAliasing::ssaa, [](mr::RenderSettings&) {}},
        {"MSAA 4", 4, mr::AntiAliasing::msaa, [](mr::RenderSettings&) {}},
        {"no deferred shading", 1, mr::AntiAliasing::ssaa, [](mr::RenderSettings& s) { s.deferred_shading = false; }},
        {"kept samples", 4, mr::AntiAliasing::ssaa, [](mr::RenderSettings& s) { s.keep_samples = true; }},
        {"kept samples, 1 sample", 1, mr::AntiAliasing::ssaa, [](mr::RenderSettings& s) { s.keep_samples = true; }},
        {"lanczos3 resolve", 4, mr::AntiAliasing::ssaa,
         [](mr::RenderSettings& s) { s.resolve_filter = mr::ResolveFilter::lanczos3; }},
        {"error estimate", 4, mr::AntiAliasing::ssaa, [](mr::RenderSettings& s) { s.estimate_error = true; }},
        {"tile mask", 4, mr::AntiAliasing::ssaa, [](mr::RenderSettings& s) {
             const int tiles = ((100 + mr::kTileSize - 1) / mr::kTileSize) * ((70 + mr::kTileSize - 1) / mr::kTileSize);
             for (int t = 0; t < tiles; ++t) s.tile_mask.push_back(t % 3 == 0);
         }},
        {"listed pixels", 4, mr::AntiAliasing::ssaa, [](mr::RenderSettings& s) { s.pixels = {0, 5, 250, 6999}; }},
        {"listed pixels, 1 sample", 1, mr::AntiAliasing::ssaa, [](mr::RenderSettings& s) { s.pixels = {3, 4000}; }},
    };
    for (const Case& c : cases)
        for (int threads : {1, 2}) {
            SCOPED_TRACE(std::string(c.name) + ", " + std::to_string(threads) + " threads");
            mr::RenderSettings s = settings(W, H, c.samples);
            s.anti_aliasing = c.aa;
            s.threads = threads;
            s.clear_color = glm::vec4(0.25f, 0.5f, 0.75f, 1.0f);
            c.adjust(s);
            const std::vector<char> guard = poison_the_heap(bytes);
            const mr::RenderResult r = mr::render({make_draw(mesh, glm::dmat4(1.0), mr::DrawState{})}, cam, s);
            ASSERT_EQ(r.color.pixels.size(), std::size_t{W} * H * 4);
            EXPECT_FALSE(holds_poison(r.color.pixels.data(), r.color.pixels.size()));
        }
}

// Where every draw tests and writes depth and replaces colour, the renderer clears a tile's colour
// after drawing, only at the samples still at the clear depth (fill_undrawn). The image, depth and
// counters must be those of a clear before drawing: of the same scene with a no-op draw (one
// triangle off the screen, blending add, no depth test) that breaks the condition, and of the
// kept-samples path, which starts from a cleared framebuffer. Scenes whose draws break it
// themselves (a draw blending over, one not writing depth, one not testing it) must match the
// kept-samples path too. Random overlapping triangles leave background in most tiles; partial
// tiles; textured, alpha-tested and untextured draws; both depth conventions; every sample mode;
// deferred shading on and off, listed pixels and the error estimate (which reads the samples);
// one and two threads. The clear colour holds a −0 and a subnormal, which a resolve keeps.
TEST(Renderer, ColourClearedAfterDrawingGivesTheImageOfTheClearBefore) {
    const int W = 100, H = 70;
    const mr::Mesh a = overlapping(60, 1.2, 31), b = overlapping(40, 0.8, 32);
    const mr::Mesh off_screen = helpers::random_triangles(1, 0.1, 33, {50.0, 50.0, 0.0}, {1.0, 1.0, 1.0});
    const mr::Texture texture = checker_texture();
    glm::dmat4 shifted(1.0);
    shifted[3] = glm::dvec4(0.4, -0.2, 0.3, 1.0);
    mr::DrawState cut, over, read_only, untested;
    cut.alpha_cutoff = 0.5f;
    over.blend = mr::BlendMode::over;
    read_only.depth_write = false;
    untested.depth_test = false;  // (depth_write on, but an untested draw stores no depth)
    std::vector<std::uint32_t> pixels;
    for (std::uint32_t i = 0; i < std::uint32_t(W * H); i += 2) pixels.push_back(i);
    const std::pair<mr::AntiAliasing, int> modes[] = {{mr::AntiAliasing::ssaa, 1}, {mr::AntiAliasing::ssaa, 4},
                                                      {mr::AntiAliasing::msaa, 4}, {mr::AntiAliasing::msaa, 16}};
    const mr::DrawState last_states[] = {mr::DrawState{}, over, read_only, untested};  // [0]: cleared after
    // (With listed pixels the kept-samples path draws whole tiles, the other only the pixels'
    // spans: their counters differ.)
    const auto same = [](const mr::RenderResult& r, const mr::RenderResult& before, bool counters) {
        EXPECT_TRUE(same_bits(r.color.pixels, before.color.pixels)) << "colour differs";
        EXPECT_TRUE(same_bits(r.depth.pixels, before.depth.pixels)) << "depth differs";
        EXPECT_TRUE(same_bits(r.error_map.pixels, before.error_map.pixels)) << "error map differs";
        if (!counters) return;
        EXPECT_EQ(r.stats.samples_covered, before.stats.samples_covered);
        EXPECT_EQ(r.stats.samples_passed, before.stats.samples_passed);
        EXPECT_EQ(r.stats.shader_invocations, before.stats.shader_invocations);
    };
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        for (std::size_t scene = 0; scene < std::size(last_states); ++scene) {
            const glm::vec4 tint(0.5f, 0.7f, 0.2f, 0.6f);
            std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), mr::DrawState{}),
                                           make_draw(b, glm::dmat4(1.0), cut, glm::vec4(0.9f, 0.6f, 1.0f, 0.8f)),
                                           make_draw(b, shifted, last_states[scene], tint)};
            draws[0].texture = texture;
            draws[1].texture = texture;
            std::vector<mr::Draw> with_no_op = draws;
            with_no_op.push_back(make_draw(off_screen, glm::dmat4(1.0), no_depth(mr::BlendMode::add)));
            for (const auto& [aa, samples] : modes)
                for (int variant = 0; variant < 4; ++variant)
                    for (int threads : {1, 2}) {
                        SCOPED_TRACE(mr::to_string(convention) + ", scene " + std::to_string(scene) + ", " +
                                     mr::to_string(aa) + " " + std::to_string(samples) + ", variant " +
                                     std::to_string(variant) + ", " + std::to_string(threads) + " threads");
                        mr::RenderSettings s = settings(W, H, samples);
                        s.anti_aliasing = aa;
                        s.threads = threads;
                        s.depth_output = true;
                        s.clear_color = glm::vec4(0.25f, -0.0f, 1e-40f, 1.0f);
                        s.deferred_shading = variant != 1;
                        if (variant == 2) s.pixels = pixels;
                        s.estimate_error = variant == 3 && samples > 1;
                        const mr::RenderResult kept = mr::render(draws, cam, s);  // (settings keep the samples)
                        s.keep_samples = false;
                        const mr::RenderResult tiles = mr::render(draws, cam, s);
                        same(tiles, kept, s.pixels.empty());
                        if (scene == 0) {
                            const mr::RenderResult cleared_before = mr::render(with_no_op, cam, s);
                            same(tiles, cleared_before, true);
                            EXPECT_EQ(cleared_before.stats.triangles_outside, tiles.stats.triangles_outside + 1);
                        }
                    }
        }
    }
}

TEST(Renderer, StatsJsonHoldsEveryCounter) {
    mr::RenderStats st;
    st.triangles_in = 7;
    st.samples_passed = 123456789012ull;
    st.total_ms = 1.5;
    const std::string j = st.to_json();
    EXPECT_EQ(j.front(), '{');
    EXPECT_EQ(j.back(), '}');
    EXPECT_NE(j.find("\"triangles_in\": 7,"), std::string::npos) << j;
    EXPECT_NE(j.find("\"samples_passed\": 123456789012,"), std::string::npos) << j;
    EXPECT_NE(j.find("\"total_ms\": 1.500"), std::string::npos) << j;
    for (const char* key : {"triangles_clipped", "triangles_outside", "triangles_between_samples", "triangles_backface",
                            "triangles_degenerate",
                            "triangles_nonfinite", "triangles_rasterized", "samples_covered", "shader_invocations",
                            "threads", "transform_ms", "setup_ms", "raster_ms"})
        EXPECT_NE(j.find(std::string("\"") + key + "\": "), std::string::npos) << key;
}

}  // namespace

namespace {

// Clip space is homogeneous: a projection times a power of two 2^k draws the same image, and in
// floating point every step scales exactly (clipping, x/w, z/w, the ratios of 1/w), so bit for
// bit. 1/w used to be stored as a float as it came: from k ≈ 127 on it was subnormal there (other
// bits), and from k ≈ 150 zero at every vertex (NaN colours).
TEST(Renderer, AProjectionScaledByAPowerOfTwoDrawsTheSameBits) {
    const int W = 64, H = 48;
    const mr::Mesh mesh = overlapping(40, 1.2, 99);
    for (const mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        glm::dmat4 shifted(1.0);
        shifted[3] = glm::dvec4(0.3, 0.1, -0.4, 1.0);
        std::vector<mr::Draw> draws = {make_draw(mesh, glm::dmat4(1.0), mr::DrawState()),
                                       make_draw(mesh, shifted, mr::DrawState())};
        draws[1].texture = checker_texture();
        mr::RenderSettings s = settings(W, H, 4);
        s.depth_output = true;
        const mr::RenderResult base = mr::render(draws, cam, s);
        ASSERT_GT(base.stats.triangles_clipped, 0u);
        ASSERT_GT(base.stats.samples_passed, std::uint64_t{W} * H);
        for (const int k : {-60, 40, 127, 140, 150, 300, 900}) {
            SCOPED_TRACE(mr::to_string(convention) + ", 2^" + std::to_string(k));
            const mr::Camera scaled = mr::Camera::from_matrices(cam.view, std::ldexp(1.0, k) * cam.projection, convention);
            const mr::RenderResult r = mr::render(draws, scaled, s);
            expect_same_render(r, base);
            EXPECT_TRUE(same_bits(r.depth.pixels, base.depth.pixels)) << "view depth differs";
        }
    }
}

// 1/w of a vertex 3·10^45 times farther than another is below float's range after the scaling
// above; raised to the smallest normal float, samples on the far edge (where the near vertex's
// weight is exactly 0) still get the far vertices' mix, not 0/0.
TEST(Renderer, SamplesOnTheFarEdgeOfATriangle10To45DeepGetTheFarVerticesColours) {
    // clip = (x, y, z/2, z): reverse-Z depth ½ everywhere, w = z.
    glm::dmat4 projection(0.0);
    projection[0][0] = projection[1][1] = 1.0;
    projection[2][2] = 0.5;
    projection[2][3] = 1.0;
    const mr::Camera cam = mr::Camera::from_matrices(glm::dmat4(1.0), projection, mr::DepthConvention::reverse_z);
    const float far = 3e38f, near = 1e-7f;
    mr::Mesh m;
    // Far edge at NDC y = 1/8: pixel row 3's centres (y = 3.5 px at H = 8), a top edge, so they are inside.
    m.positions = {{0.0f, -0.9f * near, near}, {-0.9f * far, far / 8, far}, {0.9f * far, far / 8, far}};
    m.colors = {{0, 0, 1, 1}, {1, 0, 0, 1}, {0, 1, 0, 1}};
    add_triangle(m, 0, 1, 2);
    mr::DrawState st = no_depth();
    st.cull = mr::CullMode::none;
    const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), st)}, cam, settings(8, 8));
    ASSERT_GT(r.stats.samples_covered, 8u);
    for (int x = 0; x < 8; ++x)
        for (int y = 0; y < 8; ++y)
            for (int c = 0; c < 4; ++c) ASSERT_TRUE(std::isfinite(r.color.at(x, y, c))) << x << ", " << y;
    int far_edge = 0;
    for (int x = 0; x < 8; ++x) {  // the edge runs from x = 0.4 to 7.6 px
        if (r.color.at(x, 3, 3) == 0.0f) continue;
        ++far_edge;
        EXPECT_NEAR(r.color.at(x, 3, 0) + r.color.at(x, 3, 1), 1.0f, 1e-6f) << x;
        EXPECT_EQ(r.color.at(x, 3, 2), 0.0f) << x;
    }
    EXPECT_EQ(far_edge, 8);
}

}  // namespace
