#include "mipraster/scene/demo_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/vec2.hpp>

#include <glm/geometric.hpp>

namespace mipraster {

namespace {

// The ground: one quad of kGroundSize world units, its texture repeated kGroundRepeats times
// across it, so the far checks shrink below a pixel at the horizon (what mip-mapping is for).
constexpr float kGroundSize = 320.0f;
constexpr float kGroundRepeats = 20.0f;
constexpr int kGroundTexture = 512;  // texels; 8×8 checks of 64 texels
constexpr int kCubeTexture = 256;

// Appends a quad (a, b, c, d counter-clockwise seen from its front) with a colour and uv per corner.
void add_quad(Mesh& m, const glm::vec3 (&p)[4], const glm::vec4 (&c)[4], const glm::vec2 (&uv)[4]) {
    const auto base = static_cast<unsigned>(m.positions.size());
    for (int i = 0; i < 4; ++i) {
        m.positions.push_back(p[i]);
        m.colors.push_back(c[i]);
        m.uvs.push_back(uv[i]);
    }
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
}

// sRGB8 RGB texels from a colour function of the texel position.
template <typename Colour>
Texture procedural_texture(int size, const char* name, Colour colour) {
    std::vector<std::uint8_t> texels(static_cast<std::size_t>(size) * size * 3);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const glm::ivec3 c = colour(x, y);
            for (int k = 0; k < 3; ++k) texels[(static_cast<std::size_t>(y) * size + x) * 3 + k] = static_cast<std::uint8_t>(c[k]);
        }
    return Texture::from_8bit(texels.data(), size, size, 3, true, name);
}

// Light and dark checks with a thin dark seam along their edges.
Texture ground_texture() {
    return procedural_texture(kGroundTexture, "demo:checker", [](int x, int y) {
        const int check = kGroundTexture / 8;
        const bool seam = x % check < 2 || y % check < 2;
        if (seam) return glm::ivec3(40, 44, 50);
        return ((x / check + y / check) % 2) ? glm::ivec3(228, 224, 212) : glm::ivec3(70, 84, 100);
    });
}

// A framed 4×4 grid of coloured tiles, so each cube face shows its texture's orientation.
Texture cube_texture() {
    return procedural_texture(kCubeTexture, "demo:tiles", [](int x, int y) {
        const int frame = kCubeTexture / 16, tile = (kCubeTexture - 2 * frame) / 4;
        if (x < frame || y < frame || x >= kCubeTexture - frame || y >= kCubeTexture - frame)
            return glm::ivec3(60, 40, 30);
        const int i = (x - frame) / tile, j = (y - frame) / tile;
        if ((x - frame) % tile < 3 || (y - frame) % tile < 3) return glm::ivec3(240, 235, 220);
        static const glm::ivec3 hues[4] = {{220, 80, 40}, {240, 180, 40}, {60, 150, 200}, {90, 170, 80}};
        return hues[(i + 2 * j) % 4];
    });
}

std::shared_ptr<Mesh> make_ground() {
    auto m = std::make_shared<Mesh>();
    const float h = kGroundSize / 2.0f, r = kGroundRepeats;
    const glm::vec4 white(1.0f);
    add_quad(*m, {{-h, 0, h}, {h, 0, h}, {h, 0, -h}, {-h, 0, -h}}, {white, white, white, white},
             {{0, r}, {r, r}, {r, 0}, {0, 0}});
    return m;
}

std::shared_ptr<Mesh> make_cube() {
    // Lambert shading baked into vertex colours (they multiply the texture).
    auto m = std::make_shared<Mesh>();
    const glm::vec3 light_dir = glm::normalize(glm::vec3(-0.5f, 0.9f, 0.6f));
    const glm::vec3 n[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const glm::vec3& normal : n) {
        // Two tangents so that (t1, t2, normal) is right-handed: corners run counter-clockwise
        // when seen from outside.
        const glm::vec3 t1 = std::abs(normal.y) > 0.5f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
        const glm::vec3 t2 = glm::cross(normal, t1);
        const glm::vec3 centre = normal + glm::vec3(0, 1, 0);  // cube [-1,1]³ resting on y = 0
        glm::vec3 p[4];
        glm::vec4 c[4];
        glm::vec2 uv[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
        const float s1[4] = {-1, 1, 1, -1}, s2[4] = {-1, -1, 1, 1};
        const float lambert = 0.2f + 0.8f * std::max(0.0f, glm::dot(normal, light_dir));
        for (int k = 0; k < 4; ++k) {
            p[k] = centre + s1[k] * t1 + s2[k] * t2;
            c[k] = glm::vec4(glm::vec3(lambert), 1.0f);
        }
        // Reorder so the winding is counter-clockwise about the outward normal.
        if (glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), normal) < 0) {
            std::swap(p[1], p[3]);
            std::swap(c[1], c[3]);
            std::swap(uv[1], uv[3]);
        }
        add_quad(*m, p, c, uv);
    }
    return m;
}

}  // namespace

DemoScene make_demo_scene(double aspect) {
    DemoScene s;
    s.meshes = {make_ground(), make_cube()};
    Draw ground;
    ground.mesh = s.meshes[0].get();
    ground.texture = ground_texture();
    ground.sampler = Sampler::from_filter_name("anisotropic");
    Draw cube;
    cube.mesh = s.meshes[1].get();
    cube.model = glm::dmat4(glm::dvec4(0.8660, 0, -0.5, 0), glm::dvec4(0, 1, 0, 0), glm::dvec4(0.5, 0, 0.8660, 0),
                            glm::dvec4(0, 0, 0, 1));  // 30° about y
    cube.texture = cube_texture();
    cube.sampler = Sampler::from_filter_name("anisotropic");
    cube.state.cull = CullMode::back;  // a closed mesh: its back faces are never seen
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
