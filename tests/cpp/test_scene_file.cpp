// Tests for mipraster/io/scene_file.hpp: OBJ/MTL and glTF (.gltf with a data-URI buffer, .glb
// built here) load positions, indices, colours, uvs, normals, transforms, materials, base colour
// textures with their samplers, and cameras; hostile files give errors that name the file, and
// missing textures a warning and the error texture. Also mipraster/io/texture_file.hpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "mipraster/core/colour.hpp"
#include "mipraster/io/image_io.hpp"
#include "mipraster/io/scene_file.hpp"
#include "mipraster/io/texture_file.hpp"
#include "test_output.hpp"

namespace mr = mipraster;

namespace {

std::string output_path(const std::string& name) { return test_output_path("scene_file", name); }

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

TEST(SceneFile, GltfMaskKeepsVertexColourAlphaAndOpaqueDropsIt) {
    // The scene's material as MASK: COLOR_0's alpha counts (premultiplied, as for BLEND) and the
    // draw is alpha-tested, not blended; as OPAQUE the alpha is 1.
    const std::vector<unsigned char> buffer = triangle_buffer();
    const std::string json = gltf_json("\"uri\": \"data:application/octet-stream;base64," + base64(buffer) + "\", ",
                                       buffer.size());
    const float a = 128.0f / 255.0f;
    for (const std::string mode : {"MASK", "OPAQUE"}) {
        std::string text = json;
        text.replace(text.find("\"BLEND\""), 7, "\"" + mode + "\"");
        const auto s = mr::load_scene(write_file(mode + ".gltf", text));
        ASSERT_EQ(s.meshes.size(), 1u);
        const glm::vec4 c = s.meshes[0]->colors[1];
        EXPECT_EQ(s.draws[0].state.blend, mr::BlendMode::replace) << mode;
        if (mode == "MASK") {
            EXPECT_NEAR(c.g, a, 1e-6);
            EXPECT_NEAR(c.a, a, 1e-6);
            EXPECT_EQ(s.draws[0].color, glm::vec4(0.25f, 0.125f, 0.5f, 0.5f));
            EXPECT_EQ(s.draws[0].state.alpha_cutoff, 0.5f);
        } else {
            EXPECT_EQ(c, glm::vec4(0, 1, 0, 1));
            EXPECT_EQ(s.draws[0].color, glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
            EXPECT_FALSE(s.draws[0].state.alpha_cutoff);
        }
    }
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

// tinyobjloader would read these coordinates as 0; the loader refuses them, naming the line.
TEST(SceneFile, ObjCoordinatesThatAreNotFiniteNumbersNameTheLine) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1 ('v nan 0 0'): 'nan'"},
        {"v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n", "line 2 ('v 1 inf 0'): 'inf'"},
        {"v 0 0 0\nv 1 0 0\nv 0 1,5 0\nf 1 2 3\n", "line 3 ('v 0 1,5 0'): '1,5'"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 x\nf 1 2 3\n", "line 4 ('vt 0.5 x'): 'x'"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1e999\nf 1 2 3\n", "'1e999' is not a finite number"},
    };
    for (const auto& [text, expected] : cases) {
        const std::string path = write_file("not_a_number.obj", text);
        const std::string e = error_of([&] { mr::load_scene(path); });
        EXPECT_NE(e.find(expected), std::string::npos) << e;
        EXPECT_NE(e.find(path), std::string::npos) << e;
    }
    // Comments after the numbers and CRLF line ends are fine.
    const std::string ok = write_file("fine.obj", "v 0 0 0 # origin\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n");
    EXPECT_EQ(error_of([&] { mr::load_scene(ok); }), "");
}

TEST(SceneFile, FileWithoutTrianglesLoadsWithAWarning) {
    for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
             {"empty.obj", ""}, {"points_only.obj", "v 0 0 0\nv 1 0 0\n"}, {"lines_only.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n"}}) {
        const std::string path = write_file(name, text);
        const mr::LoadedScene s = mr::load_scene(path);
        bool warned = false;
        for (const std::string& w : s.warnings) warned |= w.find(path + ": the file holds no triangles") == 0;
        EXPECT_TRUE(warned) << name << ": " << s.warnings.size() << " other warnings";
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

TEST(SceneFile, GltfInstancingDrawsEachInstanceWithTheSharedMesh) {
    // Node 0 gets two EXT_mesh_gpu_instancing instances: translation (1, 0, 0) with a quarter turn
    // about z (a normalized short quaternion), and translation (0, −1, 0.5) unrotated. An _ID
    // attribute of another count is not read; the child node 1 is not instanced.
    std::vector<unsigned char> buffer = triangle_buffer();
    for (float v : {1.f, 0.f, 0.f, 0.f, -1.f, 0.5f}) append(buffer, v);
    for (std::int16_t q : {0, 0, 23170, 23170, 0, 0, 0, 32767}) append(buffer, q);
    std::string json = gltf_json("\"uri\": \"data:application/octet-stream;base64," + base64(buffer) + "\", ",
                                 buffer.size());
    const auto replace = [&](const std::string& from, const std::string& to) {
        ASSERT_NE(json.find(from), std::string::npos) << from;
        json.replace(json.find(from), from.size(), to);
    };
    replace(R"("asset")", R"("extensionsUsed": ["EXT_mesh_gpu_instancing"],
  "extensionsRequired": ["EXT_mesh_gpu_instancing"],
  "asset")");
    replace(R"("children": [1]})", R"("children": [1],
     "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 3, "ROTATION": 4, "_ID": 2}}}})");
    replace(R"("count": 3, "type": "SCALAR"})", R"("count": 3, "type": "SCALAR"},
    {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"},
    {"bufferView": 4, "componentType": 5122, "normalized": true, "count": 2, "type": "VEC4"})");
    replace(R"("byteOffset": 48, "byteLength": 6})", R"("byteOffset": 48, "byteLength": 6},
    {"buffer": 0, "byteOffset": 56, "byteLength": 24},
    {"buffer": 0, "byteOffset": 80, "byteLength": 16})");
    const mr::LoadedScene s = mr::load_scene(write_file("instanced.gltf", json));

    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.draws.size(), 3u);
    for (const mr::Draw& d : s.draws) EXPECT_EQ(d.mesh, s.meshes[0].get());  // shared, not copied
    const glm::dmat4 node = glm::translate(glm::dmat4(1.0), glm::dvec3(1, 2, 3));
    const glm::dmat4 quarter_turn(glm::dvec4(0, 1, 0, 0), glm::dvec4(-1, 0, 0, 0), glm::dvec4(0, 0, 1, 0),
                                  glm::dvec4(0, 0, 0, 1));  // columns: x → y, y → −x
    expect_mat_near(s.draws[0].model, glm::translate(node, glm::dvec3(1, 0, 0)) * quarter_turn);
    expect_mat_near(s.draws[1].model, glm::translate(node, glm::dvec3(0, -1, 0.5)));
    expect_mat_near(s.draws[2].model, glm::scale(node, glm::dvec3(2.0)));
    for (const std::string& w : s.warnings) EXPECT_EQ(w.find("extension"), std::string::npos) << w;
}

// --- textures -----------------------------------------------------------------------------------

namespace {

// The 2×2 test texture as linear premultiplied RGBA: red, green / blue, white at alpha 128/255.
// Every colour is 0 or 1 (exact in sRGB8), so the file decodes back to these values exactly.
constexpr float kHalf = 128.0f / 255.0f;
const glm::vec4 kTexels[4] = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}, {kHalf, kHalf, kHalf, kHalf}};

std::string write_texture_png(const std::string& name) {
    mr::Image image(2, 2, 4);
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 4; ++c) image.pixels[4 * i + c] = kTexels[i][c];
    const std::string path = output_path(name);
    mr::write_image(path, image);
    return path;
}

std::vector<unsigned char> file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Texel i of the texture as loaded: opaque materials drop alpha (white texel → (1, 1, 1, 1)).
glm::vec4 expected_texel(int i, bool ignore_alpha) {
    return ignore_alpha && i == 3 ? glm::vec4(1.0f) : kTexels[i];
}

void expect_texels(const mr::Texture& t, bool ignore_alpha) {
    ASSERT_TRUE(t);
    ASSERT_EQ(t.width(), 2);
    ASSERT_EQ(t.height(), 2);
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 4; ++c)
            EXPECT_NEAR(t.base_level().at(i % 2, i / 2)[c], expected_texel(i, ignore_alpha)[c], 1e-6)
                << "texel " << i << " channel " << c;
}

bool has_warning(const mr::LoadedScene& s, const std::vector<std::string>& parts) {
    for (const std::string& w : s.warnings) {
        bool all = true;
        for (const std::string& p : parts) all &= w.find(p) != std::string::npos;
        if (all) return true;
    }
    return false;
}

std::string warnings_text(const mr::LoadedScene& s) {
    std::string out;
    for (const std::string& w : s.warnings) out += w + "\n";
    return out;
}

// 164 bytes: a quad (−1..1 in x and y) with float uvs, normals, ushort indices and normalized
// ubyte / ushort uvs: [0,48) POSITION, [48,80) uv float, [80,128) NORMAL, [128,140) indices,
// [140,148) uv ubyte, [148,164) uv ushort.
std::vector<unsigned char> quad_buffer() {
    std::vector<unsigned char> b;
    for (float v : {-1.f, -1.f, 0.f, 1.f, -1.f, 0.f, 1.f, 1.f, 0.f, -1.f, 1.f, 0.f}) append(b, v);
    for (float v : {0.f, 0.f, 1.f, 0.f, 1.f, 1.f, 0.f, 1.f}) append(b, v);
    for (int i = 0; i < 4; ++i)
        for (float v : {0.f, 0.f, 1.f}) append(b, v);
    for (std::uint16_t i : {0, 1, 2, 0, 2, 3}) append(b, i);
    for (unsigned char c : {0, 0, 255, 0, 255, 255, 51, 255}) b.push_back(c);
    for (std::uint16_t c : {0, 0, 65535, 0, 65535, 65535, 13107, 65535}) append(b, c);
    return b;
}

// A glTF file around quad_buffer(): one node and mesh per material, material i's primitive using
// `attributes`; the pieces named here replace the defaults.
struct TexturedGltf {
    std::string images = R"([{"uri": "tex.png"}])";
    std::string samplers = R"([{"magFilter": 9728, "minFilter": 9986, "wrapS": 33071, "wrapT": 33648}])";
    std::string textures = R"([{"sampler": 0, "source": 0}])";
    std::vector<std::string> materials = {
        R"({"name": "textured", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})"};
    std::string attributes = R"("POSITION": 0, "TEXCOORD_0": 1, "NORMAL": 2)";
    std::string extra_views;  // appended to bufferViews, e.g. an image's bytes in the .glb chunk

    std::string json(const std::string& buffer, std::size_t byte_length) const {
        std::string nodes, meshes, mats, scene_nodes;
        for (std::size_t i = 0; i < materials.size(); ++i) {
            const std::string sep = i ? ", " : "";
            nodes += sep + R"({"mesh": )" + std::to_string(i) + "}";
            scene_nodes += sep + std::to_string(i);
            meshes += sep + R"({"primitives": [{"attributes": {)" + attributes + R"(}, "indices": 3, "material": )" +
                      std::to_string(i) + "}]}";
            mats += sep + materials[i];
        }
        return R"({
  "asset": {"version": "2.0"},
  "scenes": [{"nodes": [)" + scene_nodes + R"(]}],
  "nodes": [)" + nodes + R"(],
  "meshes": [)" + meshes + R"(],
  "materials": [)" + mats + R"(],
  "textures": )" + textures + R"(,
  "samplers": )" + samplers + R"(,
  "images": )" + images + R"(,
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
    {"bufferView": 4, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC2"},
    {"bufferView": 5, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2"},
    {"bufferView": 4, "componentType": 5121, "count": 4, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 3, "componentType": 5123, "count": 4, "type": "VEC2"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 32},
    {"buffer": 0, "byteOffset": 80, "byteLength": 48},
    {"buffer": 0, "byteOffset": 128, "byteLength": 12},
    {"buffer": 0, "byteOffset": 140, "byteLength": 8},
    {"buffer": 0, "byteOffset": 148, "byteLength": 16})" + extra_views + R"(
  ],
  "buffers": [{)" + buffer + R"("byteLength": )" + std::to_string(byte_length) + R"(}]
})";
    }

    // A .gltf next to tex.png, its buffer as a data URI.
    std::string write(const std::string& name) const {
        const std::vector<unsigned char> b = quad_buffer();
        return write_file(name, json("\"uri\": \"data:application/octet-stream;base64," + base64(b) + "\", ", b.size()));
    }

    // A .glb whose binary chunk is quad_buffer() followed by `tail` (e.g. image bytes).
    std::string write_glb(const std::string& name, const std::vector<unsigned char>& tail) const {
        std::vector<unsigned char> bin = quad_buffer();
        bin.insert(bin.end(), tail.begin(), tail.end());
        std::string j = json("", bin.size());
        while (j.size() % 4) j += ' ';
        while (bin.size() % 4) bin.push_back(0);
        std::vector<unsigned char> out;
        append(out, std::uint32_t(0x46546C67));
        append(out, std::uint32_t(2));
        append(out, std::uint32_t(12 + 8 + j.size() + 8 + bin.size()));
        append(out, std::uint32_t(j.size()));
        append(out, std::uint32_t(0x4E4F534A));
        out.insert(out.end(), j.begin(), j.end());
        append(out, std::uint32_t(bin.size()));
        append(out, std::uint32_t(0x004E4942));
        out.insert(out.end(), bin.begin(), bin.end());
        return write_file(name, std::string(out.begin(), out.end()));
    }
};

void expect_quad_uvs(const mr::Mesh& m) {
    ASSERT_EQ(m.uvs.size(), 4u);
    EXPECT_EQ(m.uvs[0], glm::vec2(0, 0));
    EXPECT_EQ(m.uvs[1], glm::vec2(1, 0));
    EXPECT_EQ(m.uvs[2], glm::vec2(1, 1));
    EXPECT_EQ(m.uvs[3], glm::vec2(0, 1));
}

}  // namespace

TEST(SceneFileTextures, GltfLoadsUvsNormalsTextureAndSampler) {
    write_texture_png("tex.png");
    const auto s = mr::load_scene(TexturedGltf{}.write("textured.gltf"));
    EXPECT_TRUE(s.warnings.empty()) << warnings_text(s);
    ASSERT_EQ(s.draws.size(), 1u);
    const mr::Draw& d = s.draws[0];
    expect_quad_uvs(*d.mesh);
    ASSERT_EQ(d.mesh->normals.size(), 4u);
    for (const glm::vec3& n : d.mesh->normals) EXPECT_EQ(n, glm::vec3(0, 0, 1));
    // The texture: sRGB decoded to linear, premultiplied; an OPAQUE material ignores its alpha.
    expect_texels(d.texture, /*ignore_alpha=*/true);
    EXPECT_EQ(d.texture.name(), output_path("tex.png"));
    EXPECT_EQ(d.sampler.wrap_u, mr::WrapMode::clamp);
    EXPECT_EQ(d.sampler.wrap_v, mr::WrapMode::mirror);
    EXPECT_EQ(d.sampler.mag_filter, mr::TexelFilter::nearest);
    EXPECT_EQ(d.sampler.min_filter, mr::TexelFilter::nearest);
    EXPECT_EQ(d.sampler.mip_filter, mr::MipFilter::linear);
    EXPECT_EQ(d.sampler.footprint, mr::FootprintFilter::isotropic);
    EXPECT_EQ(d.color, glm::vec4(1.0f));
}

TEST(SceneFileTextures, GltfBlendAndMaskMaterialsKeepTextureAlpha) {
    write_texture_png("tex.png");
    TexturedGltf g;
    g.materials = {R"({"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})",
                   R"({"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})",
                   R"({"alphaMode": "MASK", "alphaCutoff": 0.3, "pbrMetallicRoughness":
                       {"baseColorFactor": [1, 0.5, 0.25, 0.8], "baseColorTexture": {"index": 0}}})",
                   R"({"alphaMode": "OPAQUE", "alphaCutoff": 0.3,
                       "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})"};
    const auto s = mr::load_scene(g.write("blend.gltf"));
    EXPECT_TRUE(s.warnings.empty()) << warnings_text(s);
    ASSERT_EQ(s.draws.size(), 4u);
    expect_texels(s.draws[0].texture, /*ignore_alpha=*/false);  // premultiplied: (a, a, a, a)
    EXPECT_EQ(s.draws[0].state.blend, mr::BlendMode::over);
    EXPECT_FALSE(s.draws[0].state.alpha_cutoff);
    // MASK: the texture's alpha kept for the alpha test (the spec's default cutoff 0.5, else the
    // file's), replace blending, the factor premultiplied.
    expect_texels(s.draws[1].texture, /*ignore_alpha=*/false);
    EXPECT_EQ(s.draws[1].state.blend, mr::BlendMode::replace);
    EXPECT_EQ(s.draws[1].state.alpha_cutoff, 0.5f);
    EXPECT_EQ(s.draws[2].state.alpha_cutoff, 0.3f);
    EXPECT_EQ(s.draws[2].color, glm::vec4(0.8f, 0.4f, 0.2f, 0.8f));
    // OPAQUE ignores alphaCutoff and the texture's alpha.
    expect_texels(s.draws[3].texture, /*ignore_alpha=*/true);
    EXPECT_FALSE(s.draws[3].state.alpha_cutoff);
    EXPECT_EQ(s.draws[3].color, glm::vec4(1.0f));
}

TEST(SceneFileTextures, GltfMaskCutoffOutsideZeroToOneWarnsAndUsesOneHalf) {
    write_texture_png("tex.png");
    TexturedGltf g;
    g.materials = {
        R"({"alphaMode": "MASK", "alphaCutoff": 1.5, "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})"};
    const auto s = mr::load_scene(g.write("bad_cutoff.gltf"));
    ASSERT_EQ(s.draws.size(), 1u);
    EXPECT_EQ(s.draws[0].state.alpha_cutoff, 0.5f);
    ASSERT_EQ(s.warnings.size(), 1u) << warnings_text(s);
    EXPECT_NE(s.warnings[0].find("alphaCutoff"), std::string::npos) << s.warnings[0];
}

TEST(SceneFileTextures, GltfSamplerEnumsMapToSamplers) {
    write_texture_png("tex.png");
    struct Case {
        std::string sampler;  // JSON
        mr::WrapMode wrap_u, wrap_v;
        mr::TexelFilter mag, min;
        mr::MipFilter mip;
    };
    using W = mr::WrapMode;
    using T = mr::TexelFilter;
    using M = mr::MipFilter;
    const std::vector<Case> cases = {
        {"{}", W::repeat, W::repeat, T::linear, T::linear, M::linear},  // undefined: trilinear, repeat
        {R"({"wrapS": 10497, "wrapT": 33071, "magFilter": 9728, "minFilter": 9728})", W::repeat, W::clamp, T::nearest,
         T::nearest, M::none},
        {R"({"wrapS": 33071, "wrapT": 33648, "magFilter": 9729, "minFilter": 9729})", W::clamp, W::mirror, T::linear,
         T::linear, M::none},
        {R"({"wrapS": 33648, "wrapT": 10497, "minFilter": 9984})", W::mirror, W::repeat, T::linear, T::nearest, M::nearest},
        {R"({"minFilter": 9985})", W::repeat, W::repeat, T::linear, T::linear, M::nearest},
        {R"({"minFilter": 9986})", W::repeat, W::repeat, T::linear, T::nearest, M::linear},
        {R"({"minFilter": 9987, "magFilter": 9728})", W::repeat, W::repeat, T::nearest, T::linear, M::linear},
        // Not glTF enums: warned about, defaults used.
        {R"({"wrapS": 1234, "magFilter": 5, "minFilter": 6})", W::repeat, W::repeat, T::linear, T::linear, M::linear},
    };
    TexturedGltf g;
    g.samplers = "[";
    g.textures = "[";
    g.materials.clear();
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const std::string sep = i ? ", " : "";
        g.samplers += sep + cases[i].sampler;
        g.textures += sep + R"({"source": 0, "sampler": )" + std::to_string(i) + "}";
        g.materials.push_back(R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": )" + std::to_string(i) + "}}}");
    }
    g.samplers += "]";
    g.textures += R"(, {"source": 0}])";  // a texture without a sampler: the defaults
    g.materials.push_back(R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": )" + std::to_string(cases.size()) +
                          "}}}");
    const auto s = mr::load_scene(g.write("samplers.gltf"));
    ASSERT_EQ(s.draws.size(), cases.size() + 1);
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const mr::Sampler& sm = s.draws[i].sampler;
        EXPECT_EQ(sm.wrap_u, cases[i].wrap_u) << cases[i].sampler;
        EXPECT_EQ(sm.wrap_v, cases[i].wrap_v) << cases[i].sampler;
        EXPECT_EQ(sm.mag_filter, cases[i].mag) << cases[i].sampler;
        EXPECT_EQ(sm.min_filter, cases[i].min) << cases[i].sampler;
        EXPECT_EQ(sm.mip_filter, cases[i].mip) << cases[i].sampler;
        EXPECT_TRUE(s.draws[i].texture) << i;
    }
    const mr::Sampler& def = s.draws.back().sampler;
    const mr::Sampler library_default;
    EXPECT_EQ(def.to_string(), library_default.to_string());
    EXPECT_TRUE(has_warning(s, {"samplers[7]", "wrapS 1234"})) << warnings_text(s);
    EXPECT_TRUE(has_warning(s, {"samplers[7]", "magFilter 5"})) << warnings_text(s);
    EXPECT_TRUE(has_warning(s, {"samplers[7]", "minFilter 6"})) << warnings_text(s);
    // Every draw names the same file: one shared texture.
    EXPECT_EQ(&s.draws[0].texture.base_level(), &s.draws[5].texture.base_level());
}

TEST(SceneFileTextures, GltfNormalizedIntegerTexcoords) {
    write_texture_png("tex.png");
    for (const char* accessor : {"4", "5"}) {
        TexturedGltf g;
        g.attributes = std::string(R"("POSITION": 0, "TEXCOORD_0": )") + accessor;
        const auto s = mr::load_scene(g.write(std::string("uv_int") + accessor + ".gltf"));
        const mr::Mesh& m = *s.draws[0].mesh;
        ASSERT_EQ(m.uvs.size(), 4u);
        EXPECT_EQ(m.uvs[1], glm::vec2(1, 0));
        EXPECT_FLOAT_EQ(m.uvs[3].x, 0.2f);
        EXPECT_EQ(m.uvs[3].y, 1.0f);
        EXPECT_TRUE(m.normals.empty());
    }
}

TEST(SceneFileTextures, GltfDataUriImage) {
    const std::vector<unsigned char> png = file_bytes(write_texture_png("embedded_src.png"));
    TexturedGltf g;
    g.images = R"([{"uri": "data:image/png;base64,)" + base64(png) + R"("}])";
    const auto s = mr::load_scene(g.write("data_uri_image.gltf"));
    EXPECT_TRUE(s.warnings.empty()) << warnings_text(s);
    expect_texels(s.draws[0].texture, true);
    EXPECT_NE(s.draws[0].texture.name().find("images[0]"), std::string::npos) << s.draws[0].texture.name();
}

TEST(SceneFileTextures, GlbImageInBufferView) {
    const std::vector<unsigned char> png = file_bytes(write_texture_png("glb_src.png"));
    TexturedGltf g;
    g.images = R"([{"bufferView": 6, "mimeType": "image/png"}])";
    g.extra_views = R"(, {"buffer": 0, "byteOffset": 164, "byteLength": )" + std::to_string(png.size()) + "}";
    const auto s = mr::load_scene(g.write_glb("textured.glb", png));
    EXPECT_TRUE(s.warnings.empty()) << warnings_text(s);
    expect_quad_uvs(*s.draws[0].mesh);
    expect_texels(s.draws[0].texture, true);
    EXPECT_EQ(s.draws[0].sampler.wrap_u, mr::WrapMode::clamp);

    // A bufferView running past the buffer is an error naming the file, not a read out of bounds.
    TexturedGltf bad = g;
    bad.extra_views = R"(, {"buffer": 0, "byteOffset": 164, "byteLength": 100000})";
    const std::string path = bad.write_glb("image_view_outside.glb", png);
    const std::string e = error_of([&] { mr::load_scene(path); });
    EXPECT_NE(e.find(path), std::string::npos) << e;
    EXPECT_NE(e.find("images[0]"), std::string::npos) << e;
}

TEST(SceneFileTextures, MissingOrCorruptTextureGivesErrorTextureAndWarning) {
    TexturedGltf g;
    g.images = R"([{"uri": "no_such_texture.png"}])";
    const auto s = mr::load_scene(g.write("missing_texture.gltf"));
    ASSERT_EQ(s.draws.size(), 1u);
    const mr::Texture error = mr::error_texture();
    EXPECT_EQ(s.draws[0].texture.name(), "error texture");
    EXPECT_EQ(&s.draws[0].texture.base_level(), &error.base_level());
    EXPECT_TRUE(has_warning(s, {"material 'textured'", "no_such_texture.png", "error texture"})) << warnings_text(s);
    EXPECT_EQ(s.warnings.size(), 1u) << warnings_text(s);  // tinygltf's own note about the file is dropped
    // The error texture: 8×8 magenta / black checker, opaque.
    ASSERT_EQ(error.width(), 8);
    ASSERT_EQ(error.height(), 8);
    EXPECT_EQ(error.base_level().at(0, 0), glm::vec4(1, 0, 1, 1));
    EXPECT_EQ(error.base_level().at(1, 0), glm::vec4(0, 0, 0, 1));
    EXPECT_EQ(error.base_level().at(1, 1), glm::vec4(1, 0, 1, 1));

    write_file("corrupt_texture.png", "\x89PNG\r\n\x1a\n this is not a PNG");
    TexturedGltf c;
    c.images = R"([{"uri": "corrupt_texture.png"}])";
    const auto sc = mr::load_scene(c.write("corrupt_texture.gltf"));
    EXPECT_EQ(sc.draws[0].texture.name(), "error texture");
    EXPECT_TRUE(has_warning(sc, {"material 'textured'", "corrupt_texture.png"})) << warnings_text(sc);

    TexturedGltf d;  // embedded bytes that are no image
    d.images = R"([{"uri": "data:image/png;base64,)" + base64({1, 2, 3, 4, 5}) + R"("}])";
    const auto sd = mr::load_scene(d.write("corrupt_data_uri.gltf"));
    EXPECT_EQ(sd.draws[0].texture.name(), "error texture");
    EXPECT_TRUE(has_warning(sd, {"material 'textured'", "images[0]"})) << warnings_text(sd);

    TexturedGltf w;  // a data URI of a media type tinygltf does not take as data, holding no image
    w.images = R"([{"uri": "data:image/webp;base64,AAAA"}])";
    const auto sw = mr::load_scene(w.write("webp_data_uri.gltf"));
    EXPECT_EQ(sw.draws[0].texture.name(), "error texture");
    EXPECT_TRUE(has_warning(sw, {"material 'textured'", "images[0] (data URI)"})) << warnings_text(sw);

    for (const char* uri : {"data:image/webp,AAAA", "data:image/webp;base64,AA*A", "data:image/webp;base64,A"}) {
        TexturedGltf b;  // not base64
        b.images = std::string(R"([{"uri": ")") + uri + R"("}])";
        const auto sb = mr::load_scene(b.write("bad_data_uri.gltf"));
        EXPECT_EQ(sb.draws[0].texture.name(), "error texture") << uri;
        EXPECT_TRUE(has_warning(sb, {"images[0] (data URI)", "is not a base64 data URI"})) << uri << warnings_text(sb);
    }
}

TEST(SceneFileTextures, UnusableTexturesAreWarnedAndSkipped) {
    write_texture_png("tex.png");
    TexturedGltf g;
    g.materials = {R"({"name": "uv1", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}})",
                   R"({"name": "plain"})"};
    g.textures = R"([{"sampler": 0, "source": 0}])";
    const auto s = mr::load_scene(g.write("texcoord1.gltf"));
    EXPECT_FALSE(s.draws[0].texture);
    EXPECT_FALSE(s.draws[1].texture);
    EXPECT_TRUE(has_warning(s, {"material 'uv1'", "TEXCOORD_1"})) << warnings_text(s);
    EXPECT_FALSE(has_warning(s, {"textures are not supported"}));

    TexturedGltf n;  // a textured material on a primitive without TEXCOORD_0
    n.attributes = R"("POSITION": 0)";
    const auto sn = mr::load_scene(n.write("no_texcoord.gltf"));
    EXPECT_FALSE(sn.draws[0].texture);
    EXPECT_TRUE(has_warning(sn, {"meshes[0].primitives[0]", "TEXCOORD_0", "material 'textured'"})) << warnings_text(sn);
}

TEST(SceneFileTextures, HostileTextureReferencesNameTheFileAndProblem) {
    write_texture_png("tex.png");
    struct Case {
        std::string name, problem;
        std::function<void(TexturedGltf&)> edit;
    };
    const std::vector<Case> cases = {
        {"uv_vec3.gltf", "TEXCOORD_0 must be VEC2",
         [](TexturedGltf& g) { g.attributes = R"("POSITION": 0, "TEXCOORD_0": 7)"; }},
        {"uv_count.gltf", "TEXCOORD_0 has 3 elements",
         [](TexturedGltf& g) { g.attributes = R"("POSITION": 0, "TEXCOORD_0": 8)"; }},
        {"uv_unnormalized.gltf", "TEXCOORD_0 must be float or normalized",
         [](TexturedGltf& g) { g.attributes = R"("POSITION": 0, "TEXCOORD_0": 6)"; }},
        {"uv_accessor.gltf", "accessor 42 does not exist",
         [](TexturedGltf& g) { g.attributes = R"("POSITION": 0, "TEXCOORD_0": 42)"; }},
        {"normal_vec2.gltf", "NORMAL must be VEC3",
         [](TexturedGltf& g) { g.attributes = R"("POSITION": 0, "NORMAL": 1)"; }},
        {"texture_index.gltf", "baseColorTexture index 5 does not exist",
         [](TexturedGltf& g) { g.materials = {R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 5}}})"}; }},
        {"sampler_index.gltf", "sampler 3 does not exist",
         [](TexturedGltf& g) { g.textures = R"([{"sampler": 3, "source": 0}])"; }},
        {"image_index.gltf", "source image 9 does not exist",
         [](TexturedGltf& g) { g.textures = R"([{"sampler": 0, "source": 9}])"; }},
    };
    for (const Case& c : cases) {
        TexturedGltf g;
        c.edit(g);
        const std::string path = g.write(c.name);
        std::string e;
        try {
            mr::load_scene(path);
        } catch (const std::runtime_error& ex) {
            e = ex.what();
        }
        EXPECT_NE(e.find(path), std::string::npos) << c.name << ": " << e;
        EXPECT_NE(e.find(c.problem), std::string::npos) << c.name << ": " << e;
    }
}

TEST(SceneFileTextures, ObjTexcoordsFlipNormalsSplitAndMapKd) {
    write_texture_png("obj_tex.png");
    write_file("textured.mtl",
               "newmtl tex\nKd 1 1 1\nmap_Kd -clamp on obj_tex.png\n"
               "newmtl plain\nKd 0 1 0\n");
    // A quad whose two triangles share corners 1 and 3 with different texture coordinates at
    // corner 3 (a seam): position 3 becomes two vertices.
    const std::string path = write_file("textured.obj",
                                        "mtllib textured.mtl\n"
                                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.25 0.75\n"
                                        "vn 0 0 1\n"
                                        "usemtl tex\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/5/1 4/4/1\n"
                                        "f 1 2 4\n"
                                        "usemtl plain\nf 1/1 2/2 3/3\n");
    const auto s = mr::load_scene(path);
    ASSERT_EQ(s.draws.size(), 3u) << warnings_text(s);
    // Draw 0: material 'tex', the faces with texture coordinates.
    const mr::Draw& d = s.draws[0];
    const mr::Mesh& m = *d.mesh;
    ASSERT_EQ(m.positions.size(), 5u);  // 1, 2, 3 (uv 3), 3 (uv 5), 4
    ASSERT_EQ(m.uvs.size(), 5u);
    ASSERT_EQ(m.normals.size(), 5u);
    EXPECT_EQ(m.uvs[0], glm::vec2(0, 1));  // vt 0 0 → v flipped
    EXPECT_EQ(m.uvs[1], glm::vec2(1, 1));
    EXPECT_EQ(m.uvs[2], glm::vec2(1, 0));
    EXPECT_EQ(m.positions[3], glm::vec3(1, 1, 0));
    EXPECT_EQ(m.uvs[3], glm::vec2(0.25f, 0.25f));
    EXPECT_EQ(m.triangles[1], glm::uvec3(0, 3, 4));
    EXPECT_EQ(m.normals[4], glm::vec3(0, 0, 1));
    expect_texels(d.texture, /*ignore_alpha=*/true);
    EXPECT_EQ(d.sampler.wrap_u, mr::WrapMode::clamp);  // -clamp on
    EXPECT_EQ(d.sampler.mip_filter, mr::MipFilter::linear);
    // Draw 1: the 'tex' face without texture coordinates: untextured, with a warning.
    EXPECT_FALSE(s.draws[1].texture);
    EXPECT_FALSE(s.draws[1].mesh->has_uvs());
    EXPECT_TRUE(has_warning(s, {"material 'tex'", "no texture coordinates"})) << warnings_text(s);
    // Draw 2: an untextured material keeps its uvs (every face has them) and has no texture.
    EXPECT_FALSE(s.draws[2].texture);
    EXPECT_EQ(s.draws[2].mesh->uvs.size(), 3u);
    EXPECT_EQ(s.draws[2].color, glm::vec4(0, 1, 0, 1));
}

TEST(SceneFileTextures, ObjDefaultSamplerScaleOffsetAndMissingTexture) {
    write_texture_png("obj_tex.png");
    write_file("scaled.mtl", "newmtl s\nmap_Kd -s 2 4 1 -o 0.5 0.25 0 obj_tex.png\nnewmtl gone\nmap_Kd missing_map.png\n");
    const std::string path = write_file("scaled.obj",
                                        "mtllib scaled.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                        "usemtl s\nf 1/1 2/2 3/3\nusemtl gone\nf 1/1 2/2 3/3\n");
    const auto s = mr::load_scene(path);
    ASSERT_EQ(s.draws.size(), 2u);
    const mr::Mesh& m = *s.draws[0].mesh;
    EXPECT_EQ(m.uvs[0], glm::vec2(0.5f, 1.0f - 0.25f));        // uv·s + o, then v flipped
    EXPECT_EQ(m.uvs[1], glm::vec2(2.5f, 1.0f - 0.25f));
    EXPECT_EQ(m.uvs[2], glm::vec2(0.5f, 1.0f - 4.25f));
    EXPECT_TRUE(m.normals.empty());
    EXPECT_EQ(s.draws[0].sampler.to_string(), mr::Sampler{}.to_string());  // trilinear, repeat
    EXPECT_TRUE(s.draws[0].texture);
    EXPECT_EQ(s.draws[1].texture.name(), "error texture");
    EXPECT_TRUE(has_warning(s, {"material 'gone'", "missing_map.png", "error texture"})) << warnings_text(s);
}

TEST(SceneFileTextures, ObjBadTexcoordIndexNamesTheFile) {
    const std::string path = write_file("bad_vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/7\n");
    const std::string e = error_of([&] { mr::load_scene(path); });
    EXPECT_NE(e.find(path), std::string::npos) << e;
}

TEST(TextureFile, LoadTextureIsSharedAndRereadWhenTheFileChanges) {
    const std::string path = write_texture_png("shared.png");
    const mr::Texture a = mr::load_texture(path);
    const mr::Texture b = mr::load_texture(path);
    EXPECT_EQ(&a.base_level(), &b.base_level());
    expect_texels(a, false);
    mr::TextureFileOptions opaque;
    opaque.ignore_alpha = true;
    const mr::Texture c = mr::load_texture(path, opaque);
    EXPECT_NE(&a.base_level(), &c.base_level());
    expect_texels(c, true);
    // Linear (data) decoding: code / 255 without the sRGB curve.
    mr::Image grey(1, 1, 4);
    for (int ch = 0; ch < 4; ++ch) grey.pixels[ch] = ch < 3 ? 0.5f : 1.0f;  // sRGB8 188
    const std::string grey_path = output_path("grey.png");
    mr::write_image(grey_path, grey);
    mr::TextureFileOptions linear;
    linear.srgb = false;
    EXPECT_NEAR(mr::load_texture(grey_path, linear).base_level().at(0, 0).r, 188.0f / 255.0f, 1e-6);
    EXPECT_NEAR(mr::load_texture(grey_path, /*srgb=*/false).base_level().at(0, 0).r, 188.0f / 255.0f, 1e-6);
    EXPECT_NEAR(mr::load_texture(grey_path).base_level().at(0, 0).r, mr::srgb_to_linear(188.0f / 255.0f), 1e-6);
    // From memory: the same texels; missing files and garbage bytes throw, naming them.
    const std::vector<unsigned char> png = file_bytes(path);
    expect_texels(mr::load_texture_from_memory(png.data(), png.size(), "mem"), false);
    const std::string missing = output_path("no_such.png");
    EXPECT_NE(error_of([&] { mr::load_texture(missing); }).find(missing), std::string::npos);
    const unsigned char junk[4] = {1, 2, 3, 4};
    EXPECT_NE(error_of([&] { mr::load_texture_from_memory(junk, 4, "junk bytes"); }).find("junk bytes"),
              std::string::npos);
}
