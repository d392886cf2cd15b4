// Block skipping (raster kernel, tile_blocks.hpp): leaving out the 8×8 blocks a triangle does not
// cover and the depth tests of the blocks it cannot win in changes nothing — colour, depth and
// sample counters are bit for bit those of the plain per-sample path for every depth convention,
// blend, sample mode and thread count — and it does skip blocks where a surface in front hides the rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "helpers.hpp"
#include "mipraster/pipeline/interpolate.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"
#include "pipeline/tile_blocks.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

/// `n` large random triangles in the box [−1.5, 1.5]×[−1, 1]×[−2, 6] (the cameras below look from
/// z = 4, so some cross the near plane), tilted so their depth varies across them, in random depth
/// order, with premultiplied vertex colours.
mr::Mesh random_overlap(std::size_t n, double size, std::uint64_t seed) {
    return random_triangles(n, size, seed, {-1.5, -1.0, -2.0}, {3.0, 2.0, 8.0}, 0.5);
}

// A row's pixels in given blocks, and a row trimmed of skipped blocks at its ends, against the
// blocks pixel by pixel: tile targets of every size and one-row spans starting anywhere in a tile
// (whose first block is partial), random block sets and random runs of each row.
TEST(BlockSkipping, RowMasksAndTrimsFollowTheBlocksPixelByPixel) {
    std::mt19937_64 rng(49);
    const mr::SamplePattern pattern = mr::make_sample_pattern(mr::PatternKind::center, 1);
    const auto random_int = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    for (int round = 0; round < 4000; ++round) {
        mr::TileTarget target{};
        target.pattern = &pattern;
        const int tile_x = mr::kTileSize * random_int(0, 5), tile_y = mr::kTileSize * random_int(0, 5);
        if (round % 2 == 0) {  // a tile, maybe partial
            target.x0 = tile_x, target.y0 = tile_y;
            target.x1 = tile_x + random_int(1, mr::kTileSize), target.y1 = tile_y + random_int(1, mr::kTileSize);
        } else {  // a span of one row
            target.x0 = tile_x + random_int(0, mr::kTileSize - 1);
            target.x1 = random_int(target.x0 + 1, tile_x + mr::kTileSize);
            target.y0 = tile_y + random_int(0, mr::kTileSize - 1), target.y1 = target.y0 + 1;
        }
        const mr::kernels::TileBlocks blocks(target, 1);
        const auto block_of = [&](int x, int y) {  // bit of the block holding pixel (x, y)
            return ((y >> 3) - (target.y0 >> 3)) * (mr::kTileSize / 8) + (x >> 3) - (target.x0 >> 3);
        };
        const auto bits = static_cast<std::uint32_t>(rng());
        for (int y = target.y0; y < target.y1; ++y) {
            const int x0 = random_int(target.x0, target.x1 - 1), x1 = random_int(x0 + 1, target.x1);
            std::uint32_t expected = 0;
            int first = x1, last = x0 - 1;  // pixels of [x0, x1) outside the blocks of `bits`
            for (int x = x0; x < x1; ++x) {
                const bool in = bits >> block_of(x, y) & 1;
                expected |= static_cast<std::uint32_t>(in) << (x - x0);
                if (!in) first = std::min(first, x), last = std::max(last, x);
            }
            ASSERT_EQ(blocks.row_pixels(bits, y, x0, x1 - x0), expected) << "row " << y << " from " << x0;
            int trimmed0 = x0, trimmed1 = x1;
            blocks.trim(bits, y, trimmed0, trimmed1);
            if (first > last) {
                EXPECT_GE(trimmed0, trimmed1) << "row " << y << " from " << x0 << " to " << x1;
            } else {
                EXPECT_EQ(trimmed0, first) << "row " << y << " from " << x0 << " to " << x1;
                EXPECT_EQ(trimmed1, last + 1) << "row " << y << " from " << x0 << " to " << x1;
            }
        }
    }
}

// The bits of the blocks holding pixels of a rectangle, against the blocks pixel by pixel.
TEST(BlockSkipping, BlocksInARectangleAreTheBlocksOfItsPixels) {
    std::mt19937_64 rng(50);
    const mr::SamplePattern pattern = mr::make_sample_pattern(mr::PatternKind::center, 1);
    const auto random_int = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    for (int round = 0; round < 4000; ++round) {
        mr::TileTarget target{};
        target.pattern = &pattern;
        target.x0 = mr::kTileSize * random_int(0, 5), target.y0 = mr::kTileSize * random_int(0, 5);
        target.x1 = target.x0 + random_int(1, mr::kTileSize), target.y1 = target.y0 + random_int(1, mr::kTileSize);
        const mr::kernels::TileBlocks blocks(target, 1);
        const int x0 = random_int(target.x0, target.x1 - 1), x1 = random_int(x0 + 1, target.x1);
        const int y0 = random_int(target.y0, target.y1 - 1), y1 = random_int(y0 + 1, target.y1);
        std::uint32_t expected = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) expected |= std::uint32_t{1} << blocks.bit(x, y);
        ASSERT_EQ(blocks.blocks_in(x0, y0, x1, y1), expected) << x0 << "…" << x1 << " × " << y0 << "…" << y1;
    }
}

// What TileBlocks::classify says of each block, against the blocks one by one: block_coverage and
// nearest_depth over the block's samples (whole tiles: first over the tile's, all blocks at once), the
// stored depths scanned; and against every sample: no covered sample in a block found to have none, no
// uncovered one where all are, none that would pass in a block rejected by depth. Triangles from a
// pixel to far beyond the tile, tilted in depth, one after another on a depth buffer that moves nearer
// in random blocks between them (the bounds TileBlocks keeps from earlier triangles must follow), 1
// and 4 samples, partial tiles.
TEST(BlockSkipping, ClassesAreEachBlocksCoverageAndDepthBound) {
    namespace k = mr::kernels;
    std::mt19937_64 rng(51);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int N = 80;  // tiles of 32, 32 and 16 pixels a side
    int rejected = 0, hidden = 0, whole_skipped = 0, compared = 0;
    for (int S : {1, 4}) {
        const mr::SamplePattern pattern =
            mr::make_sample_pattern(S == 1 ? mr::PatternKind::center : mr::PatternKind::rotated, S);
        std::vector<float> depth(static_cast<std::size_t>(N) * N * S);
        for (int round = 0; round < 400; ++round) {
            mr::TileTarget target{};
            target.pattern = &pattern;
            target.depth = mr::SampleWindow{depth.data(), 1, 0, 0, N, S};
            target.x0 = mr::kTileSize * static_cast<int>(3 * unit(rng));
            target.y0 = mr::kTileSize * static_cast<int>(3 * unit(rng));
            target.x1 = std::min(N, target.x0 + mr::kTileSize), target.y1 = std::min(N, target.y0 + mr::kTileSize);
            for (float& d : depth) d = static_cast<float>(0.2 + 0.6 * unit(rng));  // (reverse-Z: greater wins)
            k::TileBlocks blocks(target, S);
            for (int step = 0; step < 40; ++step) {
                const double size = std::array<double, 4>{3.0, 20.0, 120.0, 2000.0}[step % 4];
                std::array<glm::dvec4, 3> p;
                const glm::dvec2 c(N * unit(rng), N * unit(rng));
                for (glm::dvec4& v : p) {
                    const glm::dvec2 s = c + size * glm::dvec2(unit(rng) - 0.5, unit(rng) - 0.5);
                    v = glm::dvec4(2.0 * s.x / N - 1.0, 1.0 - 2.0 * s.y / N, 0.1 + 0.8 * unit(rng), 1.0);
                }
                mr::Viewport vp;
                vp.width = vp.height = N;
                mr::SetupTriangle t;
                mr::SetupCounters counters;
                if (!mr::setup_triangle(p, vp, mr::CullMode::none, t, counters)) continue;
                const int x0 = std::max(t.min_x, target.x0), x1 = std::min(t.max_x + 1, target.x1);
                const int y0 = std::max(t.min_y, target.y0), y1 = std::min(t.max_y + 1, target.y1);
                if (x0 >= x1 || y0 >= y1) continue;
                const k::BlockClasses got = blocks.classify<mr::DepthFunc::greater>(t, x0, y0, x1, y1, S);

                // Per block: samples covered, all covered, the farthest stored depth, the bound.
                const auto edges = [&](int x, int y, int s, std::int64_t (&e)[3]) {
                    const std::int64_t X = x * mr::kSubpixelOne + pattern.x[s], Y = y * mr::kSubpixelOne + pattern.y[s];
                    for (int i = 0; i < 3; ++i) e[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
                };
                const auto extent = [&](int bx0, int by0, int bx1, int by1) {
                    const auto [ox0, ox1] = std::minmax_element(pattern.x.begin(), pattern.x.begin() + S);
                    const auto [oy0, oy1] = std::minmax_element(pattern.y.begin(), pattern.y.begin() + S);
                    return k::SampleExtent{bx0 * mr::kSubpixelOne + *ox0, by0 * mr::kSubpixelOne + *oy0,
                                           (bx1 - 1) * mr::kSubpixelOne + *ox1, (by1 - 1) * mr::kSubpixelOne + *oy1};
                };
                struct Block {
                    int x0, y0, x1, y1;
                    long covered = 0, samples = 0;
                    float farthest = std::numeric_limits<float>::infinity();
                    bool loses = true;  // every covered sample fails the depth test
                };
                std::vector<Block> in_box;
                std::uint32_t box_bits = 0;
                for (int by = target.y0; by < target.y1; by += k::kBlock)
                    for (int bx = target.x0; bx < target.x1; bx += k::kBlock) {
                        Block b{std::max(bx, x0), std::max(by, y0), std::min(bx + k::kBlock, x1),
                                std::min(by + k::kBlock, y1)};
                        if (b.x0 >= b.x1 || b.y0 >= b.y1) continue;
                        box_bits |= std::uint32_t{1} << blocks.bit(bx, by);
                        for (int y = by; y < std::min(by + k::kBlock, target.y1); ++y)  // the whole block's depths
                            for (int x = bx; x < std::min(bx + k::kBlock, target.x1); ++x)
                                for (int s = 0; s < S; ++s)
                                    b.farthest = std::min(b.farthest, *target.depth.at(x, y, s));
                        for (int y = b.y0; y < b.y1; ++y)
                            for (int x = b.x0; x < b.x1; ++x)
                                for (int s = 0; s < S; ++s) {
                                    std::int64_t e[3];
                                    edges(x, y, s, e);
                                    ++b.samples;
                                    if ((e[0] | e[1] | e[2]) < 0) continue;
                                    ++b.covered;
                                    const float z = mr::sample_depth(t, mr::screen_weights(t, e[0], e[1], e[2]));
                                    if (z > *target.depth.at(x, y, s)) b.loses = false;
                                }
                        in_box.push_back(b);
                    }
                // block_coverage over an extent's corners, which must agree with the samples.
                const auto coverage = [&](const Block& b) {
                    const k::BlockCoverage c = k::block_coverage(t, extent(b.x0, b.y0, b.x1, b.y1));
                    if (c == k::BlockCoverage::none) {
                        EXPECT_EQ(b.covered, 0);
                    } else if (c == k::BlockCoverage::all) {
                        EXPECT_EQ(b.covered, b.samples);
                    }
                    return c;
                };
                k::BlockClasses expected;
                const bool whole = x0 == target.x0 && y0 == target.y0 && x1 == target.x1 && y1 == target.y1;
                Block all{x0, y0, x1, y1};
                for (const Block& b : in_box) {
                    all.covered += b.covered, all.samples += b.samples;
                    all.farthest = std::min(all.farthest, b.farthest);
                }
                const k::BlockCoverage target_coverage = whole ? coverage(all) : k::BlockCoverage::some;
                const float target_bound = k::nearest_depth<mr::DepthFunc::greater>(t, extent(x0, y0, x1, y1));
                const bool whole_done = target_coverage == k::BlockCoverage::none ||
                                        (target_coverage == k::BlockCoverage::all && target_bound <= all.farthest);
                if (whole_done) {
                    expected.skipped = box_bits;
                    if (target_coverage == k::BlockCoverage::all) {
                        expected.skipped_samples = static_cast<std::uint64_t>(all.samples);
                        expected.depth_rejected = static_cast<int>(in_box.size());
                    }
                    ++whole_skipped;
                } else {
                    for (const Block& b : in_box) {
                        if ((b.x1 - b.x0) * (b.y1 - b.y0) < k::kBlockMinPixels) continue;
                        const std::uint32_t m = std::uint32_t{1} << blocks.bit(b.x0, b.y0);
                        const k::BlockCoverage c = coverage(b);
                        if (c == k::BlockCoverage::none) {
                            expected.skipped |= m;
                            continue;
                        }
                        const float bound = k::nearest_depth<mr::DepthFunc::greater>(t, extent(b.x0, b.y0, b.x1, b.y1));
                        if (!(bound <= b.farthest)) continue;
                        ++expected.depth_rejected;
                        if (c == k::BlockCoverage::some) {
                            expected.hidden |= m;
                        } else {
                            expected.skipped |= m;
                            expected.skipped_samples += static_cast<std::uint64_t>(b.samples);
                        }
                    }
                }
                ++compared;
                ASSERT_EQ(got.skipped, expected.skipped) << "S " << S << ", round " << round << ", step " << step;
                ASSERT_EQ(got.hidden, expected.hidden) << "S " << S << ", round " << round << ", step " << step;
                ASSERT_EQ(got.skipped_samples, expected.skipped_samples) << "S " << S << ", round " << round;
                ASSERT_EQ(got.depth_rejected, expected.depth_rejected) << "S " << S << ", round " << round;
                for (const Block& b : in_box) {  // rejected by depth: nothing there could win
                    const std::uint32_t m = std::uint32_t{1} << blocks.bit(b.x0, b.y0);
                    if ((got.hidden & m) || ((got.skipped & m) && b.covered)) {
                        ASSERT_TRUE(b.loses);
                    }
                }
                rejected += got.depth_rejected;
                hidden += __builtin_popcount(got.hidden);

                // Nearer depths in some blocks of the tile, as a triangle's writes would leave them.
                for (int y = target.y0; y < target.y1; ++y)
                    for (int x = target.x0; x < target.x1; ++x) {
                        if ((blocks.bit(x, y) * 7 + step) % 5 != 0) continue;
                        for (int s = 0; s < S; ++s) {
                            float& d = *target.depth.at(x, y, s);
                            d = std::max(d, static_cast<float>(unit(rng)));
                        }
                        blocks.written(x, y);
                    }
            }
        }
    }
    // The cases the classes come from all occur.
    EXPECT_GT(compared, 10000);
    EXPECT_GT(rejected, 1000);
    EXPECT_GT(hidden, 100);
    EXPECT_GT(whole_skipped, 300);
}

TEST(BlockSkipping, SameBitsAndCountersAsThePlainPathOnRandomOverlappingScenes) {
    const int W = 96, H = 80;  // partial tiles at the right and bottom
    const mr::Mesh a = random_overlap(160, 2.5, 11), b = random_overlap(120, 1.2, 12);
    glm::dmat4 shifted(1.0);
    shifted[3] = glm::dvec4(0.2, 0.1, 0.5, 1.0);
    struct Mode {
        mr::AntiAliasing aa;
        int samples;
    };
    const Mode modes[] = {{mr::AntiAliasing::ssaa, 1}, {mr::AntiAliasing::ssaa, 4}, {mr::AntiAliasing::msaa, 4},
                          {mr::AntiAliasing::msaa, 16}};
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        for (mr::BlendMode blend : {mr::BlendMode::replace, mr::BlendMode::add, mr::BlendMode::over}) {
            // A depth-tested draw, then one that tests without writing, then one that does not test.
            mr::DrawState tested;
            tested.blend = blend;
            mr::DrawState read_only = tested;
            read_only.depth_write = false;
            read_only.interpolation = mr::Interpolation::screen;
            const std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), tested),
                                                 make_draw(b, glm::dmat4(1.0), read_only, glm::vec4(0.9f, 0.8f, 1.0f, 1.0f)),
                                                 make_draw(b, shifted,
                                                           no_depth(blend), glm::vec4(0.3f))};
            for (const Mode& mode : modes)
                for (int threads : {1, 2}) {
                    SCOPED_TRACE(mr::to_string(convention) + ", " + mr::to_string(blend) + ", " +
                                 mr::to_string(mode.aa) + " " + std::to_string(mode.samples) + ", " +
                                 std::to_string(threads) + " threads");
                    auto s = settings(W, H, mode.samples);
                    s.anti_aliasing = mode.aa;
                    s.threads = threads;
                    s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                    const auto [plain, fast] = render_off_on(draws, cam, s, &mr::RenderSettings::block_skipping);
                    EXPECT_EQ(plain.stats.depth_blocks_rejected, 0u);
                    EXPECT_GT(fast.stats.depth_blocks_rejected, 0u);
                    expect_same_render(fast, plain);
                }
        }
    }
}

TEST(BlockSkipping, TileBuffersAndListedPixelsGiveThePlainImage) {
    const int W = 70, H = 50;
    const mr::Mesh a = random_overlap(200, 2.5, 21);
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    const std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), mr::DrawState{})};
    std::vector<std::uint32_t> pixels;
    for (std::uint32_t i = 0; i < std::uint32_t(W * H); i += 3) pixels.push_back(i);
    for (int samples : {1, 4})
        for (bool listed : {false, true}) {
            SCOPED_TRACE(std::to_string(samples) + " samples" + (listed ? ", listed pixels" : ""));
            auto s = settings(W, H, samples);
            s.keep_samples = false;
            if (listed) s.pixels = pixels;
            s.block_skipping = false;
            const mr::RenderResult plain = mr::render(draws, cam, s);
            s.block_skipping = true;
            const mr::RenderResult fast = mr::render(draws, cam, s);
            // Spans of single pixels are too thin for a block test; whole tiles are not.
            if (!listed) {
                EXPECT_GT(fast.stats.depth_blocks_rejected, 0u);
            }
            EXPECT_TRUE(same_bits(fast.color.pixels, plain.color.pixels));
            EXPECT_EQ(fast.stats.samples_covered, plain.stats.samples_covered);
            EXPECT_EQ(fast.stats.samples_passed, plain.stats.samples_passed);
        }
}

TEST(BlockSkipping, ATriangleOverAWholeTileIsTestedAgainstEveryBlockOfIt) {
    // Small occluders scattered over the tiles, then triangles far larger than the screen at
    // random depths: each of those covers whole tiles, nearer than the stored depth in some of a
    // tile's blocks and farther in others, so the whole-tile test must take every block's bound.
    const int W = 96, H = 64;
    for (std::uint64_t seed : {31, 32, 33})
        for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl})
            for (int samples : {1, 4}) {
                SCOPED_TRACE("seed " + std::to_string(seed) + ", " + mr::to_string(convention) + ", " +
                             std::to_string(samples) + " samples");
                const mr::Mesh occluders = random_triangles(120, 0.25, seed, {-1.5, -1.0, -1.0}, {3.0, 2.0, 4.0});
                const mr::Mesh walls = random_triangles(40, 60.0, seed + 100, {-0.5, -0.5, -1.5}, {1.0, 1.0, 5.0}, 0.01);
                const std::vector<mr::Draw> draws = {make_draw(occluders, glm::dmat4(1.0), {}),
                                                     make_draw(walls, glm::dmat4(1.0), {})};
                const mr::Camera cam = overlap_camera(convention, W, H);
                const auto [plain, fast] =
                    render_off_on(draws, cam, settings(W, H, samples), &mr::RenderSettings::block_skipping);
                EXPECT_GT(fast.stats.depth_blocks_rejected, 0u);
                expect_same_render(fast, plain);
            }
}

// A block is classified where a triangle's bounding box holds at least kBlockMinPixels of its
// pixels; a smaller box is not classified at all (small triangles skip the call). Behind a
// full-screen occluder, block (w − 1, h − 1) holds one triangle whose box is w × h pixels: the
// blocks rejected by depth are exactly those with w·h ≥ 16.
TEST(BlockSkipping, BoundingBoxesFromSixteenPixelsAreClassified) {
    const int W = 64, H = 64;
    mr::Mesh front, behind;
    for (glm::vec3 p : {glm::vec3(0, 0, -0.5f), glm::vec3(W * 256, 0, -0.5f), glm::vec3(W * 256, H * 256, -0.5f),
                        glm::vec3(0, H * 256, -0.5f)})
        front.positions.push_back(p);
    add_triangle(front, 0, 1, 2);
    add_triangle(front, 0, 2, 3);
    int expected = 0;
    for (int w = 1; w <= 8; ++w)
        for (int h = 1; h <= 8; ++h) {
            // Pixels x0 … x0 + w − 1 and y0 … y0 + h − 1: vertices a quarter pixel in from the box.
            const float x0 = (w - 1) * 8 * 256.0f, y0 = (h - 1) * 8 * 256.0f;
            const auto first = static_cast<std::uint32_t>(behind.positions.size());
            behind.positions.push_back({x0 + 64, y0 + 64, 0.5f});
            behind.positions.push_back({x0 + (w - 1) * 256 + 192, y0 + 64, 0.5f});
            behind.positions.push_back({x0 + 64, y0 + (h - 1) * 256 + 192, 0.5f});
            add_triangle(behind, first, first + 1, first + 2);
            expected += w * h >= 16;  // (kBlockMinPixels, tile_blocks.hpp)
        }
    auto s = settings(W, H, 1);
    const glm::dmat4 model = fixed_to_ndc(W, H);
    const mr::RenderResult r =
        mr::render({make_draw(front, model, {}), make_draw(behind, model, {})}, identity_camera(), s);
    EXPECT_EQ(r.stats.depth_blocks_rejected, std::uint64_t(expected));
    EXPECT_EQ(r.stats.samples_passed, std::uint64_t(W) * H);  // the occluder's own
    EXPECT_EQ(r.stats.triangles_rasterized, 2u + 64u);
}

TEST(BlockSkipping, AlphaTestedDrawsSkipBlocksWithThePlainPathsBitsAndCounters) {
    // Alpha-tested draws (vertex alphas in [0.2, 1] against a cutoff of 0.6; one also textured)
    // drawn after an opaque one: their blocks are classified as other draws' are, so those hidden
    // behind what is drawn are rejected, and colour, depth and counters are the plain path's, with
    // their depth written or only read.
    const int W = 96, H = 80;
    const mr::Mesh a = random_overlap(160, 2.5, 13), b = random_overlap(120, 1.2, 14);
    mr::Mesh textured = random_overlap(120, 1.2, 15);
    for (const glm::vec3& p : textured.positions) textured.uvs.push_back(glm::vec2(1.7f * p.x, 2.3f * p.y));
    const struct {
        mr::AntiAliasing aa;
        int samples;
    } modes[] = {{mr::AntiAliasing::ssaa, 1}, {mr::AntiAliasing::ssaa, 4}, {mr::AntiAliasing::msaa, 4},
                 {mr::AntiAliasing::msaa, 6}};
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        for (bool depth_write : {true, false}) {
            const mr::DrawState masked = alpha_tested(0.6f, depth_write);
            std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), {}), make_draw(b, glm::dmat4(1.0), masked),
                                           make_draw(textured, glm::dmat4(1.0), masked)};
            draws[2].texture = checker_texture();
            for (const auto& mode : modes)
                for (int threads : {1, 2}) {
                    SCOPED_TRACE(mr::to_string(convention) + (depth_write ? ", depth written, " : ", depth read, ") +
                                 mr::to_string(mode.aa) + " " + std::to_string(mode.samples) + ", " +
                                 std::to_string(threads) + " threads");
                    auto s = settings(W, H, mode.samples);
                    s.anti_aliasing = mode.aa;
                    s.threads = threads;
                    const auto [plain, fast] = render_off_on(draws, cam, s, &mr::RenderSettings::block_skipping);
                    expect_same_render(fast, plain);
                    EXPECT_EQ(plain.stats.depth_blocks_rejected, 0u);
                    const mr::RenderResult opaque = mr::render({draws[0]}, cam, s);
                    EXPECT_GT(fast.stats.depth_blocks_rejected, opaque.stats.depth_blocks_rejected + 10);
                }
        }
    }
}

TEST(BlockSkipping, AnOccluderDrawnFirstHidesEveryBlockBehindIt) {
    // A full-screen quad at z = 1, then 50 triangles behind it at z = −1 that cover the screen:
    // each of them fails everywhere, so every block they fill is skipped and no sample passes.
    const int W = 64, H = 64;
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    mr::Mesh front, behind;
    for (glm::vec3 p : {glm::vec3(-9, -9, 1), glm::vec3(9, -9, 1), glm::vec3(9, 9, 1), glm::vec3(-9, 9, 1)}) {
        front.positions.push_back(p);
    }
    add_triangle(front, 0, 1, 2);
    add_triangle(front, 0, 2, 3);
    for (std::uint32_t t = 0; t < 50; ++t) {  // each nearer than the one before
        const float z = -1.5f + 0.01f * float(t);
        behind.positions.push_back({-20.0f, -20.0f, z});
        behind.positions.push_back({20.0f, -20.0f, z - 0.5f});
        behind.positions.push_back({0.0f, 20.0f, z});
        add_triangle(behind, 3 * t, 3 * t + 1, 3 * t + 2);
    }
    auto s = settings(W, H, 4);
    const mr::RenderResult r = mr::render({make_draw(front, glm::dmat4(1.0), {}), make_draw(behind, glm::dmat4(1.0), {})}, cam, s);
    const std::uint64_t samples = std::uint64_t(W) * H * 4;
    EXPECT_EQ(r.stats.samples_covered, 51 * samples);  // counted even where skipped
    EXPECT_EQ(r.stats.samples_passed, samples);         // the occluder's own
    EXPECT_EQ(r.stats.depth_blocks_rejected, 50u * (W / 8) * (H / 8));
    // Drawn the other way round, each nearer surface passes: nothing may be skipped.
    const mr::RenderResult back_to_front =
        mr::render({make_draw(behind, glm::dmat4(1.0), {}), make_draw(front, glm::dmat4(1.0), {})}, cam, s);
    EXPECT_EQ(back_to_front.stats.depth_blocks_rejected, 0u);
    EXPECT_TRUE(same_bits(back_to_front.color.pixels, r.color.pixels));
}

// A tile no triangle reaches is written from the clear values alone (no tile buffers): the same
// bits as the plain path's clear and resolve, depth output included, for every sample mode. The
// clear colour has a −0 (the resolve of several samples makes it +0) and a subnormal.
TEST(BlockSkipping, EmptyTilesGiveThePlainPathsClearAndResolve) {
    const int W = 100, H = 70;  // 4 × 3 tiles, partial at the right and bottom
    mr::Mesh corner = random_overlap(40, 0.6, 31);
    for (glm::vec3& p : corner.positions) p = 0.3f * p + glm::vec3(-1.0f, 0.5f, 0.0f);  // the top left only
    struct Mode {
        mr::AntiAliasing aa;
        int samples;
    };
    const Mode modes[] = {{mr::AntiAliasing::ssaa, 1}, {mr::AntiAliasing::ssaa, 4}, {mr::AntiAliasing::msaa, 4},
                          {mr::AntiAliasing::ssaa, 3}, {mr::AntiAliasing::msaa, 8}};
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        const std::vector<mr::Draw> draws = {make_draw(corner, glm::dmat4(1.0), mr::DrawState{})};
        for (const Mode& mode : modes)
            for (int threads : {1, 2}) {
                SCOPED_TRACE(mr::to_string(convention) + ", " + mr::to_string(mode.aa) + " " +
                             std::to_string(mode.samples) + ", " + std::to_string(threads) + " threads");
                auto s = settings(W, H, mode.samples);
                s.anti_aliasing = mode.aa;
                s.threads = threads;
                s.keep_samples = false;
                s.depth_output = true;
                s.clear_color = glm::vec4(-0.0f, 0.3f, 1e-40f, 1.0f);
                std::atomic<std::size_t> reports{0}, last{0};
                s.progress = [&](std::size_t done, std::size_t) {
                    ++reports;
                    last = std::max(last.load(), done);
                };
                const auto [plain, fast] = render_off_on(draws, cam, s, &mr::RenderSettings::block_skipping);
                EXPECT_EQ(plain.stats.tiles_empty, 0u);
                EXPECT_GT(fast.stats.tiles_empty, 0u);
                EXPECT_LT(fast.stats.tiles_empty, 12u);
                expect_same_render(fast, plain);
                EXPECT_TRUE(same_bits(fast.depth.pixels, plain.depth.pixels)) << "depth output differs";
                EXPECT_EQ(reports.load(), 2u * 12u);  // every tile reported, in both renders
                EXPECT_EQ(last.load(), 12u);
            }
    }
}

}  // namespace
