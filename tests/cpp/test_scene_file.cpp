// Tests for mipraster/io/scene_file.hpp: OBJ/MTL and glTF (.gltf with a data-URI buffer, .glb
// built here) load positions, indices, colours, transforms, materials and cameras; hostile files
// give errors that name the file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "mipraster/io/scene_file.hpp"

namespace fs = std::filesystem;
namespace mr = mipraster;

namespace {

std::string output_path(const std::string& name) {
    const fs::path dir = fs::path(MIPRASTER_TEST_OUTPUT_DIR) / "scene_file";
    fs::create_directories(dir);
    return (dir / name).string();
}

std::string write_file(const std::string& name, const std::string& bytes) {
    const std::string path = output_path(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
}

std::string base64(const std::vector<unsigned char>& data) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < data.size(); i += 3) {
        const std::uint32_t b0 = data[i], b1 = i + 1 < data.size() ? data[i + 1] : 0,
                            b2 = i + 2 < data.size() ? data[i + 2] : 0;
        const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < data.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < data.size() ? table[v & 63] : '=';
    }
    return out;
}

template <class T>
void append(std::vector<unsigned char>& out, T value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.insert(out.end(), bytes, bytes + sizeof(T));
}

// 56 bytes: 3 float positions [0, 36), 3 normalized ubyte RGBA colours [36, 48), 3 ushort indices [48, 54).
std::vector<unsigned char> triangle_buffer(std::uint16_t last_index = 2) {
    std::vector<unsigned char> b;
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) append(b, v);
    for (unsigned char c : {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 255}) b.push_back(c);
    for (std::uint16_t i : {std::uint16_t(0), std::uint16_t(1), last_index}) append(b, i);
    b.push_back(0);
    b.push_back(0);
    return b;
}

// A glTF document: node 0 (mesh 0, translation (1,2,3)) with child node 1 (mesh 0, scale 2),
// node 2 (perspective camera at z = 5), node 3 (orthographic camera, matrix translating x by 4).
// Mesh 0 has a TRIANGLES primitive (material 0, BLEND, double-sided) and a LINES primitive.
std::string gltf_json(const std::string& buffer, std::size_t byte_length, const std::string& position_count = "3") {
    return R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 2, 3]}],
  "nodes": [
    {"mesh": 0, "translation": [1, 2, 3], "children": [1]},
    {"mesh": 0, "scale": [2, 2, 2]},
    {"camera": 0, "translation": [0, 0, 5]},
    {"camera": 1, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 4,0,0,1]}
  ],
  "cameras": [
    {"type": "perspective", "name": "persp", "perspective": {"yfov": 0.8, "znear": 0.1}},
    {"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 1, "znear": 0.5, "zfar": 50}}
  ],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1.0, 0.5]}, "alphaMode": "BLEND", "doubleSided": true}],
  "meshes": [{"primitives": [
    {"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2, "material": 0},
    {"attributes": {"POSITION": 0}, "mode": 1}
  ]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": )" + position_count + R"(, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"},
    {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36},
    {"buffer": 0, "byteOffset": 36, "byteLength": 12},
    {"buffer": 0, "byteOffset": 48, "byteLength": 6}
  ],
  "buffers": [{)" + buffer + R"("byteLength": )" + std::to_string(byte_length) + R"(}]
})";
}

std::string write_gltf(const std::string& name, const std::vector<unsigned char>& buffer,
                       const std::string& position_count = "3") {
    return write_file(name, gltf_json("\"uri\": \"data:application/octet-stream;base64," + base64(buffer) + "\", ",
                                      buffer.size(), position_count));
}

std::string glb_bytes(const std::vector<unsigned char>& buffer) {
    std::string json = gltf_json("", buffer.size());
    while (json.size() % 4) json += ' ';
    std::vector<unsigned char> bin = buffer;
    while (bin.size() % 4) bin.push_back(0);
    std::vector<unsigned char> out;
    append(out, std::uint32_t(0x46546C67));  // "glTF"
    append(out, std::uint32_t(2));
    append(out, std::uint32_t(12 + 8 + json.size() + 8 + bin.size()));
    append(out, std::uint32_t(json.size()));
    append(out, std::uint32_t(0x4E4F534A));  // "JSON"
    out.insert(out.end(), json.begin(), json.end());
    append(out, std::uint32_t(bin.size()));
    append(out, std::uint32_t(0x004E4942));  // "BIN\0"
    out.insert(out.end(), bin.begin(), bin.end());
    return std::string(out.begin(), out.end());
}

template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

void expect_mat_near(const glm::dmat4& a, const glm::dmat4& b) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(a[c][r], b[c][r], 1e-12) << "[" << c << "][" << r << "]";
}

void check_gltf_scene(const mr::LoadedScene& s) {
    // One mesh shared by the two nodes; the LINES primitive is skipped with a warning.
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.draws.size(), 2u);
    const mr::Mesh& m = *s.meshes[0];
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_EQ(m.positions[1], glm::vec3(1, 0, 0));
    EXPECT_EQ(m.positions[2], glm::vec3(0, 1, 0));
    ASSERT_EQ(m.triangles.size(), 1u);
    EXPECT_EQ(m.triangles[0], glm::uvec3(0, 1, 2));
    ASSERT_EQ(m.colors.size(), 3u);
    EXPECT_EQ(m.colors[0], glm::vec4(1, 0, 0, 1));
    const float a = 128.0f / 255.0f;  // BLEND: vertex colours premultiplied by their alpha
    EXPECT_NEAR(m.colors[1].g, a, 1e-6);
    EXPECT_NEAR(m.colors[1].a, a, 1e-6);
    EXPECT_EQ(s.draws[0].mesh, &m);
    EXPECT_EQ(s.draws[1].mesh, &m);
    // Transforms: node 0 translates, node 1 (its child) scales as well.
    const glm::dmat4 t = glm::translate(glm::dmat4(1.0), glm::dvec3(1, 2, 3));
    expect_mat_near(s.draws[0].model, t);
    expect_mat_near(s.draws[1].model, glm::scale(t, glm::dvec3(2.0)));
    // Material: premultiplied base colour, blended over, double-sided (no culling).
    EXPECT_EQ(s.draws[0].color, glm::vec4(0.25f, 0.125f, 0.5f, 0.5f));
    EXPECT_EQ(s.draws[0].state.blend, mr::BlendMode::over);
    EXPECT_EQ(s.draws[0].state.cull, mr::CullMode::none);
    bool warned = false;
    for (const auto& w : s.warnings) warned |= w.find("2 primitive(s)") != std::string::npos;
    EXPECT_TRUE(warned);
    // Cameras in node order.
    ASSERT_EQ(s.cameras.size(), 2u);
    const mr::NamedCamera& p = s.cameras[0];
    EXPECT_EQ(p.name, "persp");
    EXPECT_EQ(p.projection, mr::NamedCamera::Projection::perspective);
    EXPECT_DOUBLE_EQ(p.yfov, 0.8);
    EXPECT_DOUBLE_EQ(p.znear, 0.1);
    EXPECT_TRUE(std::isinf(p.zfar));
    expect_mat_near(p.view, glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, -5)));
    const mr::Camera pc = p.build(2.0);
    expect_mat_near(pc.projection, mr::perspective(0.8, 2.0, 0.1, mr::kInfiniteFar));
    EXPECT_EQ(pc.depth_convention, mr::DepthConvention::reverse_z);
    const mr::NamedCamera& o = s.cameras[1];
    EXPECT_EQ(o.projection, mr::NamedCamera::Projection::orthographic);
    expect_mat_near(o.view, glm::translate(glm::dmat4(1.0), glm::dvec3(-4, 0, 0)));
    expect_mat_near(o.build(1.0).projection, mr::orthographic(-2, 2, -1, 1, 0.5, 50));
}

}  // namespace

TEST(SceneFile, GltfWithDataUriLoads) {
    check_gltf_scene(mr::load_scene(write_gltf("scene.gltf", triangle_buffer())));
}

TEST(SceneFile, GlbLoads) {
    check_gltf_scene(mr::load_scene(write_file("scene.glb", glb_bytes(triangle_buffer()))));
}

TEST(SceneFile, GltfCameraAspectRatioFromTheFileWins) {
    std::string json = gltf_json("\"uri\": \"data:application/octet-stream;base64," + base64(triangle_buffer()) + "\", ", 56);
    const std::string from = R"("yfov": 0.8, "znear": 0.1)";
    json.replace(json.find(from), from.size(), R"("yfov": 0.8, "znear": 0.1, "zfar": 100, "aspectRatio": 1.5)");
    const auto s = mr::load_scene(write_file("aspect.gltf", json));
    expect_mat_near(s.cameras[0].build(3.0).projection, mr::perspective(0.8, 1.5, 0.1, 100.0));
}

TEST(SceneFile, ObjWithMaterialsAndVertexColours) {
    write_file("quad.mtl", "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 0.5\n");
    const std::string path = write_file("quad.obj",
                                        "mtllib quad.mtl\n"
                                        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 1\n"
                                        "vt 0 0\n"
                                        "usemtl red\nf 1 2 3 4\n"
                                        "usemtl blue\nf 1 3 4\n");
    const auto s = mr::load_scene(path);
    ASSERT_EQ(s.draws.size(), 2u);
    EXPECT_TRUE(s.cameras.empty());
    EXPECT_EQ(s.draws[0].color, glm::vec4(1, 0, 0, 1));
    EXPECT_EQ(s.draws[1].color, glm::vec4(0, 0, 0.5f, 1));
    const mr::Mesh& quad = *s.draws[0].mesh;
    ASSERT_EQ(quad.positions.size(), 4u);  // the quad, triangulated
    ASSERT_EQ(quad.triangles.size(), 2u);
    ASSERT_EQ(quad.colors.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {  // each corner keeps its colour (the diagonal is the loader's choice)
        const glm::vec3 p = quad.positions[i];
        const glm::vec4 expected = p == glm::vec3(0, 0, 0)   ? glm::vec4(1, 0, 0, 1)
                                   : p == glm::vec3(1, 0, 0) ? glm::vec4(0, 1, 0, 1)
                                   : p == glm::vec3(1, 1, 0) ? glm::vec4(0, 0, 1, 1)
                                                             : glm::vec4(1, 1, 1, 1);
        EXPECT_EQ(quad.colors[i], expected) << i;
    }
    EXPECT_NE(quad.triangles[0], quad.triangles[1]);
    const mr::Mesh& tri = *s.draws[1].mesh;  // compacted to the vertices it uses: 1, 3, 4
    ASSERT_EQ(tri.positions.size(), 3u);
    EXPECT_EQ(tri.triangles[0], glm::uvec3(0, 1, 2));
    EXPECT_EQ(tri.positions[1], glm::vec3(1, 1, 0));
    EXPECT_EQ(tri.colors[2], glm::vec4(1, 1, 1, 1));
}

TEST(SceneFile, ObjWithoutColoursOrMaterials) {
    const auto s = mr::load_scene(write_file("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
    ASSERT_EQ(s.draws.size(), 1u);
    EXPECT_FALSE(s.draws[0].mesh->has_colors());
    EXPECT_EQ(s.draws[0].color, glm::vec4(1.0f));
}

TEST(SceneFile, FramingCameraSeesTheBoundingBoxCentre) {
    const auto s = mr::load_scene(write_file("frame.obj", "v 10 0 0\nv 12 0 0\nv 10 2 0\nf 1 2 3\n"));
    const mr::Camera c = mr::framing_camera(s.draws, 0.9, 1.0);
    const glm::dvec4 clip = c.projection * c.view * glm::dvec4(11, 1, 0, 1);
    EXPECT_NEAR(clip.x / clip.w, 0.0, 1e-9);
    EXPECT_NEAR(clip.y / clip.w, 0.0, 1e-9);
    for (const glm::vec3& p : s.draws[0].mesh->positions) {  // every vertex is in view
        const glm::dvec4 q = c.projection * c.view * glm::dvec4(glm::dvec3(p), 1.0);
        EXPECT_GT(q.w, 0.0);
        EXPECT_LE(std::abs(q.x / q.w), 1.0);
        EXPECT_LE(std::abs(q.y / q.w), 1.0);
    }
}

// --- hostile files: errors name the file, never a crash ---------------------------------------

TEST(SceneFile, MissingFilesNameThePath) {
    for (const char* name : {"missing.obj", "missing.gltf", "missing.glb"}) {
        const std::string path = output_path(name);
        const std::string e = error_of([&] { mr::load_scene(path); });
        EXPECT_NE(e.find(path), std::string::npos) << e;
    }
}

TEST(SceneFile, UnknownExtensionNamesPathAndFormats) {
    const std::string path = output_path("scene.fbx");
    try {
        mr::load_scene(path);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find(path), std::string::npos) << m;
        EXPECT_NE(m.find(".obj, .gltf, .glb"), std::string::npos) << m;
    }
}

TEST(SceneFile, CorruptAndTruncatedFilesNameTheFile) {
    const std::string json = gltf_json("\"uri\": \"data:application/octet-stream;base64," + base64(triangle_buffer()) + "\", ", 56);
    const std::string glb = glb_bytes(triangle_buffer());
    const std::vector<std::string> paths = {
        write_file("truncated.gltf", json.substr(0, json.size() / 2)),
        write_file("garbage.gltf", "\x01\x02not json at all"),
        write_file("truncated.glb", glb.substr(0, glb.size() - 20)),
        write_file("header_only.glb", glb.substr(0, 16)),
        write_file("garbage.glb", "glTF\x02\0\0\0\xff\xff\xff\xff"),
        write_gltf("short_buffer.gltf", std::vector<unsigned char>(10, 0)),
        write_gltf("index_out_of_range.gltf", triangle_buffer(7)),
        write_gltf("absurd_count.gltf", triangle_buffer(), "4000000000"),
        write_gltf("huge_count.gltf", triangle_buffer(), "100000000000000000000"),
        write_file("bad_face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
    };
    for (const std::string& path : paths) {
        const std::string e = error_of([&] { mr::load_scene(path); });
        EXPECT_FALSE(e.empty()) << path << " loaded without error";
        EXPECT_NE(e.find(path), std::string::npos) << e;
    }
}

TEST(SceneFile, NodeCycleIsAnError) {
    std::string json = gltf_json("\"uri\": \"data:application/octet-stream;base64," + base64(triangle_buffer()) + "\", ", 56);
    const std::string from = R"({"mesh": 0, "scale": [2, 2, 2]})";
    json.replace(json.find(from), from.size(), R"({"mesh": 0, "scale": [2, 2, 2], "children": [0]})");
    const std::string path = write_file("cycle.gltf", json);
    const std::string e = error_of([&] { mr::load_scene(path); });
    EXPECT_NE(e.find(path), std::string::npos) << e;
}
