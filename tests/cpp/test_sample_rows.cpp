// Sample rows (RenderSettings::sample_rows): at one sample per pixel or SSAA, a triangle's
// coverage, screen weights and depth tests (if any) along a row run four pixels per vector
// (sample by sample under SSAA); under MSAA a pixel's depth tests run four samples per vector.
// Colour, depth and every counter are bit for bit those of the per-sample path — for both depth conventions, every blend and interpolation, textured or not,
// depth written or only read, with and without block skipping and deferred shading — including
// triangles whose edge values along a row pass 2^52, where the rows fall back to the per-sample
// path.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "helpers.hpp"
#include "mipraster/pipeline/interpolate.hpp"
#include "pipeline/pixel_samples.hpp"  // (internal: coverage masks four samples per vector)
#include "pipeline/sample_row.hpp"     // (internal: the two vector widths side by side)

namespace {

namespace mr = mipraster;
using namespace helpers;

void expect_same_with_and_without_rows(const std::vector<mr::Draw>& draws, const mr::Camera& cam,
                                       const mr::RenderSettings& s) {
    const auto [plain, rows] = render_off_on(draws, cam, s, &mr::RenderSettings::sample_rows);
    EXPECT_GT(rows.stats.samples_passed, 0u);
    expect_same_render(rows, plain);
    EXPECT_EQ(rows.stats.depth_blocks_rejected, plain.stats.depth_blocks_rejected);
    EXPECT_EQ(rows.stats.tiles_deferred, plain.stats.tiles_deferred);
}

TEST(SampleRows, SameBitsAndCountersAsThePerSamplePathOnOverlappingScenes) {
    const int W = 96, H = 80;  // partial tiles at the right and bottom
    const mr::Mesh a = overlapping(150, 2.5, 41), b = overlapping(100, 1.5, 42);
    const mr::Texture texture = checker_texture();
    glm::dmat4 shifted(1.0);
    shifted[3] = glm::dvec4(0.2, 0.1, 0.5, 1.0);
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        for (mr::BlendMode blend : {mr::BlendMode::replace, mr::BlendMode::over})
            for (mr::Interpolation interpolation : {mr::Interpolation::perspective, mr::Interpolation::screen})
                for (bool skipping : {false, true}) {
                    mr::DrawState tested;
                    tested.blend = blend;
                    tested.interpolation = interpolation;
                    mr::DrawState read_only = tested;
                    read_only.depth_write = false;
                    // Textured; the same triangles again at the same depths (every test ties and fails);
                    // untextured, read-only and flat; then two draws without depth test, untextured
                    // and textured.
                    std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), tested),
                                                   make_draw(a, glm::dmat4(1.0), tested, glm::vec4(0.2f, 0.9f, 0.4f, 1.0f)),
                                                   make_draw(b, shifted, tested),
                                                   make_draw(b, glm::dmat4(1.0), read_only, glm::vec4(0.9f, 0.8f, 1.0f, 1.0f)),
                                                   make_draw(a, shifted, no_depth(blend), glm::vec4(0.5f)),
                                                   make_draw(b, glm::dmat4(1.0), no_depth(blend))};
                    draws[0].texture = texture;
                    draws[5].texture = texture;  // (textured without a depth test: rows of every mode)
                    draws[3].state.interpolation = mr::Interpolation::flat;
                    draws[4].mesh = &b;
                    // One sample per pixel, SSAA (rows sample by sample) and MSAA (a pixel's
                    // samples four per vector), with sample counts that fill vectors of four and
                    // counts that do not.
                    for (const auto& [samples, pattern, aa] :
                         {std::tuple{1, mr::PatternKind::automatic, mr::AntiAliasing::ssaa},
                          std::tuple{4, mr::PatternKind::rotated, mr::AntiAliasing::ssaa},
                          std::tuple{6, mr::PatternKind::stratified, mr::AntiAliasing::ssaa},
                          std::tuple{8, mr::PatternKind::grid, mr::AntiAliasing::ssaa},
                          std::tuple{4, mr::PatternKind::rotated, mr::AntiAliasing::msaa},
                          std::tuple{8, mr::PatternKind::stratified, mr::AntiAliasing::msaa},
                          std::tuple{6, mr::PatternKind::stratified, mr::AntiAliasing::msaa}}) {
                        SCOPED_TRACE(mr::to_string(convention) + ", " + mr::to_string(blend) + ", " +
                                     mr::to_string(interpolation) + (skipping ? ", block skipping" : "") + ", " +
                                     std::to_string(samples) + " samples " + mr::to_string(aa));
                        auto s = settings(W, H, samples, pattern);
                        s.anti_aliasing = aa;
                        s.threads = 1;
                        s.block_skipping = skipping;
                        s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                        expect_same_with_and_without_rows(draws, cam, s);
                    }
                }
    }
}

// Small triangles (a few pixels, and slivers under 8 pixels wide but up to the viewport's height)
// at one sample a pixel take box_coverage_avx2 for their whole box, and under SSAA and MSAA
// box_sample_masks_avx2, and then only their covered pixels: the same bits and counters as the
// per-sample path, textured or not, flat, blended, with and without depth writes, block skipping
// and deferred shading (sample counts that are not a multiple of four keep the rows' path).
TEST(SampleRows, SmallTrianglesABoxAtATimeGiveThePerSampleBits) {
    const int W = 96, H = 80;
    mr::Mesh small = random_triangles(3000, 0.12, 51, {-1.5, -1.0, -2.0}, {3.0, 2.0, 5.0}, 0.5);
    mr::Mesh slivers = random_triangles(200, 3.0, 52, {-1.5, -1.0, -2.0}, {3.0, 2.0, 5.0}, 0.5);
    for (glm::vec3& p : slivers.positions) p.x /= 30.0f;  // (1/30 as wide as tall)
    const auto base = static_cast<std::uint32_t>(small.positions.size());
    small.positions.insert(small.positions.end(), slivers.positions.begin(), slivers.positions.end());
    small.colors.insert(small.colors.end(), slivers.colors.begin(), slivers.colors.end());
    for (const glm::uvec3& tri : slivers.triangles) small.triangles.push_back(tri + base);
    for (const glm::vec3& p : small.positions) small.uvs.push_back(glm::vec2(5.0f * p.x + p.z, 7.0f * p.y));
    const mr::Texture texture = checker_texture();
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        for (mr::BlendMode blend : {mr::BlendMode::replace, mr::BlendMode::over})
            for (bool skipping : {false, true})
                for (bool deferred : {false, true}) {
                    mr::DrawState tested;
                    tested.blend = blend;
                    mr::DrawState read_only = tested;
                    read_only.depth_write = false;
                    read_only.interpolation = mr::Interpolation::flat;
                    const glm::dmat4 identity(1.0);
                    std::vector<mr::Draw> draws = {make_draw(small, identity, tested),
                                                   make_draw(small, identity, tested, glm::vec4(0.3f, 0.8f, 0.5f, 1)),
                                                   make_draw(small, identity, read_only, glm::vec4(0.9f)),
                                                   make_draw(small, identity, no_depth(blend), glm::vec4(0.5f))};
                    draws[0].texture = texture;
                    for (const auto& [samples, pattern, aa] :
                         {std::tuple{1, mr::PatternKind::automatic, mr::AntiAliasing::ssaa},
                          std::tuple{4, mr::PatternKind::rotated, mr::AntiAliasing::ssaa},
                          std::tuple{6, mr::PatternKind::stratified, mr::AntiAliasing::ssaa},
                          std::tuple{16, mr::PatternKind::grid, mr::AntiAliasing::ssaa},
                          std::tuple{4, mr::PatternKind::rotated, mr::AntiAliasing::msaa},
                          std::tuple{8, mr::PatternKind::stratified, mr::AntiAliasing::msaa}}) {
                        SCOPED_TRACE(mr::to_string(convention) + ", " + mr::to_string(blend) +
                                     (skipping ? ", block skipping" : "") + (deferred ? ", deferred" : "") + ", " +
                                     std::to_string(samples) + " samples " + mr::to_string(aa));
                        auto s = settings(W, H, samples, pattern);
                        s.anti_aliasing = aa;
                        s.threads = 1;
                        s.block_skipping = skipping;
                        s.deferred_shading = deferred;
                        s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                        expect_same_with_and_without_rows(draws, cam, s);
                    }
                }
    }
}

TEST(SampleRows, AlphaTestedRowsGiveThePerSampleBits) {
    // An alpha-tested draw tests its long rows a vector at a time without writing depth, and writes
    // the depth and colour of what survives its alpha test afterwards: the per-sample path's bits
    // and counters, textured (the texture's alpha, half the squares below the cutoff) and
    // untextured (vertex alphas in [0.2, 1]), depth written or only read, drawn over opaque
    // triangles and under more; at one sample, SSAA and MSAA (pixel rows at 4 and 8 samples, the
    // per-sample path at 6).
    const int W = 96, H = 80;
    const mr::Mesh a = overlapping(150, 2.5, 44), b = overlapping(100, 1.5, 45);
    std::vector<float> texels;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const float alpha = (x / 2 + y / 2) % 2 ? 0.9f : 0.3f;
            texels.insert(texels.end(), {alpha * (x + 1) / 16.0f, alpha * (y + 1) / 16.0f, alpha * 0.5f, alpha});
        }
    const mr::Texture texture = mr::Texture::from_float(texels.data(), 16, 16, 4, true, "alpha checker");
    glm::dmat4 shifted(1.0);
    shifted[3] = glm::dvec4(0.2, 0.1, 0.5, 1.0);
    std::uint64_t discarded = 0;
    for (mr::DepthConvention convention : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const mr::Camera cam = overlap_camera(convention, W, H);
        for (bool depth_write : {true, false}) {
            const mr::DrawState masked = alpha_tested(0.6f, depth_write);
            std::vector<mr::Draw> draws = {make_draw(b, shifted, mr::DrawState()),
                                           make_draw(a, glm::dmat4(1.0), masked), make_draw(b, glm::dmat4(1.0), masked),
                                           make_draw(a, shifted, mr::DrawState(), glm::vec4(0.3f, 0.9f, 0.4f, 1.0f))};
            draws[1].texture = texture;
            for (const auto& [samples, pattern, aa] :
                 {std::tuple{1, mr::PatternKind::automatic, mr::AntiAliasing::ssaa},
                  std::tuple{4, mr::PatternKind::rotated, mr::AntiAliasing::ssaa},
                  std::tuple{4, mr::PatternKind::rotated, mr::AntiAliasing::msaa},
                  std::tuple{8, mr::PatternKind::stratified, mr::AntiAliasing::msaa},
                  std::tuple{6, mr::PatternKind::stratified, mr::AntiAliasing::msaa}}) {
                SCOPED_TRACE(mr::to_string(convention) + (depth_write ? ", depth written, " : ", depth read, ") +
                             std::to_string(samples) + " samples " + mr::to_string(aa));
                auto s = settings(W, H, samples, pattern);
                s.anti_aliasing = aa;
                s.threads = 1;
                s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                expect_same_with_and_without_rows(draws, cam, s);
                // (the alpha test discarded samples: shaded samples outnumber passed ones)
                const mr::RenderResult r = mr::render(draws, cam, s);
                if (aa == mr::AntiAliasing::ssaa) discarded += r.stats.shader_invocations - r.stats.samples_passed;
            }
        }
    }
    EXPECT_GT(discarded, 1000u);
}

// Untextured screen and perspective shading of a triangle whose three vertex colours are one
// colour takes that colour without the weighted sums (raster_tile's one_colour): flat shading's
// bits, the interpolation's exactly (a weighted sum clamped to [c, c]), at one sample, SSAA and
// MSAA, with and without sample rows and deferred shading. With a +0 or −0 channel the sums run
// (they can give the other signed zero): equal as numbers.
TEST(SampleRows, UntexturedOneColourTrianglesGiveFlatShadingsColour) {
    const int W = 96, H = 80;
    mr::Mesh tinted = overlapping(150, 2.5, 43), zeros = tinted;
    for (std::size_t v = 0; v < tinted.colors.size(); ++v) {
        tinted.colors[v] = tinted.colors[v - v % 3];  // (every channel of overlapping's colours > 0)
        zeros.colors[v] = tinted.colors[v];
        if (v / 3 % 4 == 1) zeros.colors[v].g = 0.0f;
        if (v / 3 % 4 == 2) zeros.colors[v].b = -0.0f;
    }
    for (const glm::vec4& c : tinted.colors)
        for (int k = 0; k < 4; ++k) ASSERT_GT(c[k], 0.0f);
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    for (const mr::Mesh* mesh : {&tinted, &zeros})
        for (mr::BlendMode blend : {mr::BlendMode::replace, mr::BlendMode::over})
            for (mr::Interpolation interpolation : {mr::Interpolation::perspective, mr::Interpolation::screen})
                for (const auto& [samples, aa] : {std::pair{1, mr::AntiAliasing::ssaa}, std::pair{4, mr::AntiAliasing::ssaa},
                                                  std::pair{4, mr::AntiAliasing::msaa}})
                    for (bool rows : {false, true})
                        for (bool deferred : {false, true}) {
                            SCOPED_TRACE(std::string(mesh == &zeros ? "zeros, " : "") + mr::to_string(blend) + ", " +
                                         mr::to_string(interpolation) + ", " + std::to_string(samples) + " samples " +
                                         mr::to_string(aa) + (rows ? ", rows" : "") + (deferred ? ", deferred" : ""));
                            mr::DrawState state;
                            state.blend = blend;
                            state.interpolation = interpolation;
                            mr::DrawState flat = state;
                            flat.interpolation = mr::Interpolation::flat;
                            auto s = settings(W, H, samples);
                            s.anti_aliasing = aa;
                            s.sample_rows = rows;
                            s.deferred_shading = deferred;
                            s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                            const glm::vec4 tint(0.9f, 0.7f, 1.0f, 0.8f);
                            const mr::RenderResult got = mr::render({make_draw(*mesh, glm::dmat4(1.0), state, tint)}, cam, s);
                            const mr::RenderResult want = mr::render({make_draw(*mesh, glm::dmat4(1.0), flat, tint)}, cam, s);
                            EXPECT_GT(got.stats.samples_passed, 0u);
                            if (mesh == &tinted) {
                                expect_same_render(got, want);
                            } else {
                                EXPECT_EQ(got.color.pixels, want.color.pixels);
                                EXPECT_EQ(got.framebuffer.color, want.framebuffer.color);
                            }
                        }
}

TEST(SampleRows, SamplesOnEdgesFollowTheTopLeftRule) {
    // A grid of 8×8-pixel squares, each cut along a diagonal, with every vertex on a pixel centre:
    // the edges run through sample positions, so which triangle gets them is the top-left rule's
    // choice alone. Every sample is covered exactly once, and the images agree.
    const int W = 64, H = 64;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> u(0.2f, 1.0f);
    mr::Mesh grid;
    constexpr std::uint32_t kCells = 9;  // from the pixel centre at −0.5 px to 71.5 px, past the viewport
    for (std::uint32_t y = 0; y <= kCells; ++y)
        for (std::uint32_t x = 0; x <= kCells; ++x) {
            // 1/256 px through fixed_to_ndc
            grid.positions.push_back(glm::vec3(float((8.0 * x - 1.0) * 256.0 + 128.0), float((8.0 * y - 1.0) * 256.0 + 128.0), 0.5f));
            grid.colors.push_back(glm::vec4(u(rng), u(rng), u(rng), 1.0f));
        }
    for (std::uint32_t y = 0; y < kCells; ++y)
        for (std::uint32_t x = 0; x < kCells; ++x) {
            const std::uint32_t v = (kCells + 1) * y + x, below = v + kCells + 1;
            if ((x + y) % 2) {
                add_triangle(grid, v, v + 1, below + 1);
                add_triangle(grid, v, below + 1, below);
            } else {
                add_triangle(grid, v, v + 1, below);
                add_triangle(grid, v + 1, below + 1, below);
            }
        }
    mr::DrawState state;
    state.interpolation = mr::Interpolation::screen;
    auto s = settings(W, H, 1);
    s.threads = 1;
    const std::vector<mr::Draw> draws = {make_draw(grid, fixed_to_ndc(W, H), state)};
    expect_same_with_and_without_rows(draws, identity_camera(), s);
    EXPECT_EQ(mr::render(draws, identity_camera(), s).stats.samples_covered, std::uint64_t(W) * H);
}

TEST(SampleRows, TrianglesWithEdgeValuesPast2To52GiveThePerSampleBits) {
    // Triangles reaching the guard band (~10^6 px) that cover the whole viewport: at its pixels
    // their edge values are ~2^55, past the 2^52 below which the rows' sums are exact (the rows
    // fall back to the per-sample path there). Tilted in depth, drawn nearer one after the other
    // with screen-space colours, so every weight shows in the image.
    const int W = 64, H = 48;
    const mr::Camera cam = identity_camera();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    mr::Mesh big;
    for (std::uint32_t t = 0; t < 12; ++t) {
        const double reach = 15000.0;  // NDC units: 15000 × 32 px
        const float z = 0.9f - 0.05f * float(t);
        big.positions.push_back(glm::vec3(float(reach * (-0.9 + 0.1 * u(rng))), float(reach * (-0.9 + 0.1 * u(rng))), z));
        big.positions.push_back(glm::vec3(float(reach * (0.9 + 0.1 * u(rng))), float(reach * (-0.9 + 0.1 * u(rng))), z - 0.3f));
        big.positions.push_back(glm::vec3(float(reach * 0.2 * u(rng)), float(reach * (0.9 + 0.1 * u(rng))), z + 0.05f));
        for (int i = 0; i < 3; ++i)
            big.colors.push_back(glm::vec4(float(0.5 + 0.5 * u(rng)), float(0.5 + 0.5 * u(rng)), float(0.5 + 0.5 * u(rng)), 1.0f));
        add_triangle(big, 3 * t, 3 * t + 1, 3 * t + 2);
    }
    mr::DrawState state;
    state.interpolation = mr::Interpolation::screen;
    for (int samples : {1, 4}) {  // (SSAA: a row falls back whole when any sample's row would round)
        auto s = settings(W, H, samples);
        s.threads = 1;
        expect_same_with_and_without_rows({make_draw(big, glm::dmat4(1.0), state)}, cam, s);
    }
}

// The row test itself, on random triangles, rows, stored depths and masks, with depths one float
// apart (one sample per pixel) or S apart (SSAA), against the per-sample arithmetic written out
// here (exact integer edge values, screen_weights, sample_depth, a strict test): both vector
// widths give its coverage, outcomes, weights and stored depths bit for bit, touch no other
// sample, and refuse the rows whose edge values reach 2^52. Without AVX2 only the SSE2 path runs.
// A random triangle about a 96×80 viewport, set up (false: setup refused it). Every other trial
// has its vertices on pixel centres, so that its edges run through samples (the top-left rule
// decides those).
bool random_row_triangle(std::mt19937_64& rng, int trial, mr::SetupTriangle& t) {
    const mr::Viewport viewport{96, 80, mr::DepthConvention::reverse_z};
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::array<mr::ScreenVertex, 3> v;
    for (auto& vertex : v) {
        const int px = static_cast<int>(rng() % 120) - 12, py = static_cast<int>(rng() % 104) - 12;
        const int jitter = trial % 2 ? static_cast<int>(rng() % 256) - 128 : 0;
        vertex = {static_cast<std::int32_t>(px * mr::kSubpixelOne + 128 + jitter),
                  static_cast<std::int32_t>(py * mr::kSubpixelOne + 128 - jitter), 0.3 + 2.0 * unit(rng), unit(rng),
                  0.0f, 0.0f};  // (on the grid already: not moved by snapping)
    }
    mr::SetupCounters counters;
    return mr::setup_triangle(v, viewport, mr::CullMode::none, t, counters);
}

// The bits of a float or double.
template <typename T>
std::uint64_t bits(T x) {
    std::uint64_t b = 0;
    std::memcpy(&b, &x, sizeof x);
    return b;
}

TEST(SampleRows, BothVectorWidthsGiveThePerSampleArithmeticOnRandomRows) {
    const bool avx2 = __builtin_cpu_supports("avx2");
    std::mt19937_64 rng(61);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    long rows = 0, refused = 0, passed_pixels = 0, near_bound = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        mr::SetupTriangle t;
        if (!random_row_triangle(rng, trial, t)) continue;
        const int y = t.min_y + static_cast<int>(rng() % static_cast<unsigned>(t.max_y - t.min_y + 1));
        const int x0 = t.min_x - 2 + static_cast<int>(rng() % static_cast<unsigned>(t.max_x - t.min_x + 3));
        const int n = 1 + static_cast<int>(rng() % mr::kTileSize);
        std::int64_t e[3];
        const std::int64_t X = std::int64_t{x0} * mr::kSubpixelOne + 128, Y = std::int64_t{y} * mr::kSubpixelOne + 128;
        for (int i = 0; i < 3; ++i) e[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
        if (trial % 50 == 0) e[trial % 3] += (std::int64_t{1} << 52) * (trial % 100 == 0 ? 1 : -1);  // refused
        if (trial % 50 == 25)  // 2^50 to 2^52 + 2^50: taken whole or not, refused or not
            e[trial % 3] += ((std::int64_t{1} << 50) + static_cast<std::int64_t>(rng() % (std::uint64_t{1} << 52))) *
                            (trial % 100 == 25 ? 1 : -1);
        const std::uint32_t tested = static_cast<std::uint32_t>(rng());
        // (none: every covered pixel of `tested` passes, depth neither read nor written)
        const mr::DepthFunc func =
            std::array{mr::DepthFunc::greater, mr::DepthFunc::less, mr::DepthFunc::none}[rng() % 3];
        const bool depth_write = rng() % 2;
        const int stride = std::array<int, 4>{1, 1, 4, 5}[trial % 4];  // one sample per pixel, or one of S

        // The per-sample reference, pixel by pixel.
        bool exact = true;
        for (int i = 0; i < 3; ++i)
            for (int j : {0, n - 1}) {
                const std::int64_t v = e[i] + t.bias[i] + std::int64_t{t.edge_a[i]} * mr::kSubpixelOne * j;
                exact = exact && std::abs(v) < (std::int64_t{1} << 52);
            }
        // The kernel's test for a whole row, at the pixel corners: it promises every sample's row,
        // any offset from the corner (here the centre's) is taken.
        const std::int64_t corner[3] = {e[0] - 128 * std::int64_t{t.edge_a[0] + t.edge_b[0]},
                                        e[1] - 128 * std::int64_t{t.edge_a[1] + t.edge_b[1]},
                                        e[2] - 128 * std::int64_t{t.edge_a[2] + t.edge_b[2]}};
        if (mr::kernels::sample_rows_exact(t, corner, n)) {
            ASSERT_TRUE(exact) << "trial " << trial;
            near_bound += trial % 50 == 25;
        }
        float stored[mr::kTileSize], want_depth[mr::kTileSize];
        std::uint32_t want_covered = 0, want_passed = 0;
        double want_l[3][mr::kTileSize] = {};
        for (int j = 0; j < n; ++j) {
            const std::int64_t E[3] = {e[0] + std::int64_t{t.edge_a[0]} * mr::kSubpixelOne * j,
                                       e[1] + std::int64_t{t.edge_a[1]} * mr::kSubpixelOne * j,
                                       e[2] + std::int64_t{t.edge_a[2]} * mr::kSubpixelOne * j};
            const glm::dvec3 l = mr::screen_weights(t, E[0], E[1], E[2]);
            const float z = mr::sample_depth(t, l);
            const int kind = static_cast<int>(rng() % 4);  // a tie, a random depth, or either end
            stored[j] = kind == 0 ? z : kind == 1 ? float(unit(rng)) : kind == 2 ? 0.0f : 1.0f;
            want_depth[j] = stored[j];
            if ((E[0] | E[1] | E[2]) < 0) continue;
            want_covered |= 1u << j;
            const bool wins = func == mr::DepthFunc::none ||
                              (func == mr::DepthFunc::greater ? z > stored[j] : z < stored[j]);
            if (!(tested >> j & 1) || !wins) continue;
            want_passed |= 1u << j;
            want_l[0][j] = l.x, want_l[1][j] = l.y, want_l[2][j] = l.z;
            if (depth_write && func != mr::DepthFunc::none) want_depth[j] = z;
        }

        const auto check = [&](const char* path, auto row_test) {
            // The row's depths `stride` apart; the samples between them (−1, never a depth here)
            // must stay as they are.
            std::vector<float> depth(static_cast<std::size_t>(n * stride), -1.0f);
            for (int j = 0; j < n; ++j) depth[static_cast<std::size_t>(j * stride)] = stored[j];
            const std::vector<float> before = depth;
            mr::kernels::SampleRow out;
            for (double* l : {out.l0, out.l1, out.l2}) std::fill(l, l + mr::kTileSize, std::nan(""));
            const bool ran = row_test(t, e, n, tested, func, depth_write, depth.data(), stride, out);
            ASSERT_EQ(ran, exact) << path << " trial " << trial;
            for (std::size_t k = 0; k < depth.size(); ++k) {
                if (!ran || k % static_cast<std::size_t>(stride) != 0) {
                    ASSERT_EQ(bits(depth[k]), bits(before[k])) << path << " trial " << trial << " touched " << k;
                }
            }
            if (!ran) return;
            ASSERT_EQ(out.covered, want_covered) << path << " trial " << trial;
            ASSERT_EQ(out.passed, want_passed) << path << " trial " << trial;
            for (int j = 0; j < n; ++j) {
                ASSERT_EQ(bits(depth[static_cast<std::size_t>(j * stride)]), bits(want_depth[j]))
                    << path << " trial " << trial << " stride " << stride << " pixel " << j;
                if (!(want_passed >> j & 1)) continue;
                ASSERT_EQ(bits(out.l0[j]), bits(want_l[0][j])) << path << " trial " << trial << " pixel " << j;
                ASSERT_EQ(bits(out.l1[j]), bits(want_l[1][j])) << path << " trial " << trial << " pixel " << j;
                ASSERT_EQ(bits(out.l2[j]), bits(want_l[2][j])) << path << " trial " << trial << " pixel " << j;
            }
        };
        check("sse2", mr::kernels::test_sample_row_sse2);
        if (avx2) check("avx2", mr::kernels::test_sample_row_avx2);
        // sample_row_weights: screen_weights' bits at every pixel of the row, covered or not.
        const auto check_weights = [&](const char* path, auto row_weights) {
            double l[3][mr::kTileSize];
            ASSERT_EQ(row_weights(t, e, n, l[0], l[1], l[2]), exact) << path << " trial " << trial;
            for (int j = 0; exact && j < n; ++j) {
                const glm::dvec3 want =
                    mr::screen_weights(t, e[0] + std::int64_t{t.edge_a[0]} * mr::kSubpixelOne * j,
                                       e[1] + std::int64_t{t.edge_a[1]} * mr::kSubpixelOne * j,
                                       e[2] + std::int64_t{t.edge_a[2]} * mr::kSubpixelOne * j);
                for (int i = 0; i < 3; ++i)
                    ASSERT_EQ(bits(l[i][j]), bits(want[i])) << path << " weights, trial " << trial << " pixel " << j;
            }
        };
        check_weights("sse2", mr::kernels::sample_row_weights_sse2);
        if (avx2) check_weights("avx2", mr::kernels::sample_row_weights_avx2);
        ++rows;
        refused += !exact;
        passed_pixels += __builtin_popcount(want_passed);
    }
    std::cout << "rows " << rows << " (refused " << refused << "), passed pixels " << passed_pixels
              << ", rows taken whole near 2^51 " << near_bound
              << (avx2 ? "" : "; this CPU has no AVX2: only the SSE2 path ran") << "\n";
    EXPECT_GE(rows, 15000);
    EXPECT_GE(refused, 200);
    EXPECT_GE(near_bound, 40);
    EXPECT_GE(passed_pixels, 12000);
}

// test_pixel_row_avx2 (MSAA rows, a pixel's samples four per vector) against the per-sample
// arithmetic: coverage from the exact integer edge values, sample_depth(screen_weights(...)) for the
// test, ties failing. Sample 0 is the pixel centre, through which half the triangles' edges run.
// SSAA's samples four at a time (test_four_sample_rows_avx2: four of a pixel's 4, 8 or 16
// depths side by side) against four rows of the SSE2 path (checked against the per-sample
// arithmetic above), one per sample, on the same depths: the same refusals, masks, weights and
// every depth bit, the pixel's other samples and the next pixel untouched.
TEST(SampleRows, FourSampleRowsAreFourSingleSampleRows) {
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this CPU has no AVX2";
    std::mt19937_64 rng(62);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    long rows = 0, refused = 0, passed_samples = 0, partly_passed = 0;
    for (int trial = 0; trial < 12000; ++trial) {
        mr::SetupTriangle t;
        if (!random_row_triangle(rng, trial, t)) continue;
        const int y = t.min_y + static_cast<int>(rng() % static_cast<unsigned>(t.max_y - t.min_y + 1));
        const int x0 = t.min_x - 2 + static_cast<int>(rng() % static_cast<unsigned>(t.max_x - t.min_x + 3));
        const int n = 1 + static_cast<int>(rng() % mr::kTileSize);
        std::int64_t e[4][3];
        for (int s = 0; s < 4; ++s) {
            const std::int64_t X = std::int64_t{x0} * mr::kSubpixelOne + static_cast<std::int64_t>(rng() % 256);
            const std::int64_t Y = std::int64_t{y} * mr::kSubpixelOne + static_cast<std::int64_t>(rng() % 256);
            for (int i = 0; i < 3; ++i) e[s][i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
        }
        if (trial % 40 == 0) e[trial % 4][trial % 3] += std::int64_t{1} << 52;  // one sample's row refused
        const std::uint32_t tested = static_cast<std::uint32_t>(rng());
        const mr::DepthFunc func = rng() % 2 ? mr::DepthFunc::greater : mr::DepthFunc::less;
        const bool depth_write = rng() % 2;
        const int stride = std::array<int, 3>{4, 8, 16}[trial % 3];     // the pixel's samples
        const int first = 4 * static_cast<int>(rng() % static_cast<unsigned>(stride / 4));  // the four's first
        std::vector<float> depth(static_cast<std::size_t>((n + 1) * stride), -1.0f);  // (one pixel past the row)
        for (int j = 0; j < n; ++j)
            for (int s = 0; s < 4; ++s) {
                const int kind = static_cast<int>(rng() % 3);
                depth[static_cast<std::size_t>(j * stride + first + s)] =
                    kind == 0 ? float(unit(rng)) : kind == 1 ? 0.0f : 1.0f;
            }
        // Ties: some stored depths are the sample's own.
        for (int j = 0; j < n; ++j)
            for (int s = 0; s < 4; ++s)
                if (rng() % 4 == 0) {
                    const std::int64_t step = mr::kSubpixelOne * j;
                    const glm::dvec3 l = mr::screen_weights(t, e[s][0] + std::int64_t{t.edge_a[0]} * step,
                                                            e[s][1] + std::int64_t{t.edge_a[1]} * step,
                                                            e[s][2] + std::int64_t{t.edge_a[2]} * step);
                    depth[static_cast<std::size_t>(j * stride + first + s)] = mr::sample_depth(t, l);
                }
        std::vector<float> want_depth = depth;
        mr::kernels::SampleRow want[4], got[4];
        std::vector<float> scratch = depth;
        bool each_ran = true;
        for (int s = 0; s < 4; ++s)
            each_ran = mr::kernels::test_sample_row_sse2(t, e[s], n, tested, func, depth_write,
                                                         scratch.data() + first + s, stride, want[s]) && each_ran;
        if (each_ran) want_depth = scratch;
        for (mr::kernels::SampleRow& row : got)
            for (double* l : {row.l0, row.l1, row.l2}) std::fill(l, l + mr::kTileSize, std::nan(""));
        std::vector<float> got_depth = depth;
        const bool ran = mr::kernels::test_four_sample_rows_avx2(t, e, n, tested, func, depth_write,
                                                                 got_depth.data() + first, stride, got);
        ASSERT_EQ(ran, each_ran) << "trial " << trial;
        for (std::size_t k = 0; k < depth.size(); ++k)
            ASSERT_EQ(bits(got_depth[k]), bits(ran ? want_depth[k] : depth[k])) << "trial " << trial << " depth " << k;
        ++rows;
        if (!ran) {
            ++refused;
            continue;
        }
        int samples = 0;
        for (int s = 0; s < 4; ++s) {
            ASSERT_EQ(got[s].covered, want[s].covered) << "trial " << trial << " sample " << s;
            ASSERT_EQ(got[s].passed, want[s].passed) << "trial " << trial << " sample " << s;
            for (int j = 0; j < n; ++j) {
                if (!(want[s].passed >> j & 1)) continue;
                ASSERT_EQ(bits(got[s].l0[j]), bits(want[s].l0[j])) << "trial " << trial << " sample " << s;
                ASSERT_EQ(bits(got[s].l1[j]), bits(want[s].l1[j])) << "trial " << trial << " sample " << s;
                ASSERT_EQ(bits(got[s].l2[j]), bits(want[s].l2[j])) << "trial " << trial << " sample " << s;
            }
            samples += __builtin_popcount(want[s].passed);
        }
        passed_samples += samples;
        partly_passed += samples > 0 && samples < 4 * n;
    }
    std::cout << "rows " << rows << " (refused " << refused << "), passed samples " << passed_samples
              << ", rows partly passed " << partly_passed << "\n";
    EXPECT_GE(rows, 8000);
    EXPECT_GE(refused, 100);
    EXPECT_GE(partly_passed, 2000);
}

TEST(SampleRows, PixelRowsGiveThePerSampleArithmeticOnRandomRows) {
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this CPU has no AVX2, which test_pixel_row_avx2 needs";
    std::mt19937_64 rng(62);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    long rows = 0, on_edges = 0, passed_samples = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        mr::SetupTriangle t;
        if (!random_row_triangle(rng, trial, t)) continue;
        const int S = trial % 3 == 0 ? 8 : 4;
        std::int64_t ox[8], oy[8];
        double offsets[3][8];
        for (int s = 0; s < S; ++s) {
            ox[s] = s == 0 ? 128 : static_cast<std::int64_t>(rng() % 256);
            oy[s] = s == 0 ? 128 : static_cast<std::int64_t>(rng() % 256);
            for (int i = 0; i < 3; ++i)
                offsets[i][s] = static_cast<double>(std::int64_t{t.edge_a[i]} * ox[s] + t.edge_b[i] * oy[s]);
        }
        const int y = t.min_y + static_cast<int>(rng() % static_cast<unsigned>(t.max_y - t.min_y + 1));
        const int x0 = t.min_x - 2 + static_cast<int>(rng() % static_cast<unsigned>(t.max_x - t.min_x + 3));
        const int n = 1 + static_cast<int>(rng() % mr::kTileSize);
        std::int64_t corner[3];
        const std::int64_t X = std::int64_t{x0} * mr::kSubpixelOne, Y = std::int64_t{y} * mr::kSubpixelOne;
        for (int i = 0; i < 3; ++i) corner[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
        ASSERT_TRUE(mr::kernels::sample_rows_exact(t, corner, n)) << "trial " << trial;
        const mr::DepthFunc func = rng() % 2 ? mr::DepthFunc::greater : mr::DepthFunc::less;
        const bool depth_write = rng() % 2;

        // The per-sample reference.
        std::vector<float> depth(static_cast<std::size_t>(n * S)), want_depth, want_tested(depth.size());
        std::vector<char> want_covered_at(depth.size());
        std::uint64_t want_covered = 0, want_samples[mr::kTileSize] = {};
        for (int j = 0; j < n; ++j)
            for (int s = 0; s < S; ++s) {
                std::int64_t E[3];
                for (int i = 0; i < 3; ++i)
                    E[i] = corner[i] + std::int64_t{t.edge_a[i]} * (mr::kSubpixelOne * j + ox[s]) +
                           std::int64_t{t.edge_b[i]} * oy[s];
                const float z = mr::sample_depth(t, mr::screen_weights(t, E[0], E[1], E[2]));
                const int kind = static_cast<int>(rng() % 4);  // a tie, a random depth, or either end
                float& stored = depth[static_cast<std::size_t>(j * S + s)];
                stored = kind == 0 ? z : kind == 1 ? float(unit(rng)) : kind == 2 ? 0.0f : 1.0f;
                on_edges += E[0] == 0 || E[1] == 0 || E[2] == 0;
                if ((E[0] | E[1] | E[2]) < 0) continue;
                ++want_covered;
                want_covered_at[static_cast<std::size_t>(j * S + s)] = 1;
                want_tested[static_cast<std::size_t>(j * S + s)] = z;
                if (!(func == mr::DepthFunc::greater ? z > stored : z < stored)) continue;
                want_samples[j] |= std::uint64_t{1} << s;
            }
        want_depth = depth;
        for (int j = 0; j < n; ++j)
            for (int s = 0; s < S; ++s)
                if (depth_write && (want_samples[j] >> s & 1)) {
                    std::int64_t E[3];
                    for (int i = 0; i < 3; ++i)
                        E[i] = corner[i] + std::int64_t{t.edge_a[i]} * (mr::kSubpixelOne * j + ox[s]) +
                               std::int64_t{t.edge_b[i]} * oy[s];
                    const glm::dvec3 l = mr::screen_weights(t, E[0], E[1], E[2]);
                    want_depth[static_cast<std::size_t>(j * S + s)] = mr::sample_depth(t, l);
                }

        std::uint64_t samples[mr::kTileSize];
        std::vector<float> tested(static_cast<std::size_t>(n * S), -1.0f);
        const double* const offset_rows[3] = {offsets[0], offsets[1], offsets[2]};
        const bool keep_tested = trial % 2 == 0;
        const mr::kernels::PixelRowTest found =
            mr::kernels::test_pixel_row_avx2(t, corner, n, offset_rows, S, func, depth_write, depth.data(), samples,
                                             keep_tested ? tested.data() : nullptr);
        ASSERT_EQ(found.covered, want_covered) << "trial " << trial;
        std::uint64_t want_passed = 0;
        std::uint32_t want_pixels = 0;
        for (int j = 0; j < n; ++j) {
            ASSERT_EQ(samples[j], want_samples[j]) << "trial " << trial << " pixel " << j;
            want_passed += static_cast<std::uint64_t>(__builtin_popcountll(want_samples[j]));
            want_pixels |= static_cast<std::uint32_t>(want_samples[j] != 0) << j;
            for (int s = 0; s < S; ++s) {
                const auto k = static_cast<std::size_t>(j * S + s);
                ASSERT_EQ(bits(depth[k]), bits(want_depth[k]))
                    << "trial " << trial << " pixel " << j << " sample " << s;
                if (!keep_tested || (want_covered_at[k] == 0)) continue;
                ASSERT_EQ(bits(tested[k]), bits(want_tested[k]))
                    << "trial " << trial << " pixel " << j << " sample " << s << " (tested depth)";
            }
        }
        ASSERT_EQ(found.passed, want_passed) << "trial " << trial;
        ASSERT_EQ(found.pixels, want_pixels) << "trial " << trial;
        ++rows;
        for (int j = 0; j < n; ++j) passed_samples += __builtin_popcountll(want_samples[j]);
    }
    std::cout << "rows " << rows << ", samples on an edge " << on_edges << ", passed samples " << passed_samples
              << "\n";
    EXPECT_GE(rows, 15000);
    EXPECT_GE(on_edges, 200);
    EXPECT_GE(passed_samples, 50000);
}

// Edge offsets off[e][s] = a_e·x + b_e·y of S random sample positions in a pixel's 256 subpixel
// steps, sample 0 at the pixel centre (through which half of random_row_triangle's edges run).
void random_sample_offsets(std::mt19937_64& rng, const mr::SetupTriangle& t, int S, std::int64_t (&off)[3][16]) {
    for (int s = 0; s < S; ++s) {
        const std::int64_t ox = s == 0 ? 128 : static_cast<std::int64_t>(rng() % 256);
        const std::int64_t oy = s == 0 ? 128 : static_cast<std::int64_t>(rng() % 256);
        for (int i = 0; i < 3; ++i) off[i][s] = std::int64_t{t.edge_a[i]} * ox + std::int64_t{t.edge_b[i]} * oy;
    }
}

// pixel_coverage_avx2 (MSAA and SSAA rows' coverage masks, four samples per vector) against the
// exact per-sample test: all three integer edge values ≥ 0. Rows start left of the triangle and
// run past it; sample 0 is the pixel centre, through which half the triangles' edges run, so
// edge values of exactly 0 (inside by the top-left bias) and −1 (outside) are common.
TEST(SampleRows, CoverageMasksFourSamplesPerVectorAreTheExactPerSampleTest) {
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this CPU has no AVX2, which pixel_coverage_avx2 needs";
    std::mt19937_64 rng(63);
    long rows = 0, on_edges = 0, inside = 0, outside = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        mr::SetupTriangle t;
        if (!random_row_triangle(rng, trial, t)) continue;
        const int S = std::array<int, 4>{4, 4, 8, 16}[trial % 4];
        std::int64_t off[3][16];
        random_sample_offsets(rng, t, S, off);
        const int y = t.min_y + static_cast<int>(rng() % static_cast<unsigned>(t.max_y - t.min_y + 1));
        const int x0 = t.min_x - 2 + static_cast<int>(rng() % static_cast<unsigned>(t.max_x - t.min_x + 3));
        const int n = 1 + static_cast<int>(rng() % mr::kTileSize);
        std::int64_t corner[3], step[3];
        const std::int64_t X = std::int64_t{x0} * mr::kSubpixelOne, Y = std::int64_t{y} * mr::kSubpixelOne;
        for (int i = 0; i < 3; ++i) {
            corner[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
            step[i] = std::int64_t{t.edge_a[i]} * mr::kSubpixelOne;
        }
        std::uint64_t mask[mr::kTileSize];
        mr::kernels::pixel_coverage_avx2(corner, {off[0], off[1], off[2]}, step, n, S, mask);
        for (int j = 0; j < n; ++j) {
            std::uint64_t want = 0;
            for (int s = 0; s < S; ++s) {
                std::int64_t E[3];
                for (int i = 0; i < 3; ++i) E[i] = corner[i] + j * step[i] + off[i][s];
                on_edges += E[0] == 0 || E[1] == 0 || E[2] == 0;
                if (E[0] >= 0 && E[1] >= 0 && E[2] >= 0) want |= std::uint64_t{1} << s;
            }
            ASSERT_EQ(mask[j], want) << "trial " << trial << " pixel " << j << " of " << n << ", " << S << " samples";
            inside += __builtin_popcountll(want);
            outside += S - __builtin_popcountll(want);
        }
        ++rows;
    }
    std::cout << "rows " << rows << ", samples on an edge " << on_edges << ", inside " << inside << ", outside "
              << outside << "\n";
    EXPECT_GE(rows, 15000);
    EXPECT_GE(on_edges, 200);
    EXPECT_GE(inside, 50000);
    EXPECT_GE(outside, 50000);
}

// box_coverage_avx2 (small triangles at one sample a pixel: a box of up to 8 pixels by up to a
// tile's rows at once) and row_coverage_avx2 (MSAA rows' pixel centres: up to a tile's width)
// against the exact test at each pixel's centre: all three integer edge values ≥ 0. Boxes start
// left of and above the triangle and run past it; half the triangles' edges run through pixel
// centres (edge values of exactly 0 and −1 are common).
TEST(SampleRows, BoxAndRowCoverageAreTheExactPerPixelTest) {
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this CPU has no AVX2, which box_coverage_avx2 needs";
    std::mt19937_64 rng(64);
    long boxes = 0, on_edges = 0, inside = 0, outside = 0, row_inside = 0, row_outside = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        mr::SetupTriangle t;
        if (!random_row_triangle(rng, trial, t)) continue;
        const int x0 = t.min_x - 2 + static_cast<int>(rng() % static_cast<unsigned>(t.max_x - t.min_x + 3));
        const int y0 = t.min_y - 2 + static_cast<int>(rng() % static_cast<unsigned>(t.max_y - t.min_y + 3));
        const int n = 1 + static_cast<int>(rng() % 8), rows = 1 + static_cast<int>(rng() % mr::kTileSize);
        const std::int64_t X = std::int64_t{x0} * mr::kSubpixelOne, Y = std::int64_t{y0} * mr::kSubpixelOne;
        const std::int64_t half = mr::kSubpixelOne / 2;
        std::int64_t first[3], step_x[3], step_y[3];
        for (int i = 0; i < 3; ++i) {
            first[i] = t.edge_a[i] * (X + half) + t.edge_b[i] * (Y + half) + t.edge_c[i];
            step_x[i] = std::int64_t{t.edge_a[i]} * mr::kSubpixelOne;
            step_y[i] = std::int64_t{t.edge_b[i]} * mr::kSubpixelOne;
        }
        std::uint8_t cover[mr::kTileSize];
        const std::uint32_t any = mr::kernels::box_coverage_avx2(first, step_x, step_y, n, rows, cover);
        std::uint32_t want_any = 0;
        for (int r = 0; r < rows; ++r) {
            std::uint32_t want = 0;
            for (int j = 0; j < n; ++j) {
                std::int64_t E[3];
                for (int i = 0; i < 3; ++i)
                    E[i] = t.edge_a[i] * (X + j * mr::kSubpixelOne + half) +
                           t.edge_b[i] * (Y + r * mr::kSubpixelOne + half) + t.edge_c[i];
                on_edges += E[0] == 0 || E[1] == 0 || E[2] == 0;
                if (E[0] >= 0 && E[1] >= 0 && E[2] >= 0) want |= 1u << j;
            }
            ASSERT_EQ(cover[r], want) << "trial " << trial << " row " << r << " of " << rows << ", " << n << " pixels";
            want_any |= want;
            inside += __builtin_popcount(want);
            outside += n - __builtin_popcount(want);
        }
        ASSERT_EQ(any, want_any) << "trial " << trial;
        // row_coverage_avx2 along the box's first row, up to a tile's width.
        const int length = 1 + static_cast<int>(rng() % mr::kTileSize);
        std::uint32_t want_row = 0;
        for (int j = 0; j < length; ++j) {
            std::int64_t E[3];
            for (int i = 0; i < 3; ++i) E[i] = first[i] + j * step_x[i];
            if (E[0] >= 0 && E[1] >= 0 && E[2] >= 0) want_row |= 1u << j;
        }
        ASSERT_EQ(mr::kernels::row_coverage_avx2(first, step_x, length), want_row)
            << "trial " << trial << ", " << length << " pixels";
        row_inside += __builtin_popcount(want_row);
        row_outside += length - __builtin_popcount(want_row);
        ++boxes;
    }
    std::cout << "boxes " << boxes << ", pixels on an edge " << on_edges << ", inside " << inside << ", outside "
              << outside << "; rows: inside " << row_inside << ", outside " << row_outside << "\n";
    EXPECT_GE(boxes, 15000);
    EXPECT_GE(on_edges, 200);
    EXPECT_GE(inside, 50000);
    EXPECT_GE(outside, 50000);
    EXPECT_GE(row_inside, 50000);
    EXPECT_GE(row_outside, 50000);
}

// box_sample_masks_avx2 (small triangles under SSAA and MSAA: every sample mask of a box of up to
// 8 pixels by up to a tile's rows at once) against the exact per-sample test: all three integer
// edge values ≥ 0. Boxes start left of and above the triangle and run past it; sample 0 is the
// pixel centre, through which half the triangles' edges run (edge values of exactly 0 and −1 are
// common).
TEST(SampleRows, BoxSampleMasksAreTheExactPerSampleTest) {
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this CPU has no AVX2, which box_sample_masks_avx2 needs";
    std::mt19937_64 rng(66);
    long boxes = 0, on_edges = 0, inside = 0, outside = 0;
    for (int trial = 0; trial < 10000; ++trial) {
        mr::SetupTriangle t;
        if (!random_row_triangle(rng, trial, t)) continue;
        const int S = std::array<int, 4>{4, 4, 8, 16}[trial % 4];
        std::int64_t off[3][16];
        random_sample_offsets(rng, t, S, off);
        const int x0 = t.min_x - 2 + static_cast<int>(rng() % static_cast<unsigned>(t.max_x - t.min_x + 3));
        const int y0 = t.min_y - 2 + static_cast<int>(rng() % static_cast<unsigned>(t.max_y - t.min_y + 3));
        const int n = 1 + static_cast<int>(rng() % mr::kernels::kBoxPixels);
        const int rows = 1 + static_cast<int>(rng() % mr::kTileSize);
        const std::int64_t X = std::int64_t{x0} * mr::kSubpixelOne, Y = std::int64_t{y0} * mr::kSubpixelOne;
        std::int64_t corner[3], step_x[3], step_y[3];
        for (int i = 0; i < 3; ++i) {
            corner[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
            step_x[i] = std::int64_t{t.edge_a[i]} * mr::kSubpixelOne;
            step_y[i] = std::int64_t{t.edge_b[i]} * mr::kSubpixelOne;
        }
        std::uint64_t mask[mr::kTileSize][mr::kernels::kBoxPixels];
        std::uint8_t pixels[mr::kTileSize];
        const std::uint32_t any = mr::kernels::box_sample_masks_avx2(corner, {off[0], off[1], off[2]}, step_x, step_y,
                                                                     n, rows, S, mask, pixels);
        std::uint32_t want_any = 0;
        for (int r = 0; r < rows; ++r) {
            std::uint32_t want_pixels = 0;
            for (int j = 0; j < n; ++j) {
                std::uint64_t want = 0;
                for (int s = 0; s < S; ++s) {
                    std::int64_t E[3];
                    for (int i = 0; i < 3; ++i)
                        E[i] = t.edge_a[i] * (X + j * mr::kSubpixelOne) + t.edge_b[i] * (Y + r * mr::kSubpixelOne) +
                               t.edge_c[i] + off[i][s];
                    on_edges += E[0] == 0 || E[1] == 0 || E[2] == 0;
                    if (E[0] >= 0 && E[1] >= 0 && E[2] >= 0) want |= std::uint64_t{1} << s;
                }
                ASSERT_EQ(mask[r][j], want) << "trial " << trial << " row " << r << " pixel " << j << ", " << S
                                            << " samples";
                if (want) want_pixels |= 1u << j;
                inside += __builtin_popcountll(want);
                outside += S - __builtin_popcountll(want);
            }
            ASSERT_EQ(pixels[r], want_pixels) << "trial " << trial << " row " << r;
            want_any |= want_pixels;
        }
        ASSERT_EQ(any, want_any) << "trial " << trial;
        ++boxes;
    }
    std::cout << "boxes " << boxes << ", samples on an edge " << on_edges << ", inside " << inside << ", outside "
              << outside << "\n";
    EXPECT_GE(boxes, 7500);
    EXPECT_GE(on_edges, 200);
    EXPECT_GE(inside, 50000);
    EXPECT_GE(outside, 50000);
}

// sample_offsets_avx2 (each triangle's sample offsets under MSAA and SSAA, four per vector) against
// the scalar int64 products a·x + b·y, with edge coefficients over the whole int32 range (their
// extremes included) and offsets anywhere in a pixel's 256 subpixel steps.
TEST(SampleRows, SampleOffsetsFourPerVectorAreTheScalarProducts) {
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this CPU has no AVX2, which sample_offsets_avx2 needs";
    std::mt19937_64 rng(65);
    constexpr std::int32_t kExtremes[] = {std::numeric_limits<std::int32_t>::min(),
                                          std::numeric_limits<std::int32_t>::max(), -1, 0, 1};
    long checked = 0;
    for (int trial = 0; trial < 5000; ++trial) {
        mr::SetupTriangle t;
        for (int e = 0; e < 3; ++e) {
            t.edge_a[e] = trial % 4 == 0 ? kExtremes[rng() % 5] : static_cast<std::int32_t>(rng());
            t.edge_b[e] = trial % 4 == 1 ? kExtremes[rng() % 5] : static_cast<std::int32_t>(rng());
        }
        const int S = std::array<int, 4>{4, 8, 16, 64}[trial % 4];
        std::vector<std::int32_t> x(static_cast<std::size_t>(S)), y(x.size());
        for (int s = 0; s < S; ++s)
            x[static_cast<std::size_t>(s)] = static_cast<std::int32_t>(rng() % 256),
            y[static_cast<std::size_t>(s)] = static_cast<std::int32_t>(rng() % 256);
        std::int64_t off[3][64];
        mr::kernels::sample_offsets_avx2(t, x.data(), y.data(), S, {off[0], off[1], off[2]});
        for (int e = 0; e < 3; ++e)
            for (int s = 0; s < S; ++s, ++checked)
                ASSERT_EQ(off[e][s], std::int64_t{t.edge_a[e]} * x[static_cast<std::size_t>(s)] +
                                         std::int64_t{t.edge_b[e]} * y[static_cast<std::size_t>(s)])
                    << "trial " << trial << " edge " << e << " sample " << s;
    }
    std::cout << "offsets checked " << checked << "\n";
    EXPECT_GE(checked, 100000);
}

}  // namespace
