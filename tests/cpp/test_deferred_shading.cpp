// Deferred shading (RenderSettings::deferred_shading): where triangles overlap deeply and every draw
// replaces, a visibility pre-pass and one shade per visible sample give the image of shading while
// rasterizing, bit for bit — colour, depth and every counter but shader_invocations — for every
// shading, texturing, depth setting, sample mode and thread count; the shader then runs exactly once
// per sample that ends up drawn (MSAA: once per pixel and owning triangle, where that triangle's draw
// shades the pixel). MSAA tiles are deferred only from a deeper overdraw; tiles with a blended or
// alpha-tested triangle never are.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "helpers.hpp"
#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/binning.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

struct Outcome {
    mr::RenderResult forward, deferred;
};

Outcome render_both(const std::vector<mr::Draw>& draws, const mr::Camera& cam, mr::RenderSettings s) {
    s.deferred_shading = false;
    Outcome o{mr::render(draws, cam, s), {}};
    s.deferred_shading = true;
    o.deferred = mr::render(draws, cam, s);
    return o;
}

void expect_same_image(const Outcome& o) {
    EXPECT_EQ(o.forward.stats.tiles_deferred, 0u);
    EXPECT_TRUE(same_bits(o.deferred.color.pixels, o.forward.color.pixels)) << "resolved colour differs";
    EXPECT_TRUE(same_bits(o.deferred.framebuffer.color, o.forward.framebuffer.color)) << "samples differ";
    EXPECT_TRUE(same_bits(o.deferred.framebuffer.depth, o.forward.framebuffer.depth)) << "depth differs";
    EXPECT_EQ(o.deferred.stats.samples_covered, o.forward.stats.samples_covered);
    EXPECT_EQ(o.deferred.stats.samples_passed, o.forward.stats.samples_passed);
    EXPECT_EQ(o.deferred.stats.depth_blocks_rejected, o.forward.stats.depth_blocks_rejected);
}

TEST(DeferredShading, SameBitsAsShadingWhileRasterizingOnOverlappingScenes) {
    const int W = 96, H = 80;  // partial tiles at the right and bottom
    const mr::Mesh a = overlapping(150, 2.5, 31), b = overlapping(100, 1.5, 32);
    const mr::Texture texture = checker_texture();
    glm::dmat4 shifted(1.0);
    shifted[3] = glm::dvec4(0.2, 0.1, 0.5, 1.0);
    mr::Sampler trilinear, anisotropic, bilinear;
    anisotropic.footprint = mr::FootprintFilter::anisotropic;
    bilinear.mip_filter = mr::MipFilter::none;  // no derivatives: the fixed texturing kernel
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        for (const auto& [aa, samples] : {std::pair{mr::AntiAliasing::ssaa, 1}, std::pair{mr::AntiAliasing::ssaa, 4},
                                         std::pair{mr::AntiAliasing::msaa, 4}})
            for (mr::Interpolation interpolation :
                 {mr::Interpolation::perspective, mr::Interpolation::screen, mr::Interpolation::flat}) {
                mr::DrawState tested;
                tested.interpolation = interpolation;
                mr::DrawState read_only = tested;  // tests depth without writing it
                read_only.depth_write = false;
                // Textured with analytic derivatives, untextured, textured without derivatives,
                // and an untested draw over all of it.
                std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), tested), make_draw(b, glm::dmat4(1.0), read_only),
                                               make_draw(b, shifted, tested, glm::vec4(0.9f, 0.8f, 1.0f, 1.0f)),
                                               make_draw(a, shifted, no_depth(), glm::vec4(0.5f))};
                draws[0].texture = texture;
                draws[0].sampler = samples == 1 ? anisotropic : trilinear;
                draws[2].texture = texture;
                draws[2].sampler = bilinear;
                draws[3].mesh = &b;
                if (aa == mr::AntiAliasing::msaa)  // (under MSAA only textured draws are deferred)
                    for (mr::Draw* d : {&draws[1], &draws[3]}) d->texture = texture, d->sampler = trilinear;
                for (int threads : {1, 2}) {
                    SCOPED_TRACE(mr::to_string(convention) + ", " + mr::to_string(aa) + " " + std::to_string(samples) +
                                 ", " + mr::to_string(interpolation) + ", " + std::to_string(threads) + " threads");
                    auto s = settings(W, H, samples);
                    s.anti_aliasing = aa;
                    s.threads = threads;
                    s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                    const Outcome o = render_both(draws, cam, s);
                    expect_same_image(o);
                    EXPECT_GT(o.deferred.stats.tiles_deferred, 0u);
                    EXPECT_LT(o.deferred.stats.shader_invocations, o.forward.stats.shader_invocations);
                }
            }
    }
}

TEST(DeferredShading, ShadesEachDrawnSampleExactlyOnce) {
    // One depth-tested, depth-writing draw: a sample is drawn iff its depth left the clear value
    // (the test is strict), and deferred shading runs the shader exactly there.
    const int W = 64, H = 64;
    const mr::Mesh a = overlapping(200, 2.5, 41);
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl})
        for (int samples : {1, 4}) {
            SCOPED_TRACE(mr::to_string(convention) + ", " + std::to_string(samples) + " samples");
            const mr::Camera cam = overlap_camera(convention, W, H);
            const float clear_depth = convention == mr::DepthConvention::opengl ? 1.0f : 0.0f;
            const mr::RenderResult r = mr::render({make_draw(a, glm::dmat4(1.0), mr::DrawState{})}, cam, settings(W, H, samples));
            ASSERT_EQ(r.stats.tiles_deferred, std::uint64_t((W / 32) * (H / 32)));  // every tile is deep here
            std::uint64_t drawn = 0;
            for (float z : r.framebuffer.depth) drawn += z != clear_depth;
            EXPECT_EQ(r.stats.shader_invocations, drawn);
            EXPECT_LT(r.stats.shader_invocations, r.stats.samples_passed);  // overdraw was left out
        }
}

TEST(DeferredShading, TileBuffersAndListedPixelsGiveTheForwardImage) {
    const int W = 70, H = 50;
    const mr::Mesh a = overlapping(200, 2.5, 51);
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), mr::DrawState{})};
    draws[0].texture = checker_texture();
    std::vector<std::uint32_t> pixels;
    for (std::uint32_t i = 0; i < std::uint32_t(W * H); ++i)
        if (i % 5) pixels.push_back(i);  // most of each tile: rasterized whole, resolved where listed
    for (int samples : {1, 4})
        for (bool listed : {false, true}) {
            SCOPED_TRACE(std::to_string(samples) + " samples" + (listed ? ", listed pixels" : ""));
            auto s = settings(W, H, samples);
            s.keep_samples = false;
            if (listed) s.pixels = pixels;
            const Outcome o = render_both(draws, cam, s);
            expect_same_image(o);
            if (!listed || samples > 1) {
                EXPECT_GT(o.deferred.stats.tiles_deferred, 0u);
            }
        }
}

// Two full-screen layers of a grid of right triangles (cells of `cell` px, vertex colours), the
// far one first: every sample passes twice, an overdraw of 2 in every tile.
mr::Mesh two_layers(int width, int height, int cell) {
    mr::Mesh m;
    for (float z : {0.5f, -0.5f}) {  // (opengl convention: the second is nearer)
        const auto first = static_cast<std::uint32_t>(m.positions.size());
        const int nx = width / cell, ny = height / cell;
        for (int j = 0; j <= ny; ++j)
            for (int i = 0; i <= nx; ++i) {
                m.positions.push_back({i * cell * 256.0f, j * cell * 256.0f, z});
                m.colors.push_back({0.2f + 0.5f * z, float(i) / nx, float(j) / ny, 1.0f});
                m.uvs.push_back({float(i) / nx, float(j) / ny});
            }
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const std::uint32_t v = first + std::uint32_t(j * (nx + 1) + i);
                add_triangle(m, v, v + 1, v + std::uint32_t(nx) + 1);
                add_triangle(m, v + 1, v + std::uint32_t(nx) + 2, v + std::uint32_t(nx) + 1);
            }
    }
    return m;
}

// Untextured shading is cheap: at an overdraw of 2, tiles of tiny triangles (2 px²) shade while
// rasterizing and tiles of larger ones (8 px²) are deferred ((O − 1)²·a against
// kDeferredMinUntexturedGain = 4); with a texture the tiny ones are deferred too. The images are
// the forward ones either way.
TEST(DeferredShading, UntexturedTilesAreDeferredOnlyWithBigEnoughTriangles) {
    const int W = 64, H = 64;
    const std::uint64_t tiles = (W / 32) * (H / 32);
    const mr::Mesh small = two_layers(W, H, 2), large = two_layers(W, H, 4);
    const mr::Texture texture = checker_texture();
    struct Case {
        std::string name;
        const mr::Mesh* mesh;
        bool textured;
        std::uint64_t deferred_tiles;
    };
    const Case cases[] = {{"small, untextured", &small, false, 0},
                          {"large, untextured", &large, false, tiles},
                          {"small, textured", &small, true, tiles}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        mr::Draw draw = make_draw(*c.mesh, fixed_to_ndc(W, H), {});
        if (c.textured) draw.texture = texture;
        const Outcome o = render_both({draw}, identity_camera(), settings(W, H, 1));
        expect_same_image(o);
        EXPECT_EQ(o.deferred.stats.tiles_deferred, c.deferred_tiles);
    }
}

// `layers` textured quads over the W × H viewport (positions in 1/256 px: fixed_to_ndc), each nearer
// than the one before, the last one only over x < last_width · W.
mr::Mesh layered_quads(int layers, int W, int H, float last_width = 1.0f) {
    mr::Mesh m;
    for (int k = 0; k < layers; ++k) {
        const float z = 0.8f - 0.3f * static_cast<float>(k);  // (OpenGL depth: nearer is smaller)
        const float width = k == layers - 1 ? last_width : 1.0f;
        const auto first = static_cast<std::uint32_t>(m.positions.size());
        for (const glm::vec2 corner : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)}) {
            m.positions.push_back({corner.x * width * W * 256.0f, corner.y * H * 256.0f, z});
            m.uvs.push_back(corner * (1.5f + static_cast<float>(k)));
        }
        add_triangle(m, first, first + 1, first + 2);
        add_triangle(m, first, first + 2, first + 3);
    }
    return m;
}

// Over a 2 × 2 tile viewport, a full quad and one over 70 % of the width: overdraw 2 in the left
// tiles, 1.4 in the right ones. One sample and SSAA defer all four (from 1.25), MSAA the left two
// (from kDeferredMinOverdrawMsaa = 1.5); four full quads all four under MSAA too. The forward image
// every time.
TEST(DeferredShading, MsaaTilesAreDeferredFromADeeperOverdraw) {
    static_assert(mr::kDeferredMinOverdraw < 1.4 && mr::kDeferredMinOverdrawMsaa > 1.4 &&
                  mr::kDeferredMinOverdrawMsaa <= 2.0, "the cases below straddle the thresholds");
    const int W = 64, H = 64;
    for (const auto& [layers, aa, samples, deferred_tiles] :
         {std::tuple{2, mr::AntiAliasing::ssaa, 1, 4u}, std::tuple{2, mr::AntiAliasing::ssaa, 4, 4u},
          std::tuple{2, mr::AntiAliasing::msaa, 4, 2u}, std::tuple{4, mr::AntiAliasing::msaa, 4, 4u}}) {
        SCOPED_TRACE(std::to_string(layers) + " layers, " + mr::to_string(aa) + " " + std::to_string(samples));
        const mr::Mesh quads = layered_quads(layers, W, H, layers == 2 ? 0.7f : 1.0f);
        mr::Draw draw = make_draw(quads, fixed_to_ndc(W, H), {});
        draw.texture = checker_texture();
        auto s = settings(W, H, samples);
        s.anti_aliasing = aa;
        const Outcome o = render_both({draw}, identity_camera(), s);
        expect_same_image(o);
        EXPECT_EQ(o.deferred.stats.tiles_deferred, deferred_tiles);
        EXPECT_LT(o.deferred.stats.shader_invocations, o.forward.stats.shader_invocations);
        // All deferred: one shade per sample, the nearest layer's; under MSAA one per pixel, and two
        // where the diagonal between the nearest quad's triangles splits a pixel's samples.
        const std::uint64_t shades = o.deferred.stats.shader_invocations, pixels = std::uint64_t(W) * H;
        if (deferred_tiles < 4) continue;
        if (aa == mr::AntiAliasing::msaa) {
            EXPECT_GE(shades, pixels);
            EXPECT_LE(shades, pixels + 2 * W);
            EXPECT_GT(o.forward.stats.shader_invocations, 3 * pixels);
        } else {
            EXPECT_EQ(shades, pixels * samples);
        }
    }
}

TEST(DeferredShading, BlendingMsaaAndShallowScenesShadeWhileRasterizing) {
    const int W = 64, H = 64;
    const mr::Mesh deep = overlapping(200, 2.5, 61), shallow = overlapping(3, 0.3, 62);
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    mr::DrawState over;
    over.blend = mr::BlendMode::over;
    struct Case {
        std::string name;
        std::vector<mr::Draw> draws;
        mr::AntiAliasing aa;
        int samples;
    };
    const Case cases[] = {
        {"one blended draw among opaque ones", {make_draw(deep, glm::dmat4(1.0), {}), make_draw(deep, glm::dmat4(1.0), over)},
         mr::AntiAliasing::ssaa, 4},
        {"untextured msaa", {make_draw(deep, glm::dmat4(1.0), {})}, mr::AntiAliasing::msaa, 4},
        {"few small triangles", {make_draw(shallow, glm::dmat4(1.0), {})}, mr::AntiAliasing::ssaa, 4},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        auto s = settings(W, H, c.samples);
        s.anti_aliasing = c.aa;
        const Outcome o = render_both(c.draws, cam, s);
        expect_same_image(o);
        EXPECT_EQ(o.deferred.stats.tiles_deferred, 0u);
        EXPECT_EQ(o.deferred.stats.shader_invocations, o.forward.stats.shader_invocations);
    }
}

TEST(DeferredShading, ABlendedOrAlphaTestedDrawKeepsOnlyItsOwnTilesFromBeingDeferred) {
    // A deep textured scene over 3×3 tiles, and a small triangle near the camera, which it sees in
    // the middle tile only: blended or alpha-tested, it stops that tile from being
    // deferred (its shade decides what lies in front), and no other.
    const int W = 96, H = 96;
    const mr::Mesh deep = overlapping(200, 2.5, 71);
    mr::Mesh small;
    const glm::vec3 c(0.27f, 0.72f, 3.6f);  // on the line of sight, 0.43 from the camera (~6 px wide)
    small.positions = {c + glm::vec3(-0.03f, -0.025f, 0.0f), c + glm::vec3(0.03f, -0.025f, 0.0f),
                       c + glm::vec3(0.0f, 0.03f, 0.0f)};
    small.triangles = {{0, 1, 2}};
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    mr::DrawState blended, alpha_tested;
    blended.blend = mr::BlendMode::over;
    alpha_tested.alpha_cutoff = 0.5f;
    std::vector<mr::Draw> alone = {make_draw(deep, glm::dmat4(1.0), {})};
    alone[0].texture = checker_texture();
    const mr::RenderResult deep_only = mr::render(alone, cam, settings(W, H, 1));
    ASSERT_EQ(deep_only.stats.tiles_deferred, 9u);  // every tile deep enough on its own
    for (const auto& [name, state, colour] :
         {std::tuple{"blended", blended, glm::vec4(0.4f, 0.1f, 0.1f, 0.5f)},
          std::tuple{"alpha-tested, passing", alpha_tested, glm::vec4(0.9f, 0.2f, 0.1f, 0.75f)},
          std::tuple{"alpha-tested, discarded", alpha_tested, glm::vec4(0.9f, 0.2f, 0.1f, 0.25f)}})
        for (bool on_top : {false, true})
            for (int samples : {1, 4}) {
                SCOPED_TRACE(std::string(name) + (on_top ? ", no depth test" : "") + ", " + std::to_string(samples) +
                             " samples");
                mr::DrawState st = state;
                st.depth_test = !on_top;  // on top: drawn over the deep scene wherever it lies
                std::vector<mr::Draw> draws = alone;
                draws.push_back(make_draw(small, glm::dmat4(1.0), st, colour));
                const Outcome o = render_both(draws, cam, settings(W, H, samples));
                expect_same_image(o);
                EXPECT_EQ(o.deferred.stats.tiles_deferred, 8u);
                // Drawn on top, the small triangle changed the middle tile's pixels (depth-tested, the
                // deep scene's triangles that cross the near plane may hide it).
                if (on_top && std::string(name) != "alpha-tested, discarded") {
                    const mr::RenderResult without = mr::render(alone, cam, settings(W, H, samples));
                    EXPECT_FALSE(same_bits(o.deferred.color.pixels, without.color.pixels));
                }
            }
}

// A random triangle of about `size` pixels around a random point of an N×N screen (its vertices
// in pixels).
std::array<glm::dvec2, 3> random_screen_triangle(std::mt19937_64& rng, double size, int N) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const glm::dvec2 c(N * unit(rng), N * unit(rng));
    std::array<glm::dvec2, 3> v;
    for (glm::dvec2& vertex : v) vertex = c + size * glm::dvec2(unit(rng) - 0.5, unit(rng) - 0.5);
    return v;
}

// Sets up the screen triangle v on an N×N viewport (clip positions with w = 1); false when culled.
bool set_up(const std::array<glm::dvec2, 3>& v, int N, mr::SetupTriangle& t) {
    mr::Viewport vp;
    vp.width = vp.height = N;
    std::array<glm::dvec4, 3> p;
    for (int i = 0; i < 3; ++i) p[i] = glm::dvec4(2.0 * v[i].x / N - 1.0, 1.0 - 2.0 * v[i].y / N, 0.5, 1.0);
    mr::SetupCounters counters;
    return mr::setup_triangle(p, vp, mr::CullMode::none, t, counters);
}

// The area (shoelace formula) and perimeter of the screen triangle v, in pixels.
double triangle_area(const std::array<glm::dvec2, 3>& v) {
    return 0.5 * std::abs((v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y));
}
double triangle_perimeter(const std::array<glm::dvec2, 3>& v) {
    double perimeter = 0.0;
    for (int i = 0; i < 3; ++i) perimeter += glm::length(v[(i + 1) % 3] - v[i]);
    return perimeter;
}

// The overlap estimate that decides deferring (tile_overlap_area, added up while binning) against
// independent values: a triangle inside the rectangle counts its own area (the shoelace formula on
// its screen vertices, within their snapping to 1/256 px), a rectangle inside the triangle counts
// whole, one its bounding box misses counts nothing, and no estimate leaves [0, rectangle area].
TEST(DeferredShading, OverlapAreaIsTheTriangleOrTheRectangleWhereOneHoldsTheOther) {
    std::mt19937_64 rng(44);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int N = 256;
    int inside = 0, covered = 0, missed = 0;
    for (int k = 0; k < 80000; ++k) {
        const double size = std::array<double, 4>{0.7, 4.0, 30.0, 600.0}[k % 4];
        const std::array<glm::dvec2, 3> v = random_screen_triangle(rng, size, N);
        mr::SetupTriangle t;
        if (!set_up(v, N, t)) continue;
        int x0 = static_cast<int>(N * unit(rng)), y0 = static_cast<int>(N * unit(rng));
        int x1 = x0 + 1 + static_cast<int>((N - x0) * unit(rng)), y1 = y0 + 1 + static_cast<int>((N - y0) * unit(rng));
        x1 = std::min(x1, N), y1 = std::min(y1, N);
        const double got = mr::tile_overlap_area(t, x0, y0, x1, y1);
        const double rect = double(x1 - x0) * double(y1 - y0);
        ASSERT_GE(got, 0.0);
        ASSERT_LE(got, rect);
        if (t.min_x >= x1 || t.max_x < x0 || t.min_y >= y1 || t.max_y < y0) {
            ++missed;
            EXPECT_EQ(got, 0.0);
        } else if (t.min_x > x0 && t.max_x + 1 < x1 && t.min_y > y0 && t.max_y + 1 < y1) {
            ++inside;
            EXPECT_NEAR(got, triangle_area(v), triangle_perimeter(v) / 256.0 + 1e-9) << "triangle of size " << size;
        } else {
            // The rectangle inside the triangle: its corners on the inner side of every edge, by
            // more than the snapping can move an edge.
            bool holds = true;
            const double orient = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
            for (int i = 0; i < 3 && holds; ++i) {
                const glm::dvec2 a = v[i], b = v[(i + 1) % 3];
                for (const glm::dvec2 q : {glm::dvec2(x0, y0), glm::dvec2(x1, y0), glm::dvec2(x0, y1), glm::dvec2(x1, y1)}) {
                    const double side = ((b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y)) * (orient > 0 ? 1 : -1);
                    holds = holds && side > 2.0 * glm::length(b - a);
                }
            }
            if (holds) {
                ++covered;
                EXPECT_EQ(got, rect);
            }
        }
    }
    EXPECT_GT(inside, 2000);
    EXPECT_GT(covered, 600);
    EXPECT_GT(missed, 2000);
}

// Area of the triangle v (screen pixels) inside [x0, x1) × [y0, y1): the triangle clipped by the
// rectangle's four sides (the other way round from the renderer, which clips the rectangle by
// the triangle's snapped edges), then the shoelace formula.
double triangle_in_rectangle(const std::array<glm::dvec2, 3>& v, double x0, double y0, double x1, double y1) {
    std::vector<glm::dvec2> poly(v.begin(), v.end());
    const auto clip = [&](auto inside_distance) {  // keeps the side where inside_distance ≥ 0
        std::vector<glm::dvec2> out;
        for (std::size_t k = 0; k < poly.size(); ++k) {
            const glm::dvec2 p = poly[k], q = poly[(k + 1) % poly.size()];
            const double dp = inside_distance(p), dq = inside_distance(q);
            if (dp >= 0) out.push_back(p);
            if ((dp >= 0) != (dq >= 0)) out.push_back(p + (dp / (dp - dq)) * (q - p));
        }
        poly = out;
    };
    clip([&](glm::dvec2 p) { return p.x - x0; });
    clip([&](glm::dvec2 p) { return x1 - p.x; });
    clip([&](glm::dvec2 p) { return p.y - y0; });
    clip([&](glm::dvec2 p) { return y1 - p.y; });
    double twice = 0.0;
    for (std::size_t k = 0; k < poly.size(); ++k) {
        const glm::dvec2 p = poly[k], q = poly[(k + 1) % poly.size()];
        twice += p.x * q.y - q.x * p.y;
    }
    return 0.5 * std::abs(twice);
}

// Where a triangle wider or taller than a tile covers part of the rectangle, the estimate is its
// area inside the rectangle (against an independent clip of its unsnapped vertices, within the
// snapping), whether or not the triangle reaches past the viewport: a bounding box clamped to the
// viewport no longer says how much of it the triangle fills (two large triangles sharing an edge
// across a tile counted the tile twice over, and deferred it for nothing).
// Binning adds up each tile's overlap estimate only for a render that may defer: the tile lists
// are the same either way, and the sums are those of tile_overlap_area over each tile's triangles.
TEST(DeferredShading, BinningAddsOverlapAreasOnlyWhenAsked) {
    std::mt19937_64 rng(45);
    // 7×7 and 22×22 tiles, the last row and column partial; triangles from a few pixels to wider
    // than the screen.
    for (const int N : {200, 700}) {
        SCOPED_TRACE(std::to_string(N) + "×" + std::to_string(N));
        const mr::TileGrid grid = mr::TileGrid::for_viewport(N, N);
        mr::BinnedChunk with, without;
        for (int k = 0; k < 400; ++k) {
            const double size = std::array<double, 4>{3.0, 40.0, 300.0, 2000.0}[k % 4];
            mr::SetupTriangle t;
            if (set_up(random_screen_triangle(rng, size, N), N, t)) {
                with.triangles.push_back(t);
                without.triangles.push_back(t);
            }
        }
        mr::bin_triangles(with, grid, true);
        mr::bin_triangles(without, grid, false);
        EXPECT_EQ(with.tile_start, without.tile_start);
        EXPECT_TRUE(std::equal(with.tile_triangles.begin(), with.tile_triangles.end(), without.tile_triangles.begin(),
                               without.tile_triangles.end()));
        EXPECT_TRUE(without.tile_area.empty());
        ASSERT_EQ(with.tile_area.size(), static_cast<std::size_t>(grid.count()));
        for (int tile = 0; tile < grid.count(); ++tile) {
            const int x0 = tile % grid.tiles_x * mr::kTileSize, y0 = tile / grid.tiles_x * mr::kTileSize;
            double sum = 0.0;
            for (std::uint32_t i = with.tile_start[tile]; i < with.tile_start[tile + 1]; ++i)
                sum += mr::tile_overlap_area(with.triangles[with.tile_triangles[i]], x0, y0,
                                             std::min(x0 + mr::kTileSize, N), std::min(y0 + mr::kTileSize, N));
            EXPECT_EQ(with.tile_area[static_cast<std::size_t>(tile)], sum) << "tile " << tile;
        }
    }
}

// The binner's shortcut for a triangle whose bounds lie in one tile gives tile_overlap_area's sum
// too: small triangles on the tiles' borders (touching, not crossing them) and on the viewport's
// edges, where the bounds are clamped, and slivers that cut a corner of the viewport from outside
// (their clamped bounds reach into the corner tile, they cover none of it: the estimate is 0).
TEST(DeferredShading, BinningSumsOverlapAreasOfSmallTrianglesOnTileAndViewportEdges) {
    std::mt19937_64 rng(47);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (const int N : {200, 700}) {  // the last row and column of tiles partial, 8 and 28 pixels
        SCOPED_TRACE(std::to_string(N) + "×" + std::to_string(N));
        const mr::TileGrid grid = mr::TileGrid::for_viewport(N, N);
        const int tiles = grid.tiles_x;
        // Where to put a vertex: near a tile border or the viewport's edge, or anywhere.
        const auto coordinate = [&](int pick) {
            const double edge = pick == 0 ? mr::kTileSize * static_cast<int>(tiles * unit(rng)) : pick == 1 ? N : 0.0;
            return pick == 3 ? N * unit(rng) : edge + 8.0 * (unit(rng) - 0.5);
        };
        mr::BinnedChunk chunk;
        int straddling = 0;  // triangles listed in a tile their bounds reach past
        for (int k = 0; k < 6000; ++k) {
            std::array<glm::dvec2, 3> v;
            if (k % 10 == 9) {  // past corner c: its edge AB crosses the diagonal outside, 0.3 px from c
                const glm::dvec2 c(unit(rng) < 0.5 ? 0.0 : N, unit(rng) < 0.5 ? 0.0 : N);
                const glm::dvec2 out(c.x == 0.0 ? -1.0 : 1.0, c.y == 0.0 ? -1.0 : 1.0);
                const double r = 1.0 + 3.0 * unit(rng);
                v = {c + out * glm::dvec2(r + 0.3, -r), c + out * glm::dvec2(-r, r + 0.3), c + out * r};
            } else {
                const int pick_x = static_cast<int>(4 * unit(rng)), pick_y = static_cast<int>(4 * unit(rng));
                const glm::dvec2 c(coordinate(pick_x), coordinate(pick_y));
                const double size = 0.5 + 6.0 * unit(rng);
                for (glm::dvec2& vertex : v) vertex = c + size * glm::dvec2(unit(rng) - 0.5, unit(rng) - 0.5);
            }
            mr::SetupTriangle t;
            if (set_up(v, N, t)) chunk.triangles.push_back(t);
        }
        mr::bin_triangles(chunk, grid, true);
        for (int tile = 0; tile < grid.count(); ++tile) {
            const int x0 = tile % tiles * mr::kTileSize, y0 = tile / tiles * mr::kTileSize;
            double sum = 0.0;
            for (std::uint32_t i = chunk.tile_start[tile]; i < chunk.tile_start[tile + 1]; ++i) {
                const mr::SetupTriangle& t = chunk.triangles[chunk.tile_triangles[i]];
                const double area =
                    mr::tile_overlap_area(t, x0, y0, std::min(x0 + mr::kTileSize, N), std::min(y0 + mr::kTileSize, N));
                const int x1 = x0 + mr::kTileSize, y1 = y0 + mr::kTileSize;
                straddling += t.min_x < x0 || t.min_y < y0 || t.max_x >= x1 || t.max_y >= y1;
                sum += area;
            }
            EXPECT_EQ(chunk.tile_area[static_cast<std::size_t>(tile)], sum) << "tile " << tile;
        }
        EXPECT_GT(chunk.triangles.size(), 3500u);
        EXPECT_GT(straddling, 500);
    }
}

// With enough_overdraw, a tile's sum is the exact one wherever that stays below enough_overdraw
// times the tile's area, and reaches that much wherever the exact one does: the same answer to
// "is the overdraw at least enough_overdraw?", with less summed (large triangles, piled up).
TEST(DeferredShading, BinningStopsSummingATileAtEnoughOverdrawWithTheSameAnswer) {
    std::mt19937_64 rng(48);
    for (const int N : {200, 700}) {
        SCOPED_TRACE(std::to_string(N) + "×" + std::to_string(N));
        const mr::TileGrid grid = mr::TileGrid::for_viewport(N, N);
        mr::BinnedChunk exact, enough;
        for (int k = 0; k < 60; ++k) {
            const double size = std::array<double, 4>{3.0, 40.0, 0.5 * N, 1.5 * N}[k % 4];
            mr::SetupTriangle t;
            if (set_up(random_screen_triangle(rng, size, N), N, t)) {
                exact.triangles.push_back(t);
                enough.triangles.push_back(t);
            }
        }
        const double kEnough = 1.25;
        mr::bin_triangles(exact, grid, true);
        mr::bin_triangles(enough, grid, true, kEnough);
        EXPECT_EQ(exact.tile_start, enough.tile_start);
        int below = 0, stopped = 0;
        for (int tile = 0; tile < grid.count(); ++tile) {
            const int x0 = tile % grid.tiles_x * mr::kTileSize, y0 = tile / grid.tiles_x * mr::kTileSize;
            const double limit = kEnough * std::min(mr::kTileSize, N - x0) * std::min(mr::kTileSize, N - y0);
            const double all = exact.tile_area[static_cast<std::size_t>(tile)];
            const double some = enough.tile_area[static_cast<std::size_t>(tile)];
            if (all < limit) {
                ++below;
                EXPECT_EQ(some, all) << "tile " << tile;
            } else {
                EXPECT_GE(some, limit) << "tile " << tile;
                EXPECT_LE(some, all) << "tile " << tile;
                stopped += some < all;
            }
        }
        std::cout << "tiles below " << below << ", stopped " << stopped << " of " << grid.count() << "\n";
        EXPECT_GT(below, grid.count() / 20);
        EXPECT_GT(stopped, grid.count() / 4);
    }
}

// Binning lists each tile's triangles as a brute-force scan finds them: every triangle whose pixel
// bounds touch the tile, in ascending order.
TEST(DeferredShading, BinningListsEveryTileItsTouchingTrianglesInOrder) {
    std::mt19937_64 rng(46);
    const int N = 200;  // 7×7 tiles, the last row and column partial
    const mr::TileGrid grid = mr::TileGrid::for_viewport(N, N);
    for (int round = 0; round < 20; ++round) {
        mr::BinnedChunk chunk;
        for (int k = 0; k < 300; ++k) {
            mr::SetupTriangle t;
            if (set_up(random_screen_triangle(rng, std::array<double, 3>{3.0, 40.0, 300.0}[k % 3], N), N, t))
                chunk.triangles.push_back(t);
        }
        mr::bin_triangles(chunk, grid, round % 2 == 0);
        ASSERT_EQ(chunk.tile_start.size(), static_cast<std::size_t>(grid.count()) + 1);
        for (int tile = 0; tile < grid.count(); ++tile) {
            const int x0 = tile % grid.tiles_x * mr::kTileSize, y0 = tile / grid.tiles_x * mr::kTileSize;
            std::vector<std::uint32_t> touching;
            for (std::uint32_t i = 0; i < chunk.triangles.size(); ++i) {
                const mr::SetupTriangle& t = chunk.triangles[i];
                if (t.min_x < x0 + mr::kTileSize && t.max_x >= x0 && t.min_y < y0 + mr::kTileSize && t.max_y >= y0)
                    touching.push_back(i);
            }
            const std::vector<std::uint32_t> listed(chunk.tile_triangles.begin() + chunk.tile_start[tile],
                                                    chunk.tile_triangles.begin() + chunk.tile_start[tile + 1]);
            EXPECT_EQ(listed, touching) << "round " << round << ", tile " << tile;
        }
    }
}

// A triangle no larger than a tile spread over the tiles its bounds reach: their estimates add up
// to its area (the shoelace formula on its screen vertices, within their snapping), whichever tiles
// it touches or misses; the binner's sums are these estimates (the tests above).
TEST(DeferredShading, OverlapAreasOfASmallTriangleOverItsTilesAddUpToItsArea) {
    std::mt19937_64 rng(46);
    const int N = 256, T = mr::kTileSize;
    int spanning = 0;
    for (int k = 0; k < 40000; ++k) {
        const double size = std::array<double, 4>{1.5, 4.0, 12.0, 30.0}[k % 4];
        const std::array<glm::dvec2, 3> v = random_screen_triangle(rng, size, N);
        mr::SetupTriangle t;
        if (!set_up(v, N, t)) continue;
        // Whole in the viewport, no larger than a tile, its bounds on more than one tile.
        if (std::min({v[0].x, v[1].x, v[2].x, v[0].y, v[1].y, v[2].y}) < 1.0 ||
            std::max({v[0].x, v[1].x, v[2].x, v[0].y, v[1].y, v[2].y}) > N - 1.0)
            continue;
        if (t.max_x + 1 - t.min_x > T || t.max_y + 1 - t.min_y > T) continue;
        if (t.min_x / T == t.max_x / T && t.min_y / T == t.max_y / T) continue;
        ++spanning;
        double sum = 0.0;
        for (int y0 = 0; y0 < N; y0 += T)
            for (int x0 = 0; x0 < N; x0 += T) sum += mr::tile_overlap_area(t, x0, y0, x0 + T, y0 + T);
        EXPECT_NEAR(sum, triangle_area(v), triangle_perimeter(v) / 256.0 + 1e-9) << "triangle of size " << size;
    }
    EXPECT_GT(spanning, 3000);
}

TEST(DeferredShading, OverlapAreaOfALargeTriangleIsItsAreaInsideTheRectangle) {
    std::mt19937_64 rng(45);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int N = 256;
    int partial = 0, past_viewport = 0;
    for (int k = 0; k < 60000; ++k) {
        const double size = std::array<double, 3>{40.0, 200.0, 2000.0}[k % 3];
        const std::array<glm::dvec2, 3> v = random_screen_triangle(rng, size, N);
        mr::SetupTriangle t;
        if (!set_up(v, N, t)) continue;
        if (t.max_x + 1 - t.min_x <= mr::kTileSize && t.max_y + 1 - t.min_y <= mr::kTileSize) continue;
        const int x0 = static_cast<int>((N - 32) * unit(rng)), y0 = static_cast<int>((N - 32) * unit(rng));
        const int x1 = x0 + 1 + static_cast<int>(32 * unit(rng)), y1 = y0 + 1 + static_cast<int>(32 * unit(rng));
        const double got = mr::tile_overlap_area(t, x0, y0, x1, y1);
        const double rect = double(x1 - x0) * double(y1 - y0);
        const double expected = triangle_in_rectangle(v, x0, y0, x1, y1);
        if (expected <= 0.0 || expected >= rect) continue;  // (missed or held whole: the other test)
        const double perimeter = triangle_perimeter(v);
        // Snapping moves each edge by at most 1/256 px (with the top-left bias): the area inside the
        // rectangle by at most the edges' length inside it, bounded by its perimeter.
        const double slack = std::min(perimeter, 2.0 * (x1 - x0 + y1 - y0)) / 128.0 + 1e-9;
        ++partial;
        past_viewport += std::min({v[0].x, v[1].x, v[2].x}) < 0.0 || std::max({v[0].x, v[1].x, v[2].x}) > N;
        EXPECT_NEAR(got, expected, slack) << "triangle of size " << size << ", rectangle (" << x0 << ", " << y0
                                          << ") - (" << x1 << ", " << y1 << ")";
    }
    std::cout << "partly covered rectangles " << partial << ", of them by triangles past the viewport "
              << past_viewport << "\n";
    EXPECT_GT(partial, 2000);
    EXPECT_GT(past_viewport, 300);
}

}  // namespace
