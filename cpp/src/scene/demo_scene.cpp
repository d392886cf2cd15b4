#include "mipraster/scene/demo_scene.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace mipraster {

namespace {

// Checks of kCheckSize world units, kChecks × kChecks of them, centred under the cube: the far
// rows are a pixel or less wide at the horizon.
constexpr int kChecks = 160;
constexpr float kCheckSize = 2.0f;

// Appends a quad (a, b, c, d counter-clockwise seen from its front) with one colour per corner.
void add_quad(Mesh& m, const glm::vec3 (&p)[4], const glm::vec4 (&c)[4]) {
    const auto base = static_cast<unsigned>(m.positions.size());
    for (int i = 0; i < 4; ++i) {
        m.positions.push_back(p[i]);
        m.colors.push_back(c[i]);
    }
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
}

std::shared_ptr<Mesh> make_ground() {
    auto m = std::make_shared<Mesh>();
    const glm::vec4 light(0.80f, 0.78f, 0.72f, 1.0f), dark(0.06f, 0.09f, 0.12f, 1.0f);
    const float half = kChecks * kCheckSize / 2.0f;
    for (int j = 0; j < kChecks; ++j)
        for (int i = 0; i < kChecks; ++i) {
            const float x0 = -half + i * kCheckSize, z0 = -half + j * kCheckSize;
            const float x1 = x0 + kCheckSize, z1 = z0 + kCheckSize;
            const glm::vec4 c = ((i + j) % 2) ? light : dark;
            add_quad(*m, {{x0, 0, z1}, {x1, 0, z1}, {x1, 0, z0}, {x0, 0, z0}}, {c, c, c, c});
        }
    return m;
}

std::shared_ptr<Mesh> make_cube() {
    // Lambert shading baked into vertex colours, with a vertical gradient per face so the
    // perspective-correct interpolation is visible.
    auto m = std::make_shared<Mesh>();
    const glm::vec3 light_dir = glm::normalize(glm::vec3(-0.5f, 0.9f, 0.6f));
    const glm::vec3 albedo(0.85f, 0.25f, 0.10f);
    const glm::vec3 n[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const glm::vec3& normal : n) {
        // Two tangents so that (t1, t2, normal) is right-handed: corners run counter-clockwise
        // when seen from outside.
        const glm::vec3 t1 = std::abs(normal.y) > 0.5f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
        const glm::vec3 t2 = glm::cross(normal, t1);
        const glm::vec3 centre = normal + glm::vec3(0, 1, 0);  // cube [-1,1]³ resting on y = 0
        glm::vec3 p[4];
        glm::vec4 c[4];
        const float s1[4] = {-1, 1, 1, -1}, s2[4] = {-1, -1, 1, 1};
        const float lambert = 0.15f + 0.85f * std::max(0.0f, glm::dot(normal, light_dir));
        for (int k = 0; k < 4; ++k) {
            p[k] = centre + s1[k] * t1 + s2[k] * t2;
            const float height = 0.75f + 0.25f * (p[k].y / 2.0f);
            c[k] = glm::vec4(albedo * lambert * height, 1.0f);
        }
        // Reorder so the winding is counter-clockwise about the outward normal.
        if (glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), normal) < 0) {
            std::swap(p[1], p[3]);
            std::swap(c[1], c[3]);
        }
        add_quad(*m, p, c);
    }
    return m;
}

}  // namespace

DemoScene make_demo_scene(double aspect) {
    DemoScene s;
    s.meshes = {make_ground(), make_cube()};
    DrawState state;
    state.interpolation = Interpolation::perspective;
    Draw ground{s.meshes[0].get(), glm::dmat4(1.0), glm::vec4(1.0f), state};
    state.cull = CullMode::back;  // a closed mesh: its back faces are never seen
    Draw cube{s.meshes[1].get(),
              glm::dmat4(glm::dvec4(0.8660, 0, -0.5, 0), glm::dvec4(0, 1, 0, 0), glm::dvec4(0.5, 0, 0.8660, 0),
                         glm::dvec4(0, 0, 0, 1)),  // 30° about y
              glm::vec4(1.0f), state};
    s.draws = {ground, cube};
    s.eye = {5.5, 4.0, 5.5};
    s.target = {0.0, 0.8, 0.0};
    s.fovy = 0.9;
    s.near = 0.05;
    s.camera = Camera::look_at_perspective(s.eye, s.target, {0, 1, 0}, s.fovy, aspect, s.near);
    s.clear_color = glm::vec4(0.35f, 0.55f, 0.85f, 1.0f);
    return s;
}

}  // namespace mipraster
