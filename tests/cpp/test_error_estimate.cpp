// The per-render error estimate (error_estimate.hpp) and the tile mask that adaptive sampling uses:
// the halves are a checkerboard over the pattern's strata; the estimate of a pixel whose halves
// disagree by d is d·√(nA·nB)/n (d/2 for equal halves), zero where they agree; the estimate the
// renderer returns equals the one computed from its kept samples; a masked render leaves the
// other tiles at the clear colour and renders the flagged ones exactly as a full render does; a
// render of listed pixels renders those (colour, depth, estimate) exactly as a full render does.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "helpers.hpp"
#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/error_estimate.hpp"
#include "mipraster/pipeline/renderer.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

TEST(ErrorEstimate, HalvesAreACheckerboardOverStrata) {
    // 4×4 grid, row-major: stratum (a, b) belongs to half (a + b) mod 2.
    const auto grid = mr::interleaved_halves(mr::make_sample_pattern(mr::PatternKind::grid, 16, 0));
    for (int s = 0; s < 16; ++s) EXPECT_EQ(grid[s], (s % 4 + s / 4) % 2) << "sample " << s;
    // The rotated 4× pattern: (0.375,0.125) and (0.625,0.875) against the other two diagonals.
    const auto rotated = mr::interleaved_halves(mr::make_sample_pattern(mr::PatternKind::rotated, 4, 0));
    EXPECT_EQ(rotated, (std::vector<std::uint8_t>{0, 1, 1, 0}));
    // Stratified: each jittered sample stays in its stratum, so the split is the grid's.
    const auto jitter = mr::interleaved_halves(mr::make_sample_pattern(mr::PatternKind::stratified, 8, 7));
    for (int s = 0; s < 8; ++s) EXPECT_EQ(jitter[s], (s % 4 + s / 4) % 2) << "sample " << s;
    // Two samples split one each; odd counts split as evenly as the checkerboard does (5 + 4).
    EXPECT_EQ(mr::interleaved_halves(mr::make_sample_pattern(mr::PatternKind::grid, 2, 0)),
              (std::vector<std::uint8_t>{0, 1}));
    const auto nine = mr::interleaved_halves(mr::make_sample_pattern(mr::PatternKind::grid, 9, 0));
    int ones = 0;
    for (auto h : nine) ones += h;
    EXPECT_EQ(ones, 4);
}

TEST(ErrorEstimate, OneSampleIsAnError) {
    EXPECT_THROW(mr::interleaved_halves(mr::make_sample_pattern(mr::PatternKind::center, 1, 0)), std::invalid_argument);
    mr::Mesh m;
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
    add_triangle(m, 0, 1, 2);
    mr::RenderSettings s = settings(8, 8, 1);
    s.estimate_error = true;
    try {
        mr::render({make_draw(m, glm::dmat4(1.0), no_depth())}, identity_camera(), s);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("at least 2 samples"), std::string::npos) << e.what();
    }
}

TEST(ErrorEstimate, PixelEstimateFromHalves) {
    // One pixel, 4 samples (halves 0,1,1,0); half 0 is white, half 1 black in R, G, B.
    const auto halves = std::vector<std::uint8_t>{0, 1, 1, 0};
    std::vector<float> samples = {1, 1, 1, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 1};
    mr::SampleWindow w{samples.data(), 4, 0, 0, 1, 4};
    mr::Image map(1, 1, 1);
    mr::estimate_tile_error(w, halves, 0, 0, 1, 1, map);
    EXPECT_FLOAT_EQ(map.at(0, 0, 0), 0.5f);  // |A − B|/2 = 1/2 in every channel
    // Only red differs, by 0.6: sqrt(0.3² / 3).
    samples = {0.6f, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.6f, 0, 0, 1};
    mr::estimate_tile_error(w, halves, 0, 0, 1, 1, map);
    EXPECT_NEAR(map.at(0, 0, 0), std::sqrt(0.09 / 3.0), 1e-7);
    // Unequal halves (3 + 1): scale √(3·1)/4.
    samples = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 1};
    mr::estimate_tile_error(w, {0, 0, 0, 1}, 0, 0, 1, 1, map);
    EXPECT_NEAR(map.at(0, 0, 0), std::sqrt(3.0) / 4.0, 1e-7);
    // Agreeing halves: zero.
    samples.assign(16, 0.25f);
    mr::estimate_tile_error(w, halves, 0, 0, 1, 1, map);
    EXPECT_EQ(map.at(0, 0, 0), 0.0f);
    const mr::ErrorEstimate e = mr::summarize_error_map(map);
    EXPECT_EQ(e.rmse, 0.0);
}

mr::Mesh slanted_triangle() {
    mr::Mesh m;
    m.positions = {{-0.9f, -0.8f, 0}, {0.85f, -0.3f, 0}, {-0.2f, 0.9f, 0}};
    add_triangle(m, 0, 1, 2);
    return m;
}

TEST(ErrorEstimate, RendererMapMatchesItsSamples) {
    const mr::Mesh m = slanted_triangle();
    mr::RenderSettings s = settings(70, 40, 16, mr::PatternKind::stratified);
    s.estimate_error = true;
    const mr::RenderResult r = mr::render({make_draw(m, glm::dmat4(1.0), no_depth())}, identity_camera(), s);
    ASSERT_EQ(r.error_map.width, 70);
    ASSERT_EQ(r.error_map.height, 40);
    const auto halves = mr::interleaved_halves(r.pattern);
    double sum = 0, edge_pixels = 0;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 70; ++x) {
            double a = 0, b = 0;  // white on black: R of each half
            for (int s2 = 0; s2 < 16; ++s2) (halves[s2] ? b : a) += sample_channel(r.framebuffer, x, y, s2, 0);
            const double expected = std::abs(a / 8 - b / 8) / 2.0;  // same in R, G, B
            EXPECT_NEAR(r.error_map.at(x, y, 0), expected, 1e-6) << x << "," << y;
            sum += expected * expected;
            edge_pixels += expected > 0;
        }
    EXPECT_GT(edge_pixels, 20);  // the edges disagree somewhere
    EXPECT_NEAR(r.error_estimate.rmse, std::sqrt(sum / (70 * 40)), 1e-6);
}

TEST(TileMask, RendersOnlyFlaggedTilesExactly) {
    const mr::Mesh m = slanted_triangle();
    const int W = 2 * mr::kTileSize + 5, H = mr::kTileSize + 3;  // 3 × 2 tiles, ragged edges
    mr::RenderSettings s = settings(W, H, 4);
    s.keep_samples = false;
    s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
    const std::vector<mr::Draw> draws = {make_draw(m, glm::dmat4(1.0), no_depth())};
    const mr::RenderResult full = mr::render(draws, identity_camera(), s);
    s.tile_mask = {0, 1, 0, 1, 0, 1};
    const mr::RenderResult part = mr::render(draws, identity_camera(), s);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const int tile = (y / mr::kTileSize) * 3 + x / mr::kTileSize;
            for (int c = 0; c < 4; ++c) {
                const float expected = s.tile_mask[tile] ? full.color.at(x, y, c) : s.clear_color[c];
                ASSERT_EQ(part.color.at(x, y, c), expected) << x << "," << y << " c" << c;
            }
        }
    s.tile_mask = {1, 1};
    try {
        mr::render(draws, identity_camera(), s);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("tile_mask: expected 6 flags"), std::string::npos) << e.what();
    }
}

TEST(ListedPixels, RenderOnlyThoseExactly) {
    const mr::Mesh m = slanted_triangle();
    const int W = 2 * mr::kTileSize + 5, H = mr::kTileSize + 3;
    for (int samples : {1, 4, 16}) {
        mr::RenderSettings s = settings(W, H, samples, samples == 16 ? mr::PatternKind::stratified
                                                                     : mr::PatternKind::automatic);
        s.keep_samples = false;
        s.estimate_error = samples > 1;
        s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
        const std::vector<mr::Draw> draws = {make_draw(m, glm::dmat4(1.0), no_depth())};
        const mr::RenderResult full = mr::render(draws, identity_camera(), s);
        // Scattered pixels, a run across a tile border, a repeat, the last pixel, and most of the
        // first tile (rasterized whole, then resolved only where listed).
        std::vector<bool> wanted(std::size_t(W) * H, false);
        for (std::uint32_t p = 0; p < std::uint32_t(W * H); p += 37) s.pixels.push_back(p);
        for (int y = 0; y < 26; ++y)
            for (int x = 0; x < mr::kTileSize; x += (y == 7 ? 2 : 1)) s.pixels.push_back(std::uint32_t(y * W + x));
        for (int x = mr::kTileSize - 3; x < mr::kTileSize + 4; ++x) s.pixels.push_back(std::uint32_t(20 * W + x));
        s.pixels.push_back(s.pixels.front());
        s.pixels.push_back(std::uint32_t(W * H - 1));
        for (std::uint32_t p : s.pixels) wanted[p] = true;
        const mr::RenderResult part = mr::render(draws, identity_camera(), s);
        int edge = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const bool in = wanted[std::size_t(y) * W + x];
                for (int c = 0; c < 4; ++c)
                    ASSERT_EQ(part.color.at(x, y, c), in ? full.color.at(x, y, c) : s.clear_color[c])
                        << samples << " spp, " << x << "," << y << " c" << c;
                if (samples > 1) {
                    ASSERT_EQ(part.error_map.at(x, y, 0), in ? full.error_map.at(x, y, 0) : 0.0f) << x << "," << y;
                    edge += in && full.error_map.at(x, y, 0) > 0;
                }
            }
        if (samples > 1) {
            EXPECT_GT(edge, 0) << "some listed pixel lies on an edge";
        }
        EXPECT_LT(part.stats.samples_covered, full.stats.samples_covered);
    }
}

TEST(ListedPixels, BadInputIsNamed) {
    const mr::Mesh m = slanted_triangle();
    mr::RenderSettings s = settings(10, 10, 4);
    const std::vector<mr::Draw> draws = {make_draw(m, glm::dmat4(1.0), no_depth())};
    auto message = [&]() -> std::string {
        try {
            mr::render(draws, identity_camera(), s);
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "no exception";
    };
    s.pixels = {3, 100};
    EXPECT_NE(message().find("pixels[1] = 100 is outside the 10x10 image"), std::string::npos) << message();
    s.pixels = {3};
    s.tile_mask = {1};
    EXPECT_NE(message().find("not both"), std::string::npos) << message();
    s.tile_mask.clear();
    s.resolve_filter = mr::ResolveFilter::tent;
    EXPECT_NE(message().find("needs the box resolve"), std::string::npos) << message();
}

}  // namespace
