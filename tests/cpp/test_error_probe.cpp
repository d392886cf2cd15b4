// The error probe (error_probe.hpp): its guide against hand-computed values; its estimate against
// the hand-computed error of a render whose only error is one half-covered column; a flat image
// gives zero without extra passes; an exact image whose error is below the
// reference's own makes the passes double and ends in an upper bound; a kept ProbeReference gives
// a later probe exactly a fresh probe's estimate of the same draws without rendering a reference
// pixel again; bad input names itself.
#include <gtest/gtest.h>

#include <limits>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "helpers.hpp"
#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/error_probe.hpp"
#include "mipraster/pipeline/renderer.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

// White triangles given in pixel coordinates (y down) over a black background.
mr::Mesh pixel_mesh(const std::vector<glm::vec2>& corners) {
    mr::Mesh m;
    for (const glm::vec2& c : corners) m.positions.push_back({c.x * 256.0f, c.y * 256.0f, 0.0f});
    for (std::size_t t = 0; t + 2 < corners.size(); t += 3)
        add_triangle(m, static_cast<std::uint32_t>(t), static_cast<std::uint32_t>(t + 1), static_cast<std::uint32_t>(t + 2));
    return m;
}

TEST(ErrorProbe, GuideIsTheLargestHalfStepPlusTheSpreadHalves) {
    // 3×1 image, R = G = B = 0, 1, 1: the step 1 between pixels 0 and 1 is (1/2)² = 1/4 per channel.
    mr::Image c(3, 1, 4);
    for (int ch = 0; ch < 3; ++ch) c.at(1, 0, ch) = c.at(2, 0, ch) = 1.0f;
    const mr::Image g = mr::error_guide(c, nullptr);
    EXPECT_FLOAT_EQ(g.at(0, 0, 0), 0.25f);
    EXPECT_FLOAT_EQ(g.at(1, 0, 0), 0.25f);
    EXPECT_FLOAT_EQ(g.at(2, 0, 0), 0.0f);
    // A halves map of 3 at the middle pixel adds 9/9 to each pixel of its 3×3 neighbourhood.
    mr::Image h(3, 1, 1);
    h.at(1, 0, 0) = 3.0f;
    const mr::Image gh = mr::error_guide(c, &h);
    EXPECT_FLOAT_EQ(gh.at(0, 0, 0), 1.25f);
    EXPECT_FLOAT_EQ(gh.at(1, 0, 0), 1.25f);
    EXPECT_FLOAT_EQ(gh.at(2, 0, 0), 1.0f);
    mr::Image wrong(2, 1, 1);
    EXPECT_THROW(mr::error_guide(c, &wrong), std::invalid_argument);
}

TEST(ErrorProbe, GuideOfColoursNearTheFloatMaximumIsFinite) {
    // A step of 2·10³⁸ squares to 10⁷⁶: in float that was infinity, and the probe's draw
    // probabilities (guide / total) NaN. The guide keeps it at the largest float.
    mr::Image c(2, 1, 4);
    for (int ch = 0; ch < 3; ++ch) c.at(0, 0, ch) = -1e38f, c.at(1, 0, ch) = 1e38f;
    mr::Image h(2, 1, 1);
    h.at(0, 0, 0) = 1e30f;
    for (const mr::Image* halves : std::vector<const mr::Image*>{nullptr, &h}) {
        const mr::Image g = mr::error_guide(c, halves);
        for (float v : g.pixels) EXPECT_EQ(v, std::numeric_limits<float>::max());
    }
}

TEST(ErrorProbe, MeasuresAHalfCoveredColumn) {
    // A rectangle covering x < 8.5 of a 16×8 image. At 1 spp the centres of column 8 lie on its
    // right edge (not covered by the top-left rule), so column 8 renders 0 where its truth is ½:
    // the true MSE is 8·(½)²/128 = 1/64, RMSE 1/8. The 8×8 stratified reference splits column 8 at
    // a stratum boundary, so it is exact (its own error 0).
    const int w = 16, h = 8;
    const mr::Mesh m = pixel_mesh({{-1, -1}, {8.5f, -1}, {8.5f, 9}, {-1, -1}, {8.5f, 9}, {-1, 9}});
    const mr::Draw d = make_draw(m, fixed_to_ndc(w, h), no_depth());
    mr::RenderSettings s = settings(w, h, 1);
    const mr::RenderResult r = mr::render({d}, identity_camera(), s);
    ASSERT_EQ(r.color.at(8, 3, 0), 0.0f);
    ASSERT_EQ(r.color.at(7, 3, 0), 1.0f);
    const mr::ErrorProbe p = mr::measure_error({d}, identity_camera(), s, r.color, nullptr, 1024, 0);
    EXPECT_FALSE(p.upper_bound);
    EXPECT_EQ(p.reference_spp, mr::kProbeReferenceSpp * mr::kProbeMinPasses);
    EXPECT_EQ(p.reference_rmse, 0.0);
    EXPECT_LT(p.standard_error, 0.05 * p.rmse);
    EXPECT_NEAR(p.rmse, 0.125, 4.0 * p.standard_error) << p.to_string();
    EXPECT_EQ(p.halves_rmse, -1.0);
    // The same seed, the same choice and estimate; another thread count too.
    s.threads = 1;
    const mr::ErrorProbe q = mr::measure_error({d}, identity_camera(), s, r.color, nullptr, 1024, 0);
    EXPECT_EQ(q.rmse, p.rmse);
    EXPECT_EQ(q.distinct_pixels, p.distinct_pixels);
}

TEST(ErrorProbe, FlatImageIsZeroWithoutExtraPasses) {
    const int w = 16, h = 16;
    const mr::Mesh m = pixel_mesh({{-1, -1}, {17, -1}, {17, 17}, {-1, -1}, {17, 17}, {-1, 17}});
    const mr::Draw d = make_draw(m, fixed_to_ndc(w, h), no_depth());
    const mr::RenderSettings s = settings(w, h, 4);
    const mr::RenderResult r = mr::render({d}, identity_camera(), s);
    const mr::ErrorProbe p = mr::measure_error({d}, identity_camera(), s, r.color, nullptr, 64, 3);
    EXPECT_FALSE(p.upper_bound);  // the reference is exact too: nothing hides anything
    EXPECT_EQ(p.rmse, 0.0);
    EXPECT_EQ(p.standard_error, 0.0);
    EXPECT_EQ(p.reference_spp, mr::kProbeReferenceSpp * mr::kProbeMinPasses);  // nothing to resolve: no more passes
}

TEST(ErrorProbe, ErrorBelowTheReferencesOwnDoublesThePassesThenIsABound) {
    // A rectangle covering x < 8 + 77/256 of a 16×8 image, and as the "render" its exact image:
    // column 8 is 77/256 covered. Its error is 0; the stratified reference's is not (samples
    // jitter across the edge), and its expectation is the exact area (samples lie on the same
    // 1/256 lattice as the edge, uniformly within their strata: 77 of 256 positions are left of it).
    // The probe cannot resolve 0: it doubles its passes to the most, then says "at most".
    const int w = 16, h = 8;
    const float edge = 8.0f + 77.0f / 256.0f;
    const mr::Mesh m = pixel_mesh({{-1, -1}, {edge, -1}, {edge, 9}, {-1, -1}, {edge, 9}, {-1, 9}});
    const mr::Draw d = make_draw(m, fixed_to_ndc(w, h), no_depth());
    const mr::RenderSettings s = settings(w, h, 4);
    mr::Image exact(w, h, 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float v = x < 8 ? 1.0f : x == 8 ? 77.0f / 256.0f : 0.0f;
            for (int c = 0; c < 3; ++c) exact.at(x, y, c) = v;
            exact.at(x, y, 3) = 1.0f;
        }
    const mr::ErrorProbe p = mr::measure_error({d}, identity_camera(), s, exact, nullptr, 256, 0);
    EXPECT_EQ(p.reference_spp, mr::kProbeReferenceSpp * mr::kProbeMaxPasses) << p.to_string();
    EXPECT_TRUE(p.upper_bound) << p.to_string();
    EXPECT_GT(p.reference_rmse, 0.0);
    EXPECT_LT(p.rmse, 0.01) << p.to_string();  // the bound is tight
}

TEST(ErrorProbe, ReusedReferenceIsAFreshProbeOfTheSameDraws) {
    // The half-covered column of MeasuresAHalfCoveredColumn: image a is its 1-spp render (RMSE
    // 1/8), image b the same with column 8 at ¼ instead of 0 (RMSE 1/16: a better image of the
    // same scene, as after an adaptive pass).
    const int w = 16, h = 8;
    const mr::Mesh m = pixel_mesh({{-1, -1}, {8.5f, -1}, {8.5f, 9}, {-1, -1}, {8.5f, 9}, {-1, 9}});
    const mr::Draw d = make_draw(m, fixed_to_ndc(w, h), no_depth());
    const mr::RenderSettings s = settings(w, h, 1);
    const mr::Image a = mr::render({d}, identity_camera(), s).color;
    mr::Image b = a;
    for (int y = 0; y < h; ++y)
        for (int c = 0; c < 3; ++c) b.at(8, y, c) = 0.25f;
    mr::ProbeReference kept;
    EXPECT_TRUE(kept.empty());
    const mr::ErrorProbe pa = mr::measure_error({d}, identity_camera(), s, a, nullptr, 96, 5, nullptr, &kept);
    ASSERT_FALSE(kept.empty());
    EXPECT_EQ(kept.chosen.size(), 96u);
    EXPECT_EQ(kept.passes, mr::kProbeMinPasses);
    EXPECT_EQ(pa.rendered_passes, mr::kProbeMinPasses);
    EXPECT_EQ(pa.rmse, mr::measure_error({d}, identity_camera(), s, a, nullptr, 96, 5).rmse);  // filling changes nothing
    // A fresh probe of b with the same seed and a's guide draws the same pixels and renders the same passes.
    const mr::Image guide_a = mr::error_guide(a, nullptr);
    const mr::ErrorProbe fresh = mr::measure_error({d}, identity_camera(), s, b, nullptr, 96, 5, &guide_a);
    const std::vector<std::uint32_t> drawn = kept.chosen;
    // The reused probe is given other draws of the scene (an empty scene, whose reference would
    // be black), another seed and pixel count: it must use neither, so it rendered no pass.
    const mr::ErrorProbe reused = mr::measure_error({}, identity_camera(), s, b, nullptr, 7, 99, nullptr, &kept);
    EXPECT_EQ(reused.rmse, fresh.rmse) << reused.to_string() << " against " << fresh.to_string();
    EXPECT_EQ(reused.standard_error, fresh.standard_error);
    EXPECT_EQ(reused.reference_rmse, fresh.reference_rmse);
    EXPECT_EQ(reused.pixels, 96);
    EXPECT_EQ(reused.rendered_passes, 0);
    EXPECT_EQ(fresh.rendered_passes, mr::kProbeMinPasses);
    EXPECT_EQ(reused.distinct_pixels, fresh.distinct_pixels);
    EXPECT_EQ(kept.chosen, drawn);
    EXPECT_EQ(kept.passes, mr::kProbeMinPasses);
    EXPECT_GT(reused.rmse, 0.0);
    EXPECT_LT(reused.rmse, 0.75 * pa.rmse);  // b is the better image (1/16 against 1/8), and the probe says so
    // Draws made for a 16×8 image do not fit another size.
    const mr::Image other(8, 8, 4);
    EXPECT_THROW(mr::measure_error({d}, identity_camera(), settings(8, 8, 1), other, nullptr, 96, 5, nullptr, &kept),
                 std::invalid_argument);
}

TEST(ErrorProbe, BadInputNamesItself) {
    const mr::Mesh m = pixel_mesh({{0, 0}, {8, 8}, {0, 8}});
    const mr::Draw d = make_draw(m, fixed_to_ndc(8, 8), no_depth());
    const mr::RenderSettings s = settings(8, 8, 4);
    const mr::Image c(8, 8, 4), small(4, 4, 4), map(8, 4, 1);
    auto message = [&](auto f) {
        try {
            f();
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no exception");
    };
    EXPECT_NE(message([&] { mr::measure_error({d}, identity_camera(), s, c, nullptr, 0, 0); }).find("probe_pixels"),
              std::string::npos);
    EXPECT_NE(message([&] { mr::measure_error({d}, identity_camera(), s, small, nullptr, 64, 0); }).find("color"),
              std::string::npos);
    EXPECT_NE(message([&] { mr::measure_error({d}, identity_camera(), s, c, &map, 64, 0); }).find("halves_map"),
              std::string::npos);
    EXPECT_NE(message([&] { mr::measure_error({d}, identity_camera(), s, c, nullptr, 64, 0, &map); }).find("guide"),
              std::string::npos);
}

TEST(ErrorProbe, PassesAndDefaultPixels) {
    EXPECT_EQ(mr::probe_reference_passes(1), 2);
    EXPECT_EQ(mr::probe_reference_passes(32), 2);
    EXPECT_EQ(mr::probe_reference_passes(64), 4);
    // 320×240 at 4 spp: a quarter of 307 200 samples in passes of 2×64: 600 pixels.
    EXPECT_EQ(mr::default_probe_pixels(320, 240, 4), 600);
    EXPECT_EQ(mr::default_probe_pixels(8, 8, 1), mr::kProbeMinPixels);
    EXPECT_EQ(mr::default_probe_pixels(4096, 4096, 64), mr::kProbeMaxPixels);
}

}  // namespace
