// Resolve and anti-aliasing modes (DESIGN.md §2.7, §3): a half-covered edge pixel resolves to
// linear 0.5 and sRGB8 188; the box filter is the mean of a pixel's samples; MSAA shades once per
// pixel per triangle and stores that colour to every covered sample while SSAA shades every
// sample; sample counts 1…64 are accepted and 0 / 65 are not.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "helpers.hpp"
#include "mipraster/core/colour.hpp"
#include "mipraster/core/thread_pool.hpp"
#include "mipraster/pipeline/resolve.hpp"
#include "mipraster/pipeline/sample_pattern.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;
using oracle::Fixed2;

mr::Mesh fixed_triangle(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    mr::Mesh m;
    for (const auto& p : {a, b, c}) m.positions.push_back(glm::vec3(static_cast<float>(p.x), static_cast<float>(p.y), 0.0f));
    add_triangle(m, 0, 1, 2);
    return m;
}

TEST(Resolve, EdgePixelWithTwoOfFourRotatedSamplesWhiteOverBlackIsLinearHalfAndSrgb188) {
    // A rectangle from x = 0 to x = 2.5 px over every row. In pixel column 2 the rotated pattern's
    // samples at x offsets 96/256 and 32/256 are left of 0.5 px, those at 224 and 160 right of it.
    const int W = 4, H = 4;
    mr::Mesh rect;
    rect.positions = {{0, -256, 0}, {640, -256, 0}, {640, 5 * 256, 0}, {0, 5 * 256, 0}};
    add_triangle(rect, 0, 1, 2);
    add_triangle(rect, 0, 2, 3);
    for (mr::BlendMode blend : {mr::BlendMode::replace, mr::BlendMode::over}) {
        for (mr::AntiAliasing aa : {mr::AntiAliasing::ssaa, mr::AntiAliasing::msaa}) {
            SCOPED_TRACE(mr::to_string(blend) + ", " + mr::to_string(aa));
            auto s = settings(W, H, 4, mr::PatternKind::rotated);
            s.anti_aliasing = aa;
            s.clear_color = glm::vec4(0, 0, 0, 1);  // opaque black
            const mr::RenderResult r = mr::render({make_draw(rect, fixed_to_ndc(W, H), no_depth(blend), glm::vec4(1.0f))},
                                                  identity_camera(), s);
            ASSERT_TRUE(same_offsets(to_oracle(r.pattern), oracle::rotated_pattern()));
            const std::vector<std::uint8_t> srgb = mr::to_srgb8(r.color);
            const float expect_linear[4] = {1.0f, 1.0f, 0.5f, 0.0f};
            const int expect_srgb[4] = {255, 255, 188, 0};
            for (int y = 0; y < H; ++y)
                for (int x = 0; x < W; ++x) {
                    for (int c = 0; c < 3; ++c) {
                        EXPECT_EQ(r.color.at(x, y, c), expect_linear[x]) << "pixel (" << x << ", " << y << ")";
                        EXPECT_EQ(srgb[(y * W + x) * 4 + c], expect_srgb[x]) << "pixel (" << x << ", " << y << ")";
                    }
                    EXPECT_EQ(r.color.at(x, y, 3), 1.0f);
                    EXPECT_EQ(srgb[(y * W + x) * 4 + 3], 255);
                }
        }
    }
}

/// Recursive float summation error bound for the mean of n values: (n−1)·u·Σ|x|/n + u·|mean|.
double mean_tolerance(const std::vector<double>& xs) {
    const double u = std::ldexp(1.0, -24);
    double abs_sum = 0, sum = 0;
    for (double x : xs) {
        abs_sum += std::fabs(x);
        sum += x;
    }
    const double n = static_cast<double>(xs.size());
    return 1.01 * ((n - 1) * u * abs_sum / n + u * std::fabs(sum / n)) + 1e-30;
}

TEST(Resolve, BoxResolveIsTheMeanOfEachPixelsSamplesForRandomData) {
    std::mt19937_64 rng(6);
    std::uniform_real_distribution<float> u(-1.0f, 2.0f);  // nothing clamps: out-of-range values too
    for (int S : {1, 2, 3, 4, 8, 9, 16, 25, 32, 64}) {
        mr::Framebuffer fb;
        fb.width = 13;
        fb.height = 7;
        fb.samples = S;
        fb.color.resize(static_cast<std::size_t>(fb.width) * fb.height * S * 4);
        for (float& v : fb.color) v = u(rng);
        mr::Image img(fb.width, fb.height, 4);
        mr::resolve_tile(mr::color_window(fb), 0, 0, fb.width, fb.height, mr::ResolveFilter::box, img);
        ASSERT_EQ(img.width, fb.width);
        ASSERT_EQ(img.height, fb.height);
        ASSERT_EQ(img.channels, 4);
        for (int y = 0; y < fb.height; ++y)
            for (int x = 0; x < fb.width; ++x)
                for (int c = 0; c < 4; ++c) {
                    std::vector<double> xs;
                    for (int s = 0; s < S; ++s) xs.push_back(fb.color[4 * fb.sample_index(x, y, s) + c]);
                    double mean = 0;
                    for (double v : xs) mean += v;
                    mean /= S;
                    EXPECT_NEAR(img.at(x, y, c), mean, mean_tolerance(xs)) << "S=" << S << " pixel (" << x << ", " << y << ")";
                    // Exactly: the double sum in sample order, divided by S, rounded to float once
                    // (a power-of-two S multiplies by its reciprocal instead: the same bits).
                    EXPECT_EQ(img.at(x, y, c), static_cast<float>(mean)) << "S=" << S << " pixel (" << x << ", " << y << ")";
                }
        // A tile-local window (origin (5, 2), its own pitch) over a copy of a sub-rectangle gives
        // the same pixels there, and writes nothing outside it.
        const int x0 = 5, y0 = 2, x1 = 11, y1 = 6, pitch = 8;
        std::vector<float> local(static_cast<std::size_t>(pitch) * (y1 - y0) * S * 4, -7.0f);
        const mr::SampleWindow window{local.data(), 4, x0, y0, pitch, S};
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x)
                for (int s = 0; s < S; ++s)
                    for (int c = 0; c < 4; ++c) window.at(x, y, s)[c] = fb.color[4 * fb.sample_index(x, y, s) + c];
        mr::Image tile(fb.width, fb.height, 4);
        mr::resolve_tile(window, x0, y0, x1, y1, mr::ResolveFilter::box, tile);
        for (int y = 0; y < fb.height; ++y)
            for (int x = 0; x < fb.width; ++x)
                for (int c = 0; c < 4; ++c) {
                    const bool inside = x >= x0 && x < x1 && y >= y0 && y < y1;
                    EXPECT_EQ(tile.at(x, y, c), inside ? img.at(x, y, c) : 0.0f) << "S=" << S << " (" << x << ", " << y << ")";
                }
    }
}

// One sample per pixel resolves by copying (the renderer's 1x path): every bit arrives, signed
// zeros, infinities, subnormals and NaN payloads included, in a window with its own pitch.
TEST(Resolve, OneSampleResolveCopiesEveryBit) {
    const std::uint32_t patterns[] = {0x80000000u, 0x7f800000u, 0xff800000u, 0x00000001u, 0x7fc12345u,
                                      0xffa00001u, 0x3f800000u, 0xc0490fdbu};
    const int x0 = 3, y0 = 1, x1 = 9, y1 = 4, pitch = 7;
    std::vector<float> local(static_cast<std::size_t>(pitch) * (y1 - y0) * 4);
    for (std::size_t i = 0; i < local.size(); ++i) std::memcpy(&local[i], &patterns[(i * 5 + i / 3) % 8], 4);
    const mr::SampleWindow window{local.data(), 4, x0, y0, pitch, 1};
    mr::Image out(x1 + 2, y1 + 1, 4);
    mr::resolve_tile(window, x0, y0, x1, y1, mr::ResolveFilter::box, out);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int c = 0; c < 4; ++c) {
                const bool inside = x >= x0 && x < x1 && y >= y0 && y < y1;
                std::uint32_t got, want = 0;
                std::memcpy(&got, &out.at(x, y, c), 4);
                if (inside) std::memcpy(&want, &window.at(x, y, 0)[c], 4);
                EXPECT_EQ(got, want) << "(" << x << ", " << y << ") channel " << c;
            }
}

// resolve_undrawn is fill_undrawn followed by resolve_tile's box, in one pass: the same bits for
// every pixel (random colours, random depths of which a random share is the clear depth; pixels
// with no, some and all samples undrawn; a window with its own origin and pitch), nothing written
// outside the rectangle, and the samples themselves left as they were. The clear colour holds a
// −0 and a subnormal, which the mean keeps.
TEST(Resolve, ResolvingOverUndrawnSamplesIsTheFillThenTheResolve) {
    std::mt19937_64 rng(46);
    std::uniform_real_distribution<float> u(-1.0f, 2.0f);
    const glm::vec4 clear(0.25f, -0.0f, 1e-40f, 1.0f);
    const float clear_depth = 1.0f;
    const int x0 = 5, y0 = 2, x1 = 16, y1 = 9, pitch = 13, W = 19, H = 11;
    for (int S : {1, 2, 3, 4, 8, 9, 16, 64}) {
        for (double undrawn_share : {0.0, 0.3, 0.9, 1.0}) {
            SCOPED_TRACE("S=" + std::to_string(S) + ", undrawn share " + std::to_string(undrawn_share));
            std::bernoulli_distribution undrawn(undrawn_share);
            const std::size_t count = static_cast<std::size_t>(pitch) * (y1 - y0) * S;
            std::vector<float> colour(4 * count), depth(count);
            for (float& v : colour) v = u(rng);
            for (std::size_t i = 0; i < count; ++i) {
                // Whole pixels undrawn or drawn as well as single samples.
                const std::size_t pixel = i / static_cast<std::size_t>(S);
                const bool whole = pixel % 3 == 0, pixel_undrawn = pixel % 6 == 0;
                depth[i] = (whole ? pixel_undrawn : undrawn(rng)) ? clear_depth : std::nextafter(clear_depth, 0.0f) * u(rng);
            }
            const mr::SampleWindow c{colour.data(), 4, x0, y0, pitch, S}, z{depth.data(), 1, x0, y0, pitch, S};
            const std::vector<float> colour_before = colour;
            mr::Image fused(W, H, 4);
            mr::resolve_undrawn(c, z, x0, y0, x1, y1, clear_depth, clear, fused);
            EXPECT_TRUE(same_bits(colour, colour_before)) << "the samples changed";
            mr::fill_undrawn(c, z, x0, y0, x1, y1, clear_depth, clear);
            mr::Image two_passes(W, H, 4);
            mr::resolve_tile(c, x0, y0, x1, y1, mr::ResolveFilter::box, two_passes);
            EXPECT_TRUE(same_bits(fused.pixels, two_passes.pixels));
        }
    }
}

// The mean of finite samples is finite, however large they are: the sum must not overflow.
TEST(Resolve, SamplesNearTheFloatMaximumResolveToTheirFiniteMean) {
    const float big = std::numeric_limits<float>::max();
    for (int S : {2, 4, 16, 64}) {
        mr::Framebuffer fb;
        fb.width = 2;
        fb.height = 1;
        fb.samples = S;
        fb.color.assign(static_cast<std::size_t>(2 * S * 4), big);
        for (int s = 0; s < S; ++s) fb.color[4 * fb.sample_index(1, 0, s)] = s % 2 ? big : -big;  // pixel 1, red: mean 0
        mr::Image img(2, 1, 4);
        mr::resolve_tile(mr::color_window(fb), 0, 0, 2, 1, mr::ResolveFilter::box, img);
        for (int c = 0; c < 4; ++c) EXPECT_EQ(img.at(0, 0, c), big) << "S=" << S;
        EXPECT_EQ(img.at(1, 0, 0), 0.0f) << "S=" << S;
    }
}

// The wide filters too: their weighted sums of finite samples near the float maximum stay finite
// (in float they overflowed to infinity, and negative lobes made NaN). A constant frame of the
// maximum resolves to that constant, within rounding, and a frame of alternating signs near it
// to a finite value.
TEST(Resolve, WideFiltersOfSamplesNearTheFloatMaximumStayFinite) {
    const float big = std::numeric_limits<float>::max();
    mr::ThreadPool pool(1);
    for (mr::ResolveFilter filter : {mr::ResolveFilter::tent, mr::ResolveFilter::mitchell,
                                     mr::ResolveFilter::catmull_rom, mr::ResolveFilter::lanczos3}) {
        const mr::SamplePattern pattern = mr::make_sample_pattern(mr::PatternKind::grid, 4);
        mr::Framebuffer fb;
        fb.width = 7;
        fb.height = 5;
        fb.samples = 4;
        fb.color.assign(static_cast<std::size_t>(7 * 5 * 4 * 4), big);
        mr::Image img;
        mr::resolve_framebuffer(fb, pattern, filter, pool, img);
        for (float v : img.pixels) EXPECT_NEAR(v / big, 1.0f, 1e-6f) << mr::to_string(filter);
        for (std::size_t i = 0; i < fb.color.size(); i += 4) fb.color[i] = (i / 4) % 3 ? big : -big;
        mr::resolve_framebuffer(fb, pattern, filter, pool, img);
        for (float v : img.pixels) EXPECT_TRUE(std::isfinite(v)) << mr::to_string(filter);
    }
}

TEST(Resolve, RenderedImageIsTheMeanOfTheKeptSamples) {
    const int W = 24, H = 16, S = 16;
    const mr::Mesh tri = fixed_triangle({100, 200}, {23 * 256 + 5, 3 * 256 + 100}, {7 * 256 + 77, 15 * 256 + 250});
    mr::Mesh colored = tri;
    colored.colors = {glm::vec4(1, 0, 0, 1), glm::vec4(0, 0.5f, 0, 0.5f), glm::vec4(0.1f, 0.2f, 0.3f, 0.4f)};
    auto s = settings(W, H, S, mr::PatternKind::grid);
    s.clear_color = glm::vec4(0.25f, 0.5f, 0.75f, 1.0f);
    mr::DrawState st = no_depth(mr::BlendMode::over);
    st.interpolation = mr::Interpolation::screen;
    const mr::RenderResult r = mr::render({make_draw(colored, fixed_to_ndc(W, H), st)}, identity_camera(), s);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int c = 0; c < 4; ++c) {
                std::vector<double> xs;
                for (int k = 0; k < S; ++k) xs.push_back(sample_channel(r.framebuffer, x, y, k, c));
                double mean = 0;
                for (double v : xs) mean += v;
                mean /= S;
                EXPECT_NEAR(r.color.at(x, y, c), mean, mean_tolerance(xs));
            }
}

// ---------------------------------------------------------------------------------------------
// MSAA against SSAA
// ---------------------------------------------------------------------------------------------

void expect_msaa_shades_once_per_pixel(int S, mr::PatternKind kind) {
    const int W = 32, H = 32;
    // Two triangles sharing an edge, with vertex colours (screen interpolation).
    mr::Mesh m;
    m.positions = {{300, 500, 0}, {30 * 256 + 17, 2 * 256 + 3, 0}, {5 * 256 + 9, 31 * 256 + 100, 0}, {31 * 256, 29 * 256, 0}};
    m.colors = {glm::vec4(1, 0, 0, 1), glm::vec4(0, 1, 0, 1), glm::vec4(0, 0, 1, 1), glm::vec4(1, 1, 1, 1)};
    add_triangle(m, 0, 1, 2);
    add_triangle(m, 2, 1, 3);
    mr::DrawState st = no_depth();
    st.interpolation = mr::Interpolation::screen;
    auto s = settings(W, H, S, kind);
    s.anti_aliasing = mr::AntiAliasing::msaa;
    const mr::RenderResult msaa = mr::render({make_draw(m, fixed_to_ndc(W, H), st)}, identity_camera(), s);
    s.anti_aliasing = mr::AntiAliasing::ssaa;
    const mr::RenderResult ssaa = mr::render({make_draw(m, fixed_to_ndc(W, H), st)}, identity_camera(), s);
    const oracle::Pattern p = to_oracle(msaa.pattern);
    ASSERT_EQ(p.count(), S);

    std::uint64_t covered_samples = 0, pixel_triangle_pairs = 0, centre_checked = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            for (std::size_t t = 0; t < m.triangles.size(); ++t) {
                const auto v = snapped_triangle(m, t);
                int n = 0;
                for (int k = 0; k < S; ++k) {
                    const Fixed2 q = oracle::sample_position(x, y, p, k);
                    n += oracle::covers(v, q.x, q.y);
                }
                covered_samples += n;
                pixel_triangle_pairs += n > 0;
                if (n == 0) continue;
                // One colour for all the samples this triangle covers in this pixel.
                glm::vec4 first(-1.0f);
                for (int k = 0; k < S; ++k) {
                    const Fixed2 q = oracle::sample_position(x, y, p, k);
                    if (!oracle::covers(v, q.x, q.y)) continue;
                    const glm::vec4 c = sample_color(msaa.framebuffer, x, y, k);
                    if (first.r < 0) first = c;
                    EXPECT_EQ(c, first) << "pixel (" << x << ", " << y << ") sample " << k;
                }
                // With the pixel centre inside, that colour is the one at the centre.
                const Fixed2 centre{x * 256 + 128, y * 256 + 128};
                if (oracle::covers(v, centre.x, centre.y)) {
                    const double area = static_cast<double>(oracle::cross(v[0], v[1], v[2].x, v[2].y));
                    const glm::dvec3 l(static_cast<double>(oracle::cross(v[1], v[2], centre.x, centre.y)) / area,
                                       static_cast<double>(oracle::cross(v[2], v[0], centre.x, centre.y)) / area,
                                       static_cast<double>(oracle::cross(v[0], v[1], centre.x, centre.y)) / area);
                    const glm::uvec3 tri = m.triangles[t];
                    for (int c = 0; c < 4; ++c) {
                        const double want = l.x * m.colors[tri[0]][c] + l.y * m.colors[tri[1]][c] + l.z * m.colors[tri[2]][c];
                        EXPECT_NEAR(first[c], want, 1e-6) << "pixel (" << x << ", " << y << ")";
                    }
                    ++centre_checked;
                }
            }
        }
    EXPECT_EQ(msaa.stats.samples_covered, covered_samples);
    EXPECT_EQ(ssaa.stats.samples_covered, covered_samples);
    EXPECT_EQ(msaa.stats.shader_invocations, pixel_triangle_pairs);
    EXPECT_EQ(ssaa.stats.shader_invocations, covered_samples);
    EXPECT_GT(covered_samples, (S / 4) * pixel_triangle_pairs);  // MSAA really saves work here
    EXPECT_GT(centre_checked, 300u);
}

TEST(Resolve, MsaaShadesOncePerPixelAndStoresThatColourToEveryCoveredSample) {
    expect_msaa_shades_once_per_pixel(4, mr::PatternKind::rotated);
    expect_msaa_shades_once_per_pixel(16, mr::PatternKind::grid);
    expect_msaa_shades_once_per_pixel(64, mr::PatternKind::grid);
    expect_msaa_shades_once_per_pixel(25, mr::PatternKind::stratified);
}

// ---------------------------------------------------------------------------------------------
// Sample counts
// ---------------------------------------------------------------------------------------------

TEST(Resolve, SampleCounts1To64PassValidationEverySquareCountRendersAnd0And65AreRejected) {
    const int W = 8, H = 8;
    // A triangle far larger than the viewport: every sample covered exactly once.
    const mr::Mesh big = fixed_triangle({-4096, -4096}, {8192, -4096}, {-4096, 8192});
    for (int S = 1; S <= 64; ++S) {
        EXPECT_NO_THROW(mr::validate_framebuffer_size(W, H, S, true)) << "samples " << S;
        const int n = static_cast<int>(std::lround(std::sqrt(double(S))));
        const bool has_pattern = n * n == S;  // DESIGN.md §1: grid N×N (and rotated for 4, center for 1)
        if (!has_pattern) continue;
        const mr::RenderResult r = mr::render({make_draw(big, fixed_to_ndc(W, H), no_depth(mr::BlendMode::add))},
                                              identity_camera(), settings(W, H, S));
        ASSERT_EQ(r.framebuffer.samples, S);
        ASSERT_EQ(r.pattern.count(), S);
        for (int k = 0; k < S; ++k) {
            EXPECT_GE(r.pattern.x[k], 0);
            EXPECT_LT(r.pattern.x[k], 256);
            EXPECT_GE(r.pattern.y[k], 0);
            EXPECT_LT(r.pattern.y[k], 256);
        }
        EXPECT_EQ(r.stats.samples_covered, std::uint64_t(W) * H * S) << "samples " << S;
        EXPECT_TRUE(samples_equal(r.framebuffer, std::vector<float>(std::size_t(W) * H * S, 1.0f), 0, "coverage"))
            << "samples " << S;
        for (float v : r.color.pixels) EXPECT_EQ(v, 1.0f) << "samples " << S;
    }
    for (int S : {0, 65, -1}) {
        try {
            mr::render({make_draw(big, fixed_to_ndc(W, H), no_depth())}, identity_camera(), settings(W, H, S));
            ADD_FAILURE() << "samples " << S << " did not throw";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("samples"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(std::to_string(S)), std::string::npos) << e.what();
        }
        EXPECT_THROW(mr::validate_framebuffer_size(W, H, S, false), std::invalid_argument);
    }
}

TEST(Resolve, NonSquareCountsUseTheMostSquareGridAndStrata) {
    // Columns × rows with columns ≥ rows and rows the largest divisor ≤ √S.
    const std::vector<std::array<int, 3>> layouts = {{2, 2, 1}, {3, 3, 1}, {5, 5, 1}, {8, 4, 2},  {12, 4, 3},
                                                     {15, 5, 3}, {32, 8, 4}, {48, 8, 6}, {63, 9, 7}};
    for (const auto& [S, cols, rows] : layouts) {
        oracle::Pattern want;
        for (int b = 0; b < rows; ++b)
            for (int a = 0; a < cols; ++a) {
                want.x.push_back(static_cast<int>(std::floor((a + 0.5) / cols * 256.0 + 0.5)));
                want.y.push_back(static_cast<int>(std::floor((b + 0.5) / rows * 256.0 + 0.5)));
            }
        EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::grid, S)), want)) << "S = " << S;
        EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::automatic, S)), want)) << "S = " << S;
        const mr::SamplePattern j = mr::make_sample_pattern(mr::PatternKind::stratified, S, 7);
        // The cells the samples stand for (SSAA filters each sample's texture footprint over one).
        for (const mr::SamplePattern& p : {mr::make_sample_pattern(mr::PatternKind::grid, S), j}) {
            EXPECT_EQ(p.columns, cols) << "S = " << S;
            EXPECT_EQ(p.rows, rows) << "S = " << S;
        }
        std::vector<int> per(static_cast<std::size_t>(S), 0);
        for (int k = 0; k < j.count(); ++k) {
            // Stratum a covers [⌊256·a/cols⌋, ⌊256·(a+1)/cols⌋) on the 1/256 grid.
            int a = 0, b = 0;
            while (a < cols && 256 * (a + 1) / cols <= j.x[k]) ++a;
            while (b < rows && 256 * (b + 1) / rows <= j.y[k]) ++b;
            ASSERT_LT(a, cols);
            ASSERT_LT(b, rows);
            ++per[static_cast<std::size_t>(b * cols + a)];
        }
        for (int c : per) EXPECT_EQ(c, 1) << "S = " << S;
    }
    const mr::SamplePattern rotated = mr::make_sample_pattern(mr::PatternKind::rotated, 4);
    EXPECT_EQ(rotated.columns * 10 + rotated.rows, 22);
    const mr::SamplePattern centre = mr::make_sample_pattern(mr::PatternKind::center, 1);
    EXPECT_EQ(centre.columns * 10 + centre.rows, 11);
    // Every count renders, watertight: a covering triangle pair gives each sample exactly 1.
    for (int S = 1; S <= 64; ++S) {
        mr::Mesh quad = fixed_triangle({-4096, -4096}, {8192, -4096}, {-4096, 8192});
        const mr::RenderResult r = mr::render({make_draw(quad, fixed_to_ndc(8, 8), no_depth(mr::BlendMode::add))},
                                              identity_camera(), settings(8, 8, S));
        ASSERT_EQ(r.pattern.count(), S);
        EXPECT_EQ(r.stats.samples_covered, 64u * static_cast<unsigned>(S)) << "S = " << S;
    }
    // center and rotated have fixed counts.
    EXPECT_THROW(mr::make_sample_pattern(mr::PatternKind::center, 4), std::invalid_argument);
    EXPECT_THROW(mr::make_sample_pattern(mr::PatternKind::rotated, 8), std::invalid_argument);
}

TEST(Resolve, PatternsAreTheDocumentedOnes) {
    EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::center, 1)), oracle::center_pattern()));
    EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::rotated, 4)), oracle::rotated_pattern()));
    EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::automatic, 4)), oracle::rotated_pattern()));
    EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::automatic, 1)), oracle::center_pattern()));
    for (int n : {1, 2, 4, 8})
        EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::grid, n * n)), oracle::grid_pattern(n)));
    // Other N: ((a+½)/N)·256 rounded to the nearest 1/256 (never a tie for N ≤ 8).
    for (int n : {3, 5, 6, 7}) {
        oracle::Pattern want;
        for (int b = 0; b < n; ++b)
            for (int a = 0; a < n; ++a) {
                want.x.push_back(static_cast<int>(std::lround((a + 0.5) / n * 256.0)));
                want.y.push_back(static_cast<int>(std::lround((b + 0.5) / n * 256.0)));
            }
        EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::grid, n * n)), want)) << "N = " << n;
        EXPECT_TRUE(same_offsets(to_oracle(mr::make_sample_pattern(mr::PatternKind::automatic, n * n)), want)) << "N = " << n;
    }
    // Stratified: one sample in each stratum, the same for the same seed, different for another.
    for (int n = 1; n <= 8; ++n) {
        const mr::SamplePattern a = mr::make_sample_pattern(mr::PatternKind::stratified, n * n, 42);
        const mr::SamplePattern b = mr::make_sample_pattern(mr::PatternKind::stratified, n * n, 42);
        EXPECT_EQ(a.x, b.x);
        EXPECT_EQ(a.y, b.y);
        std::vector<int> per(n * n, 0);
        for (int k = 0; k < a.count(); ++k) {
            // Stratum a covers [256·a/n, 256·(a+1)/n) on the 1/256 grid.
            int sa = 0, sb = 0;
            while (256 * (sa + 1) / n <= a.x[k]) ++sa;
            while (256 * (sb + 1) / n <= a.y[k]) ++sb;
            ASSERT_LT(sa, n);
            ASSERT_LT(sb, n);
            ++per[sb * n + sa];
        }
        for (int c : per) EXPECT_EQ(c, 1) << "n = " << n;
    }
    const mr::SamplePattern c = mr::make_sample_pattern(mr::PatternKind::stratified, 16, 1);
    const mr::SamplePattern d = mr::make_sample_pattern(mr::PatternKind::stratified, 16, 2);
    EXPECT_TRUE(c.x != d.x || c.y != d.y);
}

TEST(Resolve, KeepingTheSamplesDoesNotChangeTheImage) {
    const int W = 24, H = 16;
    mr::Mesh tri = fixed_triangle({100, 200}, {23 * 256 + 5, 3 * 256 + 100}, {7 * 256 + 77, 15 * 256 + 250});
    tri.colors = {glm::vec4(1, 0, 0, 1), glm::vec4(0, 0.5f, 0, 0.5f), glm::vec4(0.1f, 0.2f, 0.3f, 0.4f)};
    for (int S : {1, 4}) {
        auto s = settings(W, H, S);
        s.clear_color = glm::vec4(0.25f, 0.5f, 0.75f, 1.0f);
        const mr::RenderResult kept = mr::render({make_draw(tri, fixed_to_ndc(W, H), no_depth(mr::BlendMode::over))},
                                                 identity_camera(), s);
        s.keep_samples = false;
        const mr::RenderResult plain = mr::render({make_draw(tri, fixed_to_ndc(W, H), no_depth(mr::BlendMode::over))},
                                                  identity_camera(), s);
        EXPECT_EQ(plain.color.pixels, kept.color.pixels) << "S=" << S;
        EXPECT_TRUE(plain.framebuffer.color.empty()) << "S=" << S;
        EXPECT_EQ(kept.framebuffer.color.size(), std::size_t(W) * H * S * 4);
        // And the image is the oracle's: per sample the clear colour, or the interpolated
        // premultiplied vertex colour over it (w = 1: perspective-correct is affine here).
        const oracle::Pattern p = to_oracle(kept.pattern);
        const auto v = snapped_triangle(tri, 0);
        const double area = static_cast<double>(oracle::cross(v[0], v[1], v[2].x, v[2].y));
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                glm::dvec4 sum(0.0);
                for (int k = 0; k < S; ++k) {
                    const oracle::Fixed2 q = oracle::sample_position(x, y, p, k);
                    glm::dvec4 c(s.clear_color);
                    if (oracle::covers(v, q.x, q.y)) {
                        const double l0 = static_cast<double>(oracle::cross(v[1], v[2], q.x, q.y)) / area;
                        const double l1 = static_cast<double>(oracle::cross(v[2], v[0], q.x, q.y)) / area;
                        const glm::dvec4 src = l0 * glm::dvec4(tri.colors[0]) + l1 * glm::dvec4(tri.colors[1]) +
                                               (1.0 - l0 - l1) * glm::dvec4(tri.colors[2]);
                        c = src + (1.0 - src.a) * c;
                    }
                    sum += c;
                }
                for (int c = 0; c < 4; ++c)
                    EXPECT_NEAR(plain.color.at(x, y, c), sum[c] / S, 2e-6) << "S=" << S << " pixel (" << x << ", " << y << ")";
            }
    }
}


// "One sample per pixel runs no resolve" (render's resolve_filter): at one sample a wide filter
// gives the box's copy, kept samples or not. (It used to reach resolve_tile with the wide filter
// and throw "use resolve_framebuffer".)
TEST(Resolve, OneSampleWithAWideFilterIsTheCopy) {
    const int W = 40, H = 36;  // two tiles by two, partial at the right and bottom
    mr::Mesh tri = fixed_triangle({100, 200}, {39 * 256 + 5, 3 * 256 + 100}, {7 * 256 + 77, 35 * 256 + 250});
    tri.colors = {glm::vec4(1, 0, 0, 1), glm::vec4(0, 0.5f, 0, 0.5f), glm::vec4(0.1f, 0.2f, 0.3f, 0.4f)};
    const std::vector<mr::Draw> draws = {make_draw(tri, fixed_to_ndc(W, H), no_depth(mr::BlendMode::over))};
    auto s = settings(W, H, 1);
    s.clear_color = glm::vec4(0.25f, 0.5f, 0.75f, 1.0f);
    s.keep_samples = false;
    const mr::RenderResult box = mr::render(draws, identity_camera(), s);
    for (mr::ResolveFilter filter : {mr::ResolveFilter::tent, mr::ResolveFilter::mitchell,
                                     mr::ResolveFilter::catmull_rom, mr::ResolveFilter::lanczos3})
        for (bool keep : {false, true}) {
            SCOPED_TRACE(mr::to_string(filter) + (keep ? ", samples kept" : ""));
            s.resolve_filter = filter;
            s.keep_samples = keep;
            const mr::RenderResult r = mr::render(draws, identity_camera(), s);
            EXPECT_TRUE(same_bits(r.color.pixels, box.color.pixels));
        }
}
}  // namespace
