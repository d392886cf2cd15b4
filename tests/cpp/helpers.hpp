#pragma once
// Small helpers shared by the C++ tests: cameras and model matrices that make test geometry exact,
// render wrappers and framebuffer accessors. Expected values come from oracle.hpp, never from here.
#include <algorithm>
#include <array>
#include <cstring>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mipraster/pipeline/draw.hpp"
#include "mipraster/pipeline/framebuffer.hpp"
#include "mipraster/pipeline/renderer.hpp"
#include "mipraster/pipeline/sample_pattern.hpp"
#include "mipraster/scene/camera.hpp"
#include "mipraster/scene/mesh.hpp"
#include "mipraster/texture/texture.hpp"
#include "oracle.hpp"

namespace helpers {

namespace mr = mipraster;

/// Identity view and projection, OpenGL convention: clip (x, y, z, 1) is NDC directly.
inline mr::Camera identity_camera() {
    return mr::Camera::from_matrices(glm::dmat4(1.0), glm::dmat4(1.0), mr::DepthConvention::opengl);
}

/// Model matrix from (X, Y, z) in 1/256 px screen units (y down) to NDC of a W×H viewport:
/// x = X/(128·W) − 1, y = 1 − Y/(128·H). For power-of-two W and H every step is exact in double,
/// so the library's screen position ·256 is X itself and snapping rounds X.
inline glm::dmat4 fixed_to_ndc(int width, int height) {
    glm::dmat4 m(1.0);
    m[0][0] = 1.0 / (128.0 * width);
    m[3][0] = -1.0;
    m[1][1] = -1.0 / (128.0 * height);
    m[3][1] = 1.0;
    return m;
}

/// The snapped position of a vertex given in 1/256 px units through fixed_to_ndc.
inline oracle::Fixed2 snap_fixed(const glm::vec3& p) {
    return {oracle::snap(static_cast<double>(p.x)), oracle::snap(static_cast<double>(p.y))};
}

inline std::array<oracle::Fixed2, 3> snapped_triangle(const mr::Mesh& mesh, std::size_t t) {
    const glm::uvec3 tri = mesh.triangles[t];
    return {snap_fixed(mesh.positions[tri[0]]), snap_fixed(mesh.positions[tri[1]]), snap_fixed(mesh.positions[tri[2]])};
}

inline mr::RenderSettings settings(int width, int height, int samples = 1,
                                   mr::PatternKind pattern = mr::PatternKind::automatic) {
    mr::RenderSettings s;
    s.width = width;
    s.height = height;
    s.samples = samples;
    s.pattern = pattern;
    s.threads = 2;
    s.keep_samples = true;
    return s;
}

inline mr::DrawState no_depth(mr::BlendMode blend = mr::BlendMode::replace) {
    mr::DrawState st;
    st.depth_test = false;
    st.depth_write = false;
    st.blend = blend;
    return st;
}

/// A depth-tested state with alpha testing at `cutoff`, its depth written or only read.
inline mr::DrawState alpha_tested(float cutoff, bool depth_write) {
    mr::DrawState st;
    st.alpha_cutoff = cutoff;
    st.depth_write = depth_write;
    return st;
}

inline mr::Draw make_draw(const mr::Mesh& mesh, const glm::dmat4& model, const mr::DrawState& state,
                          glm::vec4 color = glm::vec4(1.0f)) {
    mr::Draw d;
    d.mesh = &mesh;
    d.model = model;
    d.color = color;
    d.state = state;
    return d;
}

/// The pattern the render used, as the oracle's type.
inline oracle::Pattern to_oracle(const mr::SamplePattern& p) {
    oracle::Pattern o;
    for (int s = 0; s < p.count(); ++s) {
        o.x.push_back(p.x[s]);
        o.y.push_back(p.y[s]);
    }
    return o;
}

/// Whether two patterns hold the same set of offsets (in any order).
inline bool same_offsets(const oracle::Pattern& a, const oracle::Pattern& b) {
    if (a.count() != b.count()) return false;
    std::vector<std::pair<int, int>> pa, pb;
    for (int s = 0; s < a.count(); ++s) pa.push_back({a.x[s], a.y[s]});
    for (int s = 0; s < b.count(); ++s) pb.push_back({b.x[s], b.y[s]});
    std::sort(pa.begin(), pa.end());
    std::sort(pb.begin(), pb.end());
    return pa == pb;
}

inline float sample_channel(const mr::Framebuffer& fb, int x, int y, int s, int c) {
    return fb.color[4 * fb.sample_index(x, y, s) + static_cast<std::size_t>(c)];
}

inline glm::vec4 sample_color(const mr::Framebuffer& fb, int x, int y, int s) {
    const float* p = &fb.color[4 * fb.sample_index(x, y, s)];
    return {p[0], p[1], p[2], p[3]};
}

/// Compares channel c of every sample with an expected value per sample; reports the first few
/// differences and their number.
inline ::testing::AssertionResult samples_equal(const mr::Framebuffer& fb, const std::vector<float>& expected, int c,
                                                const std::string& what) {
    const int W = fb.width, H = fb.height, S = fb.samples;
    if (expected.size() != static_cast<std::size_t>(W) * H * S)
        return ::testing::AssertionFailure() << what << ": expected array has the wrong size";
    std::size_t bad = 0;
    std::ostringstream first;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int s = 0; s < S; ++s) {
                const std::size_t i = fb.sample_index(x, y, s);
                const float got = fb.color[4 * i + c];
                if (got != expected[i]) {
                    if (bad < 8)
                        first << "\n  pixel (" << x << ", " << y << ") sample " << s << ": got " << got
                              << ", expected " << expected[i];
                    ++bad;
                }
            }
    if (bad == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << what << ": " << bad << " of " << static_cast<std::size_t>(W) * H * S
                                         << " samples differ" << first.str();
}

/// Triangle count helper for meshes built in tests.
inline void add_triangle(mr::Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    m.triangles.push_back(glm::uvec3(a, b, c));
}

/// `n` random triangles with premultiplied vertex colours: centres uniform in the box lo + [0, extent),
/// corners within size·[−½, ½]³ of their centre, the z offsets scaled by `z_scale` (< 1: flatter).
inline mr::Mesh random_triangles(std::size_t n, double size, std::uint64_t seed, const glm::dvec3& lo,
                                 const glm::dvec3& extent, double z_scale = 1.0) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    mr::Mesh m;
    for (std::size_t t = 0; t < n; ++t) {
        const glm::dvec3 c(lo.x + extent.x * u(rng), lo.y + extent.y * u(rng), lo.z + extent.z * u(rng));
        for (int i = 0; i < 3; ++i) {
            const glm::dvec3 p = c + size * glm::dvec3(u(rng) - 0.5, u(rng) - 0.5, z_scale * (u(rng) - 0.5));
            m.positions.push_back(glm::vec3(p));
            const float a = static_cast<float>(0.2 + 0.8 * u(rng));
            m.colors.push_back(glm::vec4(a * float(u(rng)), a * float(u(rng)), a * float(u(rng)), a));
        }
        add_triangle(m, static_cast<std::uint32_t>(3 * t), static_cast<std::uint32_t>(3 * t + 1),
                     static_cast<std::uint32_t>(3 * t + 2));
    }
    return m;
}

/// Whether two float buffers hold the same bits (bit-identical renders).
template <class Floats>
bool same_bits(const Floats& a, const Floats& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

/// The scene rendered with a switch of the settings off, then on: {off, on}.
inline std::pair<mr::RenderResult, mr::RenderResult> render_off_on(const std::vector<mr::Draw>& draws,
                                                                   const mr::Camera& cam, mr::RenderSettings s,
                                                                   bool mr::RenderSettings::*flag) {
    s.*flag = false;
    mr::RenderResult off = mr::render(draws, cam, s);
    s.*flag = true;
    return {std::move(off), mr::render(draws, cam, s)};
}

/// Two renders of one scene by two paths agree bit for bit: resolved colour, samples, depth and
/// the sample counters.
inline void expect_same_render(const mr::RenderResult& fast, const mr::RenderResult& plain) {
    EXPECT_TRUE(same_bits(fast.color.pixels, plain.color.pixels)) << "resolved colour differs";
    EXPECT_TRUE(same_bits(fast.framebuffer.color, plain.framebuffer.color)) << "samples differ";
    EXPECT_TRUE(same_bits(fast.framebuffer.depth, plain.framebuffer.depth)) << "depth differs";
    EXPECT_EQ(fast.stats.samples_covered, plain.stats.samples_covered);
    EXPECT_EQ(fast.stats.samples_passed, plain.stats.samples_passed);
    EXPECT_EQ(fast.stats.shader_invocations, plain.stats.shader_invocations);
}

/// A perspective camera at (0.3, 0.8, 4) looking at the origin, for scenes of random_triangles in
/// [−1.5, 1.5]×[−1, 1]×[−2, 6] (some cross its near plane).
inline mr::Camera overlap_camera(mr::DepthConvention convention, int width, int height) {
    const glm::dmat4 view = mr::look_at({0.3, 0.8, 4.0}, {0, 0, 0}, {0, 1, 0});
    const double far = convention == mr::DepthConvention::opengl ? 20.0 : mr::kInfiniteFar;
    return mr::Camera::from_matrices(view, mr::perspective(1.0, double(width) / height, 0.05, far, convention),
                                     convention);
}

/// Large random triangles crossing each other at random depths (some cross the near plane, so
/// clipped pieces take part), with uvs spanning several texture periods.
inline mr::Mesh overlapping(std::size_t n, double size, std::uint64_t seed) {
    mr::Mesh m = random_triangles(n, size, seed, {-1.5, -1.0, -2.0}, {3.0, 2.0, 8.0}, 0.5);
    for (std::size_t i = 0; i < m.positions.size(); ++i)
        m.uvs.push_back(glm::vec2(1.7f * m.positions[i].x + 0.3f * m.positions[i].z, 2.3f * m.positions[i].y));
    return m;
}

/// An RGBA checker of 2×2-texel squares, n × m texels, values in [0.15, 0.9] (all channels vary).
inline mr::Texture checker_texture(int n = 16, int m = 16) {
    std::vector<float> texels;
    for (int y = 0; y < m; ++y)
        for (int x = 0; x < n; ++x) {
            const float v = (x / 2 + y / 2) % 2 ? 0.9f : 0.15f;
            texels.insert(texels.end(), {v, 0.5f * v + 0.2f * float(x) / n, 1.0f - v, 1.0f});
        }
    return mr::Texture::from_float(texels.data(), n, m, 4, true, "checker");
}

/// What fn throws (any std::exception's message), or "<nothing thrown>".
template <class Fn>
std::string thrown_message(Fn&& fn) {
    try {
        fn();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "<nothing thrown>";
}

}  // namespace helpers
