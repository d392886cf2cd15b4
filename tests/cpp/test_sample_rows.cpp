// Sample rows (RenderSettings::sample_rows): at one sample per pixel, a depth-tested triangle's
// coverage, screen weights and depth tests along a row run four pixels per vector. Colour, depth
// and every counter are bit for bit those of the per-sample path — for both depth conventions,
// every blend and interpolation, textured or not, depth written or only read, with and without
// block skipping and deferred shading — including triangles whose edge values along a row pass
// 2^52, where the rows fall back to the per-sample path.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "helpers.hpp"

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
                    // untextured, read-only and flat; then a draw without depth test.
                    std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), tested),
                                                   make_draw(a, glm::dmat4(1.0), tested, glm::vec4(0.2f, 0.9f, 0.4f, 1.0f)),
                                                   make_draw(b, shifted, tested),
                                                   make_draw(b, glm::dmat4(1.0), read_only, glm::vec4(0.9f, 0.8f, 1.0f, 1.0f)),
                                                   make_draw(a, shifted, no_depth(blend), glm::vec4(0.5f))};
                    draws[0].texture = texture;
                    draws[3].state.interpolation = mr::Interpolation::flat;
                    draws[4].mesh = &b;
                    SCOPED_TRACE(mr::to_string(convention) + ", " + mr::to_string(blend) + ", " +
                                 mr::to_string(interpolation) + (skipping ? ", block skipping" : ""));
                    auto s = settings(W, H, 1);
                    s.threads = 1;
                    s.block_skipping = skipping;
                    s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
                    expect_same_with_and_without_rows(draws, cam, s);
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
    auto s = settings(W, H, 1);
    s.threads = 1;
    expect_same_with_and_without_rows({make_draw(big, glm::dmat4(1.0), state)}, cam, s);
}

}  // namespace
