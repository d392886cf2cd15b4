// The stress suite (issue 6) in its fast sizes: every case must pass its bound. The oracles the
// suite carries in the library are checked here first against hand-worked cases, so a broken
// oracle cannot make a case pass.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mipraster/stress/clip_ray_cast.hpp"
#include "mipraster/stress/exact_coverage.hpp"
#include "mipraster/stress/stress_cases.hpp"
#include "mipraster/stress/texture_reference.hpp"

namespace {

namespace mr = mipraster;
namespace st = mipraster::stress;

void expect_rows_pass(const std::vector<mr::StressRow>& rows, int number) {
    ASSERT_FALSE(rows.empty());
    for (const mr::StressRow& r : rows) {
        EXPECT_EQ(r.number, number);
        EXPECT_FALSE(r.figure.empty());
        EXPECT_FALSE(r.bound.empty());
        std::string details;
        for (const std::string& d : r.details) details += "\n  " + d;
        EXPECT_TRUE(r.pass) << mr::format_stress_report({r}, true);
        std::printf("%s%s\n", r.to_string().c_str(), details.c_str());
    }
}

// ---- the oracles ------------------------------------------------------------------------------

TEST(StressOracle, ExactSnapRoundsHalfToEvenAndRefusesNonFinite) {
    EXPECT_EQ(st::exact_snap(2.5), 2);
    EXPECT_EQ(st::exact_snap(3.5), 4);
    EXPECT_EQ(st::exact_snap(-2.5), -2);
    EXPECT_THROW(st::exact_snap(std::numeric_limits<double>::quiet_NaN()), std::domain_error);
    EXPECT_THROW(st::exact_snap(1e19), std::domain_error);
}

TEST(StressOracle, ExactCoverageFollowsTheTopLeftRule) {
    // Right triangle (0,0), (512,0), (0,512) in units, either winding: the top edge y = 0 and the
    // left edge x = 0 own their samples, the hypotenuse does not.
    for (bool flip : {false, true}) {
        std::array<st::FixedPoint, 3> v = {st::FixedPoint{0, 0}, st::FixedPoint{512, 0}, st::FixedPoint{0, 512}};
        if (flip) std::swap(v[1], v[2]);
        EXPECT_TRUE(st::exact_covers(v, 100, 0));     // on the top edge
        EXPECT_TRUE(st::exact_covers(v, 0, 100));     // on the left edge
        EXPECT_FALSE(st::exact_covers(v, 256, 256));  // on the hypotenuse (a right/bottom edge)
        EXPECT_TRUE(st::exact_covers(v, 255, 256));
        EXPECT_FALSE(st::exact_covers(v, -1, 10));
    }
    EXPECT_TRUE(st::exact_degenerate({st::FixedPoint{0, 0}, st::FixedPoint{10, 10}, st::FixedPoint{-30, -30}}));
    // Huge coordinates stay exact in __int128.
    const std::int64_t big = std::int64_t{1} << 60;
    EXPECT_TRUE(st::exact_covers({st::FixedPoint{-big, -big}, st::FixedPoint{big, -big}, st::FixedPoint{0, big}}, 0, 0));
}

TEST(StressOracle, ClipRayCastFindsPerspectiveWeightsAndTheVisiblePart) {
    // A triangle with w = 1, 2, 4: at the NDC point of vertex 1 the weights are (0, 1, 0); the
    // clip-space point with weights b, projected, must give back b.
    const std::array<glm::dvec4, 3> p = {glm::dvec4(-0.5, -0.5, 0.0, 1.0), glm::dvec4(1.0, -1.0, 0.0, 2.0),
                                         glm::dvec4(0.0, 2.0, 0.0, 4.0)};
    const st::ClipHit h = st::ray_cast_clip(p, 0.5, -0.5, false);
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.weights.y, 1.0, 1e-12);
    const glm::dvec3 b(0.2, 0.3, 0.5);
    const glm::dvec4 q = b.x * p[0] + b.y * p[1] + b.z * p[2];
    const st::ClipHit g = st::ray_cast_clip(p, q.x / q.w, q.y / q.w, false);
    ASSERT_TRUE(g.hit);
    EXPECT_NEAR(g.weights.x, 0.2, 1e-12);
    EXPECT_NEAR(g.weights.z, 0.5, 1e-12);
    // Behind the eye (w < 0 at the point): no hit.
    const std::array<glm::dvec4, 3> behind = {glm::dvec4(0, 0, 0, -1), glm::dvec4(1, 0, 0, -1), glm::dvec4(0, 1, 0, -1)};
    EXPECT_FALSE(st::ray_cast_clip(behind, 0.1, 0.1, false).hit);
}

TEST(StressOracle, TextureReferenceWrapsByDefinition) {
    EXPECT_EQ(st::reference_wrap(-1, 5, mr::WrapMode::repeat), 4);
    EXPECT_EQ(st::reference_wrap(-1, 5, mr::WrapMode::mirror), 0);
    EXPECT_EQ(st::reference_wrap(5, 5, mr::WrapMode::mirror), 4);
    EXPECT_EQ(st::reference_wrap(10, 5, mr::WrapMode::mirror), 0);
    EXPECT_EQ(st::reference_wrap(7, 5, mr::WrapMode::clamp), 4);
    EXPECT_EQ(st::reference_wrap(-1, 5, mr::WrapMode::border), -1);
    mr::TextureLevel level(2, 1);
    level.at(0, 0) = glm::vec4(0.0f);
    level.at(1, 0) = glm::vec4(1.0f);
    mr::Sampler s;
    s.wrap_u = mr::WrapMode::clamp;
    EXPECT_DOUBLE_EQ(st::reference_lookup(level, 0.5, 0.5, mr::TexelFilter::linear, s).r, 0.5);
    EXPECT_DOUBLE_EQ(st::reference_lookup(level, 0.74, 0.5, mr::TexelFilter::nearest, s).r, 1.0);
}

// ---- the cases, fast sizes -----------------------------------------------------------------------

TEST(Stress, Case01Watertight) { expect_rows_pass(mr::stress_watertight(mr::StressSize::fast), 1); }
TEST(Stress, Case02Slivers) { expect_rows_pass(mr::stress_slivers(mr::StressSize::fast), 2); }
TEST(Stress, Case03HugeCoordinates) { expect_rows_pass(mr::stress_huge_coordinates(mr::StressSize::fast), 3); }
TEST(Stress, Case04NearPlane) { expect_rows_pass(mr::stress_near_plane(mr::StressSize::fast), 4); }
TEST(Stress, Case05Depth) { expect_rows_pass(mr::stress_depth(mr::StressSize::fast), 5); }
TEST(Stress, Case06GrazingTexture) { expect_rows_pass(mr::stress_grazing_texture(mr::StressSize::fast), 6); }
TEST(Stress, Case07Derivatives) { expect_rows_pass(mr::stress_derivatives(mr::StressSize::fast), 7); }
TEST(Stress, Case08Degenerate) { expect_rows_pass(mr::stress_degenerate(mr::StressSize::fast), 8); }
TEST(Stress, Case09TextureSizes) { expect_rows_pass(mr::stress_texture_sizes(mr::StressSize::fast), 9); }
TEST(Stress, Case10SubpixelMotion) { expect_rows_pass(mr::stress_subpixel_motion(mr::StressSize::fast), 10); }
TEST(Stress, Case11Interpolation) { expect_rows_pass(mr::stress_interpolation(mr::StressSize::fast), 11); }
TEST(Stress, Case12Determinism) { expect_rows_pass(mr::stress_determinism(mr::StressSize::fast), 12); }

TEST(StressReport, RowsPrintAsTextAndJson) {
    mr::StressRow r;
    r.number = 3;
    r.name = "a \"quoted\" name";
    r.figure = "0 differences";
    r.bound = "0";
    r.pass = true;
    r.details = {"line\twith tab"};
    EXPECT_NE(r.to_string().find("PASS"), std::string::npos);
    const std::string json = mr::stress_rows_to_json({r});
    EXPECT_NE(json.find("\"name\": \"a \\\"quoted\\\" name\""), std::string::npos);
    EXPECT_NE(json.find("\"pass\": true"), std::string::npos);
    EXPECT_NE(json.find("line\\twith tab"), std::string::npos);
    EXPECT_EQ(mr::parse_stress_size("full"), mr::StressSize::full);
    EXPECT_THROW(mr::parse_stress_size("huge"), std::invalid_argument);
}

}  // namespace
