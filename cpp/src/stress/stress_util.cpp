#include "stress_util.hpp"

#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

#include "mipraster/stress/exact_coverage.hpp"

namespace mipraster::stress {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

std::string fmt(double value, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    return buf;
}

std::string count(std::uint64_t n) {
    std::string s = std::to_string(n), out;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (i && (s.size() - i) % 3 == 0) out += ',';
        out += s[i];
    }
    return out;
}

glm::dmat4 fixed_to_ndc(int width, int height) {
    glm::dmat4 m(1.0);
    m[0][0] = 1.0 / (128.0 * width);
    m[3][0] = -1.0;
    m[1][1] = -1.0 / (128.0 * height);
    m[3][1] = 1.0;
    return m;
}

Camera identity_camera() { return Camera::from_matrices(glm::dmat4(1.0), glm::dmat4(1.0), DepthConvention::opengl); }

StressScene coverage_scene(std::string name, std::shared_ptr<Mesh> mesh, int width, int height, int samples,
                           PatternKind pattern) {
    StressScene sc;
    sc.name = std::move(name);
    Draw d;
    d.mesh = mesh.get();
    d.model = fixed_to_ndc(width, height);
    d.state.depth_test = false;
    d.state.depth_write = false;
    d.state.blend = BlendMode::add;
    sc.draws.push_back(d);
    sc.meshes.push_back(std::move(mesh));
    sc.camera = identity_camera();
    sc.settings.width = width;
    sc.settings.height = height;
    sc.settings.samples = samples;
    sc.settings.pattern = pattern;
    sc.settings.keep_samples = true;
    sc.settings.threads = 2;
    return sc;
}

RenderResult render_scene(const StressScene& scene) { return render(scene.draws, scene.camera, scene.settings); }

CoverageComparison compare_coverage(const StressScene& scene, const RenderResult& result) {
    CoverageComparison c;
    const Framebuffer& fb = result.framebuffer;
    const int W = fb.width, H = fb.height, S = fb.samples;
    c.pattern_ok = pattern_is_documented(result.pattern);
    std::vector<int> counts(static_cast<std::size_t>(W) * H * S, 0);
    for (const auto& mesh : scene.meshes)
        for (const glm::uvec3& t : mesh->triangles) {
            std::array<FixedPoint, 3> v;
            for (int i = 0; i < 3; ++i)
                v[i] = {exact_snap(double(mesh->positions[t[i]].x)), exact_snap(double(mesh->positions[t[i]].y))};
            exact_accumulate(v, W, H, result.pattern, counts);
        }
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int s = 0; s < S; ++s) {
                const std::size_t i = fb.sample_index(x, y, s);
                const float got = fb.color[4 * i];
                const int want = counts[(static_cast<std::size_t>(y) * W + x) * S + s];
                ++c.samples;
                if (!std::isfinite(got) || !std::isfinite(fb.color[4 * i + 3])) c.finite = false;
                c.oracle_covered += want > 0;
                c.oracle_twice += want > 1;
                c.cracks += want > 0 && got == 0.0f;
                c.double_hits += got > float(want);
                c.mismatches += got != float(want);
            }
    return c;
}

std::shared_ptr<Mesh> jittered_grid_mesh(int nx, int ny, double x0, double y0, double x1, double y1, bool integer_units,
                                         std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2);  // keeps every quad convex: conforming
    const double cx = (x1 - x0) / nx, cy = (y1 - y0) / ny;
    auto m = std::make_shared<Mesh>();
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) {
            // Border vertices stay on the border so the grid's outline is a rectangle.
            double x = x0 + (i + (i > 0 && i < nx ? jitter(rng) : 0.0)) * cx;
            double y = y0 + (j + (j > 0 && j < ny ? jitter(rng) : 0.0)) * cy;
            x *= 256.0;
            y *= 256.0;
            if (integer_units) {
                x = std::round(x);
                y = std::round(y);
            }
            m->positions.push_back(glm::vec3(float(x), float(y), 0.0f));
        }
    auto idx = [&](int i, int j) { return static_cast<std::uint32_t>(j * (nx + 1) + i); };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const std::uint32_t a = idx(i, j), b = idx(i + 1, j), c = idx(i + 1, j + 1), d = idx(i, j + 1);
            const bool main = rng() & 1;
            const std::uint32_t t[2][3] = {{a, b, main ? c : d}, {main ? a : b, c, d}};
            for (const auto& tri : t)
                m->triangles.push_back(rng() & 1 ? glm::uvec3(tri[0], tri[1], tri[2]) : glm::uvec3(tri[0], tri[2], tri[1]));
        }
    return m;
}

std::shared_ptr<Mesh> fan_mesh(double cx, double cy, double r, int n) {
    auto m = std::make_shared<Mesh>();
    m->positions.push_back(glm::vec3(float(cx * 256.0), float(cy * 256.0), 0.0f));
    for (int k = 0; k < n; ++k) {
        const double a = 2.0 * kPi * k / n;
        m->positions.push_back(glm::vec3(float((cx + r * std::cos(a)) * 256.0), float((cy + r * std::sin(a)) * 256.0), 0.0f));
    }
    for (int k = 0; k < n; ++k) {
        const std::uint32_t a = 1 + k, b = 1 + (k + 1) % n;
        m->triangles.push_back(k % 2 ? glm::uvec3(0, b, a) : glm::uvec3(0, a, b));
    }
    return m;
}

std::shared_ptr<Mesh> sliver_mesh(int width_px, int height_px, double length, double width, int count, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> pos(0.25, 0.75), unit(0.0, 1.0);
    auto m = std::make_shared<Mesh>();
    for (int k = 0; k < count; ++k) {
        // Angles cover [0, π) evenly (axis-aligned and diagonal ones included), the centre a random
        // point of the middle of the viewport; the apex is at one end, the base `width` wide at the other.
        const double a = kPi * k / count;
        const glm::dvec2 dir(std::cos(a), std::sin(a)), normal(-dir.y, dir.x);
        const glm::dvec2 c(pos(rng) * width_px, pos(rng) * height_px);
        const double t = unit(rng);  // where along its length the sliver crosses the centre
        const glm::dvec2 apex = c - t * length * dir;
        const glm::dvec2 base = c + (1.0 - t) * length * dir;
        const glm::dvec2 p[3] = {apex, base + 0.5 * width * normal, base - 0.5 * width * normal};
        const std::uint32_t first = static_cast<std::uint32_t>(m->positions.size());
        for (const glm::dvec2& q : p) m->positions.push_back(glm::vec3(float(q.x * 256.0), float(q.y * 256.0), 0.0f));
        m->triangles.push_back(glm::uvec3(first, first + 1, first + 2));
    }
    return m;
}

ClipScene huge_scene(int width, double radius, int count, std::uint64_t seed,
                     std::vector<std::array<glm::dvec2, 3>>* units) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> pos(0.1, 0.9), angle(0.0, 2.0 * kPi);
    ClipScene sc;
    sc.name = "huge triangles " + fmt(radius) + " px";
    for (int k = 0; k < count; ++k) {
        // Edge 0–1 passes through a point q of the viewport; vertex 2 is `radius` away to one side,
        // so the viewport holds one long edge of the triangle and the interior on one side of it.
        const glm::dvec2 q(pos(rng) * width, pos(rng) * width);
        const double a = angle(rng);
        const glm::dvec2 dir(std::cos(a), std::sin(a)), normal(-dir.y, dir.x);
        const std::array<glm::dvec2, 3> p = {q - radius * dir, q + radius * dir, q + radius * normal};
        const std::uint32_t first = static_cast<std::uint32_t>(sc.clip.size());
        std::array<glm::dvec2, 3> u;
        for (int i = 0; i < 3; ++i) {
            const glm::dvec4 c(2.0 * p[i].x / width - 1.0, 1.0 - 2.0 * p[i].y / width, 0.0, 1.0);
            sc.clip.push_back(c);
            // The screen position these clip coordinates hold (NDC ± 1 is exact at these
            // magnitudes, the rest are powers of two): the vertex the pipeline is given, not the
            // p above, which NDC cannot hold to a pixel at 10^15 px.
            u[i] = glm::dvec2((c.x + 1.0) * (0.5 * width) * 256.0, (1.0 - c.y) * (0.5 * width) * 256.0);
        }
        if (units) units->push_back(u);
        sc.triangles.push_back(glm::uvec3(first, first + 1, first + 2));
    }
    sc.settings.width = sc.settings.height = width;
    sc.settings.samples = 4;
    sc.settings.pattern = PatternKind::rotated;
    sc.settings.threads = 2;
    return sc;
}

StressScene grazing_scene(double angle_degrees, int width, int height, int samples) {
    // A 64×64 checker (8-texel squares, linear 0/1) on the plane y = 0, uv = (x, z)/4 with repeat;
    // the camera at height 1 looks along −z tilted down so the view axis meets the plane at
    // (90° − angle) — the plane's normal makes `angle` with the view direction.
    StressScene sc;
    sc.name = "grazing plane " + fmt(angle_degrees, 6) + " deg";
    auto m = std::make_shared<Mesh>();
    const float extent = 1e6f;
    m->positions = {{-extent, 0.0f, 0.0f}, {extent, 0.0f, 0.0f}, {extent, 0.0f, -extent}, {-extent, 0.0f, -extent}};
    m->uvs = {{-extent / 4, 0.0f}, {extent / 4, 0.0f}, {extent / 4, extent / 4}, {-extent / 4, extent / 4}};
    m->triangles = {{0, 1, 2}, {0, 2, 3}};
    std::vector<float> texels(64 * 64);
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 64; ++i) texels[j * 64 + i] = float((i / 8 + j / 8) % 2);
    Draw d;
    d.mesh = m.get();
    d.texture = Texture::from_float(texels.data(), 64, 64, 1, true, "checker 64");
    d.sampler = Sampler::from_filter_name("anisotropic");
    sc.draws.push_back(d);
    sc.meshes.push_back(m);
    const double pitch = (90.0 - angle_degrees) * kPi / 180.0;  // below the horizontal
    const glm::dvec3 eye(0.0, 1.0, 0.0), dir(0.0, -std::sin(pitch), -std::cos(pitch));
    sc.camera = Camera::look_at_perspective(eye, eye + dir, {0.0, 1.0, 0.0}, 60.0 * kPi / 180.0,
                                            double(width) / height, 1e-3);
    sc.settings.width = width;
    sc.settings.height = height;
    sc.settings.samples = samples;
    sc.settings.keep_samples = true;
    sc.settings.threads = 2;
    return sc;
}

StressScene depth_scene(bool reverse_z, double near, double far, double distance, double separation, bool near_first,
                        int size) {
    // Two quads, the same tilted square (30° about y) at `distance` and `distance·(1 + separation)`
    // along the view axis, each scaled to fill the view; green is the nearer, red the farther.
    StressScene sc;
    sc.name = std::string(reverse_z ? "reverse-Z" : "OpenGL") + " depth d=" + fmt(distance) + " sep=" + fmt(separation);
    auto m = std::make_shared<Mesh>();
    m->positions = {{-1.0f, -1.0f, 0.0f}, {1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {-1.0f, 1.0f, 0.0f}};
    m->triangles = {{0, 1, 2}, {0, 2, 3}};
    sc.meshes.push_back(m);
    const double fov = 0.5;  // radians; the quad (half-width d·tan(fov/2)·2) overfills the view
    auto quad = [&](double z, glm::vec4 colour) {
        Draw d;
        d.mesh = m.get();
        glm::dmat4 model = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -z));
        model = glm::rotate(model, 30.0 * kPi / 180.0, glm::dvec3(0.0, 1.0, 0.0));
        model = glm::scale(model, glm::dvec3(distance * std::tan(fov) * 2.0));
        d.model = model;
        d.color = colour;
        return d;
    };
    const Draw nearer = quad(distance, {0.0f, 1.0f, 0.0f, 1.0f});
    const Draw farther = quad(distance * (1.0 + separation), {1.0f, 0.0f, 0.0f, 1.0f});
    sc.draws = near_first ? std::vector<Draw>{nearer, farther} : std::vector<Draw>{farther, nearer};
    const DepthConvention conv = reverse_z ? DepthConvention::reverse_z : DepthConvention::opengl;
    glm::dmat4 projection(0.0);
    if (!reverse_z && std::isinf(far)) {
        // The OpenGL matrix in the limit far → ∞: z_clip = −z − 2n, w = −z.
        const double f = 1.0 / std::tan(0.5 * fov);
        projection[0][0] = f;
        projection[1][1] = f;
        projection[2][2] = -1.0;
        projection[2][3] = -1.0;
        projection[3][2] = -2.0 * near;
    } else {
        projection = perspective(fov, 1.0, near, far, conv);
    }
    sc.camera = Camera::from_matrices(glm::dmat4(1.0), projection, conv);
    sc.settings.width = sc.settings.height = size;
    sc.settings.samples = 1;
    sc.settings.threads = 2;
    return sc;
}

ClipScene near_plane_scene(int width, int samples) {
    ClipScene sc;
    sc.name = "near plane";
    sc.settings.width = sc.settings.height = width;
    sc.settings.samples = samples;
    sc.settings.threads = 2;
    sc.settings.depth_convention = DepthConvention::opengl;
    // OpenGL clip space (−w ≤ z ≤ w is visible). Each triangle is separate (own vertices).
    const std::vector<std::array<glm::dvec4, 3>> tris = {
        // w → 0⁺ at one vertex (in front of the near plane: z = −w/2), the others ordinary.
        {glm::dvec4(0.3, 0.2, -0.5e-12, 1e-12), glm::dvec4(-0.5, -0.4, 0.2, 1.0), glm::dvec4(0.6, -0.5, 0.3, 1.0)},
        // w = 0 exactly at one vertex.
        {glm::dvec4(0.4, 0.3, 0.0, 0.0), glm::dvec4(-0.6, -0.5, 0.1, 1.0), glm::dvec4(0.5, -0.6, 0.2, 1.0)},
        // w < 0 at one vertex: the triangle crosses the plane w = 0 (behind the eye).
        {glm::dvec4(0.2, 0.5, 0.5, -1.0), glm::dvec4(-0.5, -0.5, 0.0, 1.0), glm::dvec4(0.7, -0.3, 0.5, 1.0)},
        // Two vertices behind the eye, one in front.
        {glm::dvec4(0.2, 0.5, 0.5, -0.5), glm::dvec4(-0.8, 0.1, 0.4, -2.0), glm::dvec4(0.1, -0.3, 0.2, 1.0)},
        // Entirely behind the eye: must draw nothing.
        {glm::dvec4(0.2, 0.5, 0.5, -0.5), glm::dvec4(-0.8, 0.1, 0.4, -2.0), glm::dvec4(0.1, -0.3, 0.2, -1.0)},
        // Crossing the near plane (z = −w) at a grazing angle: z + w goes from −1e-9 to +1e-3.
        {glm::dvec4(-0.9, -0.1, -1.0 - 1e-9, 1.0), glm::dvec4(0.9, -0.05, -1.0 + 1e-3, 1.0), glm::dvec4(0.0, 0.1, -1.0 + 5e-4, 1.0)},
        // Crossing the near plane steeply, with a vertex at w ≈ 1e-300.
        {glm::dvec4(0.5, 0.5, -2e-300, 1e-300), glm::dvec4(-0.5, 0.4, 0.9, 1.0), glm::dvec4(0.0, -0.7, -1.5, 1.0)},
        // A triangle whose plane passes through the eye (seen edge-on): a line on screen.
        {glm::dvec4(0.0, 0.0, 0.0, 1.0), glm::dvec4(0.0, 0.0, 0.5, 2.0), glm::dvec4(0.5, 0.0, 0.0, 1.0)},
        // One vertex 10^20 behind the eye: the crossings next to it are rounded at its scale
        // unless computed from the endpoint nearer the plane.
        {glm::dvec4(-0.4e20, 0.3e20, 0.5e20, -1e20), glm::dvec4(-0.6, -0.5, 0.1, 1.0), glm::dvec4(0.7, -0.4, 0.3, 1.2)},
        // Every w near 10^46 (an ordinary triangle times 10^46): 1/w is below float's range.
        {glm::dvec4(0.3e46, 0.2e46, 0.1e46, 1e46), glm::dvec4(-0.5e46, -0.4e46, 0.2e46, 1.5e46),
         glm::dvec4(0.6e46, -0.5e46, 0.6e46, 2e46)},
    };
    for (const auto& t : tris) {
        const std::uint32_t first = static_cast<std::uint32_t>(sc.clip.size());
        for (const glm::dvec4& v : t) sc.clip.push_back(v);
        sc.triangles.push_back(glm::uvec3(first, first + 1, first + 2));
    }
    return sc;
}

}  // namespace mipraster::stress
