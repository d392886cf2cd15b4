// Batched texture lookups in the renderer (RenderSettings::batched_lookups): a render that queues
// its lookups and runs them sixteen at a time through BatchSampler gives every sample the reference
// render's colour within the batch tolerance (per shade: the untextured colour is at most 1 and the
// texels at most 1), the same depth and the same counters, for every shading, sample mode, blend
// mode, deferred or forward shading and thread count. Samplers it does not cover give the
// reference's bits, which also shows its vectorized interpolation gives the per-sample bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "helpers.hpp"
#include "mipraster/texture/sample_batch.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

struct Outcome {
    mr::RenderResult reference, batched;
};

Outcome render_both(const std::vector<mr::Draw>& draws, const mr::Camera& cam, mr::RenderSettings s) {
    s.keep_samples = true;
    s.batched_lookups = false;
    Outcome o{mr::render(draws, cam, s), {}};
    s.batched_lookups = true;
    o.batched = mr::render(draws, cam, s);
    return o;
}

// Largest per-channel difference between the two sample framebuffers.
double largest_difference(const Outcome& o) {
    const std::vector<float>& a = o.reference.framebuffer.color;
    const std::vector<float>& b = o.batched.framebuffer.color;
    EXPECT_EQ(a.size(), b.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
        worst = std::max(worst, std::abs(double(a[i]) - double(b[i])));
    return worst;
}

void expect_same_geometry(const Outcome& o) {
    EXPECT_TRUE(same_bits(o.batched.framebuffer.depth, o.reference.framebuffer.depth)) << "depth differs";
    EXPECT_EQ(o.batched.stats.samples_covered, o.reference.stats.samples_covered);
    EXPECT_EQ(o.batched.stats.samples_passed, o.reference.stats.samples_passed);
    EXPECT_EQ(o.batched.stats.shader_invocations, o.reference.stats.shader_invocations);
    EXPECT_EQ(o.batched.stats.tiles_deferred, o.reference.stats.tiles_deferred);
}

TEST(BatchedLookups, EverySampleWithinTheToleranceOfTheReferenceRender) {
    const int W = 96, H = 80;  // partial tiles at the right and bottom
    const mr::Mesh a = overlapping(150, 2.5, 61), b = overlapping(60, 1.5, 62);
    glm::dmat4 shifted(1.0);
    shifted[3] = glm::dvec4(0.2, 0.1, 0.5, 1.0);
    mr::Sampler trilinear, clamped, bilinear, one_probe;
    clamped.wrap_u = mr::WrapMode::clamp;
    clamped.lod_bias = 0.7f;
    bilinear.mip_filter = mr::MipFilter::none;  // no derivatives: the fixed texturing kernel
    one_probe.footprint = mr::FootprintFilter::anisotropic;
    one_probe.max_anisotropy = 1.0f;
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    // A power-of-two texture (positions exact in float) and one that is not (rounded).
    for (const auto& size : {std::pair{16, 16}, std::pair{20, 12}}) {
        const mr::Texture texture = checker_texture(size.first, size.second);
        const double tolerance = mr::batch_sampling_tolerance(size.first, size.second);
        for (mr::Interpolation interpolation : {mr::Interpolation::perspective, mr::Interpolation::screen})
            for (auto [samples, aa] : {std::pair{1, mr::AntiAliasing::ssaa}, std::pair{4, mr::AntiAliasing::ssaa},
                                       std::pair{4, mr::AntiAliasing::msaa}})
                for (bool deferred : {false, true}) {
                    mr::DrawState state;
                    state.interpolation = interpolation;
                    std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), state),
                                                   make_draw(b, shifted, state, glm::vec4(0.9f, 0.8f, 1.0f, 1.0f)),
                                                   make_draw(b, glm::dmat4(1.0), state)};
                    const mr::Sampler samplers[] = {trilinear, bilinear, samples == 1 ? one_probe : clamped};
                    for (int d = 0; d < 3; ++d) {
                        draws[d].texture = texture;
                        draws[d].sampler = samplers[d];
                    }
                    for (int threads : {1, 2}) {
                        SCOPED_TRACE(std::to_string(size.first) + "x" + std::to_string(size.second) + ", " +
                                     mr::to_string(interpolation) + ", " + std::to_string(samples) + " " +
                                     mr::to_string(aa) + (deferred ? ", deferred" : "") + ", " +
                                     std::to_string(threads) + " threads");
                        auto s = settings(W, H, samples);
                        s.anti_aliasing = aa;
                        s.threads = threads;
                        s.deferred_shading = deferred;
                        const Outcome o = render_both(draws, cam, s);
                        expect_same_geometry(o);
                        // One shade per sample survives replace blending.
                        EXPECT_LE(largest_difference(o), tolerance);
                    }
                }
    }
}

TEST(BatchedLookups, BlendedLayersAccumulateAtMostOneToleranceEach) {
    // Three textured layers of one mesh (one draw, one queue) blended over (and added onto) a
    // cleared target: the error of each layer's lookups adds up, no more. (Blending in queue
    // order matters where one batch holds two shades of a sample: the random scene above fails
    // when the queue blends backwards.)
    const int W = 64, H = 48;
    mr::Mesh layers;
    for (int layer = 0; layer < 3; ++layer) {
        const float x = 1.0f - 0.3f * layer, uv = 1.0f + layer;  // different sizes and uv scales
        const std::uint32_t first = static_cast<std::uint32_t>(layers.positions.size());
        layers.positions.insert(layers.positions.end(), {{-x, -1, 0}, {x, -1, 0}, {x, 1, 0}, {-x, 1, 0}});
        layers.uvs.insert(layers.uvs.end(), {{0.1f, 0.2f}, {3.7f * uv, 0.1f}, {3.3f * uv, 2.9f}, {-0.4f, 2.5f * uv}});
        add_triangle(layers, first, first + 1, first + 2);
        add_triangle(layers, first, first + 2, first + 3);
    }
    const mr::Texture texture = checker_texture(20, 12);
    const double tolerance = mr::batch_sampling_tolerance(20, 12);
    for (mr::BlendMode blend : {mr::BlendMode::over, mr::BlendMode::add})
        for (int samples : {1, 4}) {
            SCOPED_TRACE(mr::to_string(blend) + ", " + std::to_string(samples) + " samples");
            std::vector<mr::Draw> draws = {make_draw(layers, glm::dmat4(1.0), no_depth(blend), glm::vec4(0.5f))};
            draws[0].texture = texture;
            const Outcome o = render_both(draws, identity_camera(), settings(W, H, samples));
            expect_same_geometry(o);
            // Each layer's shade is ≤ 1 and off by ≤ tolerance; over scales what lies beneath by ≤ 1.
            EXPECT_LE(largest_difference(o), 3 * tolerance);
        }
}

TEST(BatchedLookups, UncoveredSamplersAndDebugViewsGiveTheReferenceBits) {
    const int W = 64, H = 64;
    const mr::Mesh a = overlapping(80, 2.5, 71);
    const mr::Camera cam = overlap_camera(mr::DepthConvention::reverse_z, W, H);
    mr::Sampler mirror, nearest, ewa;
    mirror.wrap_v = mr::WrapMode::mirror;
    nearest.min_filter = mr::TexelFilter::nearest;
    ewa.footprint = mr::FootprintFilter::ewa;
    for (const mr::Sampler& sampler : {mirror, nearest, ewa}) {
        SCOPED_TRACE(sampler.to_string());
        ASSERT_FALSE(mr::BatchSampler::covers(sampler));
        std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), mr::DrawState{})};
        draws[0].texture = checker_texture(20, 12);
        draws[0].sampler = sampler;
        const Outcome o = render_both(draws, cam, settings(W, H, 4));
        expect_same_geometry(o);
        EXPECT_TRUE(same_bits(o.batched.framebuffer.color, o.reference.framebuffer.color));
    }
    for (mr::DebugView view : {mr::DebugView::mip_level, mr::DebugView::uv}) {
        SCOPED_TRACE(mr::to_string(view));
        std::vector<mr::Draw> draws = {make_draw(a, glm::dmat4(1.0), mr::DrawState{})};
        draws[0].texture = checker_texture(20, 12);
        auto s = settings(W, H, 1);
        s.debug_view = view;
        const Outcome o = render_both(draws, cam, s);
        EXPECT_TRUE(same_bits(o.batched.framebuffer.color, o.reference.framebuffer.color));
    }
}


TEST(BatchedLookups, BatchedInterpolationGivesTheReferenceBits) {
    // The queue interpolates a triangle's samples in vectors (interpolate_batch). Through samplers
    // BatchSampler does not cover, the lookups are the reference's own, so any difference in the
    // colour is the interpolation's: it must give the per-sample functions' bits for every
    // shading (no vertex colours: constant; flat, screen, perspective; one colour per triangle), uv interpolation,
    // derivative mode, sample mode, camera and forward or deferred shading, clipped pieces included.
    const int W = 48, H = 40;
    const mr::Mesh coloured = overlapping(90, 2.5, 81);
    mr::Mesh plain = coloured;
    plain.colors.clear();
    // One colour per triangle (the batch then skips the weighted sums), some with a +0 or −0
    // channel (where it must not).
    mr::Mesh tinted = coloured;
    for (std::size_t v = 0; v < tinted.colors.size(); ++v) {
        tinted.colors[v] = tinted.colors[v - v % 3];
        if (v / 3 % 4 == 1) tinted.colors[v].g = 0.0f;
        if (v / 3 % 4 == 2) tinted.colors[v].b = -0.0f;
    }
    mr::Sampler mirror, mirror_bilinear;  // λ and derivatives; uv only (no mip levels)
    mirror.wrap_u = mirror_bilinear.wrap_u = mr::WrapMode::mirror;
    mirror_bilinear.mip_filter = mr::MipFilter::none;
    const auto convention = mr::DepthConvention::reverse_z;
    const mr::Camera perspective = overlap_camera(convention, W, H);
    const mr::Camera orthographic =
        mr::Camera::from_matrices(mr::look_at({0.3, 0.8, 4.0}, {0, 0, 0}, {0, 1, 0}),
                                  mr::orthographic(-2.0, 2.0, -1.5, 1.5, 0.05, 20.0, convention), convention);
    const std::pair<int, mr::AntiAliasing> modes[] = {
        {1, mr::AntiAliasing::ssaa}, {4, mr::AntiAliasing::ssaa}, {4, mr::AntiAliasing::msaa}};
    for (const mr::Sampler& sampler : {mirror, mirror_bilinear}) {
        ASSERT_FALSE(mr::BatchSampler::covers(sampler));
        for (const mr::Mesh* mesh : std::initializer_list<const mr::Mesh*>{&coloured, &tinted, &plain})
            for (mr::Interpolation interpolation :
                 {mr::Interpolation::perspective, mr::Interpolation::screen, mr::Interpolation::flat})
                for (const mr::Camera* cam : {&perspective, &orthographic})
                    for (auto [samples, aa] : modes)
                        for (mr::DerivativeMode derivatives : {mr::DerivativeMode::analytic, mr::DerivativeMode::quad})
                            for (bool deferred : {false, true}) {
                                SCOPED_TRACE(sampler.to_string() +
                                             (mesh == &plain ? ", no colours, " : mesh == &tinted ? ", tinted, " : ", ") +
                                             mr::to_string(interpolation) +
                                             (cam == &perspective ? ", perspective, " : ", orthographic, ") +
                                             std::to_string(samples) + " " + mr::to_string(aa) + ", " +
                                             mr::to_string(derivatives) + " derivatives" +
                                             (deferred ? ", deferred" : ""));
                                mr::DrawState state;
                                state.interpolation = interpolation;
                                std::vector<mr::Draw> draws = {
                                    make_draw(*mesh, glm::dmat4(1.0), state, glm::vec4(0.9f, 0.7f, 1.0f, 0.8f))};
                                draws[0].texture = checker_texture(20, 12);
                                draws[0].sampler = sampler;
                                auto s = settings(W, H, samples);
                                s.anti_aliasing = aa;
                                s.derivatives = derivatives;
                                s.deferred_shading = deferred;
                                const Outcome o = render_both(draws, *cam, s);
                                expect_same_geometry(o);
                                // (The overlap, about 2.5 deep, is deferred under MSAA too: textured.)
                                EXPECT_EQ(o.batched.stats.tiles_deferred > 0, deferred);
                                EXPECT_TRUE(same_bits(o.batched.framebuffer.color, o.reference.framebuffer.color));
                            }
    }
}

}  // namespace
