// Camera matrices (DESIGN.md §1): the seeds' OpenGL frustum entry by entry, reverse-Z depth
// (near → 1, far or infinity → 0), look_at's right-handed view (camera down −z, +y up) and the
// orthographic box to ±1. Transforms are applied with the tests' own matrix code (oracle.hpp).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "helpers.hpp"
#include "oracle.hpp"

namespace {

namespace mr = mipraster;
using helpers::thrown_message;

/// The projected NDC point (x, y, z) of a view-space point (own matrix code).
glm::dvec3 ndc(const glm::dmat4& projection, const glm::dvec3& p) {
    const auto c = oracle::apply(oracle::from_glm(projection), {p.x, p.y, p.z, 1.0});
    return {c[0] / c[3], c[1] / c[3], c[2] / c[3]};
}

glm::dvec3 transform_point(const glm::dmat4& m, const glm::dvec3& p) {
    const auto c = oracle::apply(oracle::from_glm(m), {p.x, p.y, p.z, 1.0});
    return {c[0] / c[3], c[1] / c[3], c[2] / c[3]};
}

TEST(Camera, OpenGlFrustumIsTheSeedsMatrixEntryByEntry) {
    const double l = -0.3, r = 0.5, b = -0.2, t = 0.4, n = 0.7, f = 55.0;
    const oracle::Mat4 m = oracle::from_glm(mr::frustum(l, r, b, t, n, f, mr::DepthConvention::opengl));
    // Rows of the seeds' matrix (perspective-projection notes, "Matrix for Perspective Transform").
    const double seeds[4][4] = {{2 * n / (r - l), 0, (r + l) / (r - l), 0},
                                {0, 2 * n / (t - b), (t + b) / (t - b), 0},
                                {0, 0, -(f + n) / (f - n), -2 * f * n / (f - n)},
                                {0, 0, -1, 0}};
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) EXPECT_EQ(m.m[row][col], seeds[row][col]) << "row " << row << " col " << col;
}

TEST(Camera, OpenGlFrustumMapsTheFrustumCornersToTheUnitCube) {
    const double l = -0.3, r = 0.5, b = -0.2, t = 0.4, n = 0.7, f = 55.0;
    const glm::dmat4 p = mr::frustum(l, r, b, t, n, f, mr::DepthConvention::opengl);
    for (int i = 0; i < 8; ++i) {
        const double depth = i & 4 ? f : n, k = depth / n;  // the far corners scale by f/n
        const glm::dvec3 v((i & 1 ? r : l) * k, (i & 2 ? t : b) * k, -depth);
        const glm::dvec3 q = ndc(p, v);
        EXPECT_NEAR(q.x, i & 1 ? 1.0 : -1.0, 1e-12) << "corner " << i;
        EXPECT_NEAR(q.y, i & 2 ? 1.0 : -1.0, 1e-12) << "corner " << i;
        EXPECT_NEAR(q.z, i & 4 ? 1.0 : -1.0, 1e-12) << "corner " << i;
    }
}

TEST(Camera, ReverseZMapsNearToOneAndFarToZero) {
    const double n = 0.25, f = 400.0;
    const glm::dmat4 p = mr::frustum(-0.1, 0.2, -0.15, 0.1, n, f, mr::DepthConvention::reverse_z);
    EXPECT_NEAR(ndc(p, {0, 0, -n}).z, 1.0, 1e-15);
    EXPECT_NEAR(ndc(p, {0, 0, -f}).z, 0.0, 1e-15);
    // Monotonic: farther is smaller, and inside (0, 1) between the planes.
    double previous = 2.0;
    for (double d = n * 1.001; d < f; d *= 1.7) {
        const double z = ndc(p, {0.01, -0.02, -d}).z;
        EXPECT_LT(z, previous) << "distance " << d;
        EXPECT_GT(z, 0.0);
        EXPECT_LT(z, 1.0);
        previous = z;
    }
    // The x and y rows are the same as the OpenGL frustum's.
    const glm::dmat4 g = mr::frustum(-0.1, 0.2, -0.15, 0.1, n, f, mr::DepthConvention::opengl);
    for (int col = 0; col < 4; ++col) {
        EXPECT_EQ(p[col][0], g[col][0]);
        EXPECT_EQ(p[col][1], g[col][1]);
        EXPECT_EQ(p[col][3], g[col][3]);
    }
}

TEST(Camera, ReverseZWithInfiniteFarMapsNearToOneAndDistanceToZeroInTheLimit) {
    const double n = 1e-3;
    const glm::dmat4 p = mr::frustum(-n, n, -n, n, n, mr::kInfiniteFar, mr::DepthConvention::reverse_z);
    EXPECT_EQ(ndc(p, {0, 0, -n}).z, 1.0);
    for (double d : {1.0, 1e3, 1e10, 1e30}) {
        const double z = ndc(p, {0, 0, -d}).z;
        EXPECT_GT(z, 0.0) << "distance " << d;
        EXPECT_NEAR(z, n / d, 1e-15 * n / d) << "distance " << d;  // z = n / d
    }
    EXPECT_LT(ndc(p, {0, 0, -1e30}).z, 1e-32);
    // perspective() with the default far plane is the same kind of matrix.
    const glm::dmat4 q = mr::perspective(1.0, 1.5, n);
    EXPECT_EQ(ndc(q, {0, 0, -n}).z, 1.0);
    EXPECT_GT(ndc(q, {0, 0, -1e30}).z, 0.0);
    EXPECT_LT(ndc(q, {0, 0, -1e30}).z, 1e-32);
}

TEST(Camera, PerspectiveMapsTheFieldOfViewEdgesToPlusMinusOne) {
    const double fovy = 0.8, aspect = 1.6, n = 0.1;
    for (auto c : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const glm::dmat4 p = mr::perspective(fovy, aspect, n, 50.0, c);
        const double d = 7.0, h = d * std::tan(fovy / 2);
        EXPECT_NEAR(ndc(p, {0, h, -d}).y, 1.0, 1e-14);
        EXPECT_NEAR(ndc(p, {0, -h, -d}).y, -1.0, 1e-14);
        EXPECT_NEAR(ndc(p, {h * aspect, 0, -d}).x, 1.0, 1e-14);
        EXPECT_NEAR(ndc(p, {-h * aspect, 0, -d}).x, -1.0, 1e-14);
        EXPECT_NEAR(ndc(p, {0, 0, -n}).z, c == mr::DepthConvention::opengl ? -1.0 : 1.0, 1e-14);
        EXPECT_NEAR(ndc(p, {0, 0, -50.0}).z, c == mr::DepthConvention::opengl ? 1.0 : 0.0, 1e-14);
    }
}

TEST(Camera, LookAtMapsEyeToOriginTargetOntoMinusZAndUpIntoThePlusYHalfPlane) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    for (int k = 0; k < 200; ++k) {
        const glm::dvec3 eye(u(rng), u(rng), u(rng)), target(u(rng), u(rng), u(rng)), up(u(rng), u(rng), u(rng));
        const glm::dvec3 w = target - eye;
        const double dist = std::sqrt(oracle::RayCaster::dot3(w, w));
        // Skip near-parallel up vectors (look_at rejects exactly parallel ones).
        const glm::dvec3 c = oracle::RayCaster::cross3(w, up);
        if (std::sqrt(oracle::RayCaster::dot3(c, c)) < 1e-3 * dist * std::sqrt(oracle::RayCaster::dot3(up, up))) continue;
        const glm::dmat4 v = mr::look_at(eye, target, up);
        const glm::dvec3 e = transform_point(v, eye), t = transform_point(v, target), a = transform_point(v, eye + up);
        const double tol = 1e-12 * (1.0 + dist);
        EXPECT_NEAR(e.x, 0.0, tol);
        EXPECT_NEAR(e.y, 0.0, tol);
        EXPECT_NEAR(e.z, 0.0, tol);
        EXPECT_NEAR(t.x, 0.0, tol);
        EXPECT_NEAR(t.y, 0.0, tol);
        EXPECT_NEAR(t.z, -dist, tol);
        EXPECT_NEAR(a.x, 0.0, 1e-12 * (1.0 + dist));
        EXPECT_GT(a.y, 0.0);
        // Rigid and right-handed: orthonormal rotation rows with determinant +1.
        const oracle::Mat4 m = oracle::from_glm(v);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double d = 0;
                for (int q = 0; q < 3; ++q) d += m.m[i][q] * m.m[j][q];
                EXPECT_NEAR(d, i == j ? 1.0 : 0.0, 1e-12);
            }
        const double det = m.m[0][0] * (m.m[1][1] * m.m[2][2] - m.m[1][2] * m.m[2][1]) -
                           m.m[0][1] * (m.m[1][0] * m.m[2][2] - m.m[1][2] * m.m[2][0]) +
                           m.m[0][2] * (m.m[1][0] * m.m[2][1] - m.m[1][1] * m.m[2][0]);
        EXPECT_NEAR(det, 1.0, 1e-12);
        EXPECT_EQ(m.m[3][0], 0.0);
        EXPECT_EQ(m.m[3][1], 0.0);
        EXPECT_EQ(m.m[3][2], 0.0);
        EXPECT_EQ(m.m[3][3], 1.0);
    }
}

TEST(Camera, LookAtPerspectiveIsReverseZWithAnInfiniteFarPlane) {
    const mr::Camera cam = mr::Camera::look_at_perspective({1, 2, 3}, {0, 0, 0}, {0, 1, 0}, 0.7, 1.25, 0.01);
    EXPECT_EQ(cam.depth_convention, mr::DepthConvention::reverse_z);
    const glm::dvec3 dir = glm::dvec3(0, 0, 0) - glm::dvec3(1, 2, 3);
    const double len = std::sqrt(oracle::RayCaster::dot3(dir, dir));
    auto clip_ndc = [&](const glm::dvec3& world) { return ndc(cam.projection, transform_point(cam.view, world)); };
    const glm::dvec3 at_near = clip_ndc(glm::dvec3(1, 2, 3) + (0.01 / len) * dir);
    EXPECT_NEAR(at_near.x, 0.0, 1e-12);
    EXPECT_NEAR(at_near.y, 0.0, 1e-12);
    EXPECT_NEAR(at_near.z, 1.0, 1e-12);
    const glm::dvec3 far_away = clip_ndc(glm::dvec3(1, 2, 3) + 1e12 * dir);
    EXPECT_GT(far_away.z, 0.0);
    EXPECT_LT(far_away.z, 1e-13);
}

TEST(Camera, OrthographicMapsTheBoxCornersToPlusMinusOne) {
    const double l = -3.0, r = 5.0, b = -1.0, t = 2.5, n = 0.5, f = 20.0;
    for (auto c : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
        const glm::dmat4 p = mr::orthographic(l, r, b, t, n, f, c);
        const double z_near = c == mr::DepthConvention::opengl ? -1.0 : 1.0;
        const double z_far = c == mr::DepthConvention::opengl ? 1.0 : 0.0;
        for (int i = 0; i < 8; ++i) {
            const glm::dvec3 q = ndc(p, {i & 1 ? r : l, i & 2 ? t : b, i & 4 ? -f : -n});
            EXPECT_NEAR(q.x, i & 1 ? 1.0 : -1.0, 1e-15) << mr::to_string(c) << " corner " << i;
            EXPECT_NEAR(q.y, i & 2 ? 1.0 : -1.0, 1e-15) << mr::to_string(c) << " corner " << i;
            EXPECT_NEAR(q.z, i & 4 ? z_far : z_near, 1e-15) << mr::to_string(c) << " corner " << i;
        }
        // w stays 1: no perspective division.
        const auto w = oracle::apply(oracle::from_glm(p), {1.0, 2.0, -7.0, 1.0});
        EXPECT_EQ(w[3], 1.0);
    }
}

TEST(Camera, InvalidParametersThrowNamingTheProblem) {
    const double inf = mr::kInfiniteFar, nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(mr::frustum(-1, 1, -1, 1, 0.0, 10.0), std::invalid_argument);
    EXPECT_THROW(mr::frustum(-1, 1, -1, 1, -0.1, 10.0), std::invalid_argument);
    EXPECT_THROW(mr::frustum(-1, 1, -1, 1, 1.0, 0.5), std::invalid_argument);
    EXPECT_THROW(mr::frustum(1, 1, -1, 1, 0.1, 10.0), std::invalid_argument);
    EXPECT_THROW(mr::frustum(-1, 1, 2, 2, 0.1, 10.0), std::invalid_argument);
    EXPECT_THROW(mr::frustum(-1, nan, -1, 1, 0.1, 10.0), std::invalid_argument);
    EXPECT_THROW(mr::frustum(-1, 1, -1, 1, 0.1, inf, mr::DepthConvention::opengl), std::invalid_argument);
    EXPECT_THROW(mr::perspective(0.0, 1.0, 0.1), std::invalid_argument);
    EXPECT_THROW(mr::perspective(3.2, 1.0, 0.1), std::invalid_argument);
    EXPECT_THROW(mr::perspective(1.0, 0.0, 0.1), std::invalid_argument);
    // A near plane too small for float32 depth (near / distance rounds to 0, the clear depth): the
    // message names near and the smallest allowed value, for every perspective constructor.
    const double too_small = std::nextafter(mr::kMinPerspectiveNear, 0.0);
    for (const double n : {1e-45, 1e-40, too_small, 1e-320}) {
        for (const mr::DepthConvention c : {mr::DepthConvention::reverse_z, mr::DepthConvention::opengl}) {
            const std::string message = thrown_message([&] { mr::frustum(-1, 1, -1, 1, n, 10.0, c); });
            EXPECT_NE(message.find("near = "), std::string::npos) << message;
            EXPECT_NE(message.find(">= 1.17549435e-38"), std::string::npos) << message;
        }
        EXPECT_THROW(mr::perspective(1.0, 1.0, n), std::invalid_argument) << n;
        EXPECT_THROW(mr::Camera::look_at_perspective({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 1.0, 1.0, n),
                     std::invalid_argument)
            << n;
    }
    EXPECT_EQ(mr::kMinPerspectiveNear, static_cast<double>(std::numeric_limits<float>::min()));
    EXPECT_NO_THROW(mr::perspective(1.0, 1.0, mr::kMinPerspectiveNear));
    EXPECT_NO_THROW(mr::perspective(1.0, 1.0, 1e-3));  // the depth contract's near
    EXPECT_NO_THROW(mr::orthographic(-1, 1, -1, 1, 1e-45, 10.0));  // linear depth: any near
    EXPECT_THROW(mr::orthographic(-1, 1, -1, 1, 1.0, 1.0), std::invalid_argument);
    EXPECT_THROW(mr::orthographic(-1, 1, -1, 1, 1.0, inf), std::invalid_argument);
    EXPECT_THROW(mr::look_at({1, 2, 3}, {1, 2, 3}, {0, 1, 0}), std::invalid_argument);
    EXPECT_THROW(mr::look_at({0, 0, 0}, {0, 5, 0}, {0, 1, 0}), std::invalid_argument);
    glm::dmat4 bad(1.0);
    bad[1][2] = nan;
    try {
        mr::Camera::from_matrices(bad, glm::dmat4(1.0));
        ADD_FAILURE() << "a NaN view matrix was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("view"), std::string::npos) << e.what();
    }
    try {
        mr::Camera::from_matrices(glm::dmat4(1.0), bad);
        ADD_FAILURE() << "a NaN projection matrix was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("projection"), std::string::npos) << e.what();
    }
}

}  // namespace
