// Scene files: OBJ/MTL through tinyobjloader, glTF 2.0 through tinygltf. The only file that
// includes either library.
#include "mipraster/io/scene_file.hpp"

#include "file_extension.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

namespace mipraster {

namespace {

/// Limits against absurd files: a mesh's vertex and triangle counts must fit the 32-bit indices,
/// and the node hierarchy is walked at most this deep (a deeper one is a cycle or hostile).
constexpr std::size_t kMaxElements = std::numeric_limits<std::uint32_t>::max();
constexpr int kMaxNodeDepth = 1024;
static_assert(kMaxNodeDepth > 0 && kMaxElements > 0, "limits must be positive");

std::string directory_of(const std::string& path) {
    const auto slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string("./") : path.substr(0, slash + 1);
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
    throw std::runtime_error(path + ": " + problem);
}

std::string trim(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
    return s;
}

void add_warnings(std::vector<std::string>& out, const std::string& path, const std::string& text) {
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) {
        line = trim(line);
        if (!line.empty()) out.push_back(path + ": " + line);
    }
}

// ---------------------------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------------------------
LoadedScene load_obj(const std::string& path) {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    const std::string base = directory_of(path);
    // No default vertex colours: attrib.colors stays empty unless every vertex has one.
    const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, path.c_str(), base.c_str(),
                                     /*triangulate=*/true, /*default_vcols_fallback=*/false);
    if (!ok) fail(path, "cannot read OBJ file: " + trim(err.empty() ? warn : err));
    LoadedScene scene;
    add_warnings(scene.warnings, path, err);  // tinyobjloader reports missing MTL files here
    add_warnings(scene.warnings, path, warn);

    const std::size_t vertex_count = attrib.vertices.size() / 3;
    if (vertex_count > kMaxElements) fail(path, "too many vertices (" + std::to_string(vertex_count) + ")");
    const bool has_colors = !attrib.colors.empty() && attrib.colors.size() == attrib.vertices.size();

    // Step 1: gather triangles per material (−1: none) in order of first use.
    std::vector<int> material_order;
    std::map<int, std::vector<glm::uvec3>> by_material;  // corners as OBJ vertex indices
    for (std::size_t s = 0; s < shapes.size(); ++s) {
        const tinyobj::mesh_t& m = shapes[s].mesh;
        std::size_t offset = 0;
        for (std::size_t f = 0; f < m.num_face_vertices.size(); ++f) {
            const std::size_t n = m.num_face_vertices[f];
            if (offset + n > m.indices.size()) fail(path, "shape '" + shapes[s].name + "': face indices truncated");
            if (n == 3) {
                glm::uvec3 tri;
                for (int c = 0; c < 3; ++c) {
                    const int vi = m.indices[offset + c].vertex_index;
                    if (vi < 0 || static_cast<std::size_t>(vi) >= vertex_count)
                        fail(path, "shape '" + shapes[s].name + "' face " + std::to_string(f) + ": vertex index " +
                                       std::to_string(vi + 1) + " out of range (the file has " +
                                       std::to_string(vertex_count) + " vertices)");
                    tri[c] = static_cast<std::uint32_t>(vi);
                }
                int material = f < m.material_ids.size() ? m.material_ids[f] : -1;
                if (material < 0 || static_cast<std::size_t>(material) >= materials.size()) material = -1;
                auto it = by_material.find(material);
                if (it == by_material.end()) {
                    material_order.push_back(material);
                    it = by_material.emplace(material, std::vector<glm::uvec3>{}).first;
                }
                it->second.push_back(tri);
            }
            offset += n;
        }
    }

    // Step 2: one compact mesh and draw per material.
    for (int material : material_order) {
        const std::vector<glm::uvec3>& tris = by_material[material];
        auto mesh = std::make_shared<Mesh>();
        std::vector<std::uint32_t> remap(vertex_count, std::numeric_limits<std::uint32_t>::max());
        mesh->triangles.reserve(tris.size());
        for (const glm::uvec3& t : tris) {
            glm::uvec3 out;
            for (int c = 0; c < 3; ++c) {
                std::uint32_t& r = remap[t[c]];
                if (r == std::numeric_limits<std::uint32_t>::max()) {
                    r = static_cast<std::uint32_t>(mesh->positions.size());
                    const std::size_t v = t[c];
                    mesh->positions.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1],
                                                 attrib.vertices[3 * v + 2]);
                    if (has_colors)
                        mesh->colors.emplace_back(attrib.colors[3 * v], attrib.colors[3 * v + 1],
                                                  attrib.colors[3 * v + 2], 1.0f);
                }
                out[c] = r;
            }
            mesh->triangles.push_back(out);
        }
        const std::string name =
            material < 0 ? std::string("default material") : "material '" + materials[material].name + "'";
        mesh->validate(path + " (" + name + ")");
        Draw draw;
        draw.mesh = mesh.get();
        if (material >= 0) {
            const auto& kd = materials[material].diffuse;
            draw.color = glm::vec4(kd[0], kd[1], kd[2], 1.0f);
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(kd[c])) fail(path, name + ": Kd is not finite");
        }
        scene.meshes.push_back(std::move(mesh));
        scene.draws.push_back(draw);
    }
    return scene;
}

// ---------------------------------------------------------------------------------------------
// glTF
// ---------------------------------------------------------------------------------------------

// Images are not decoded (textures come later): accept every image without touching its bytes.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
    return true;
}

/// Reads an accessor's elements as doubles (normalized integers mapped to [0, 1] / [−1, 1]),
/// after checking that every byte it names lies inside its buffer.
class AccessorReader {
public:
    AccessorReader(const tinygltf::Model& model, int index, const std::string& path, const std::string& what)
        : path_(path), what_(what) {
        if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
            fail(path, what + ": accessor " + std::to_string(index) + " does not exist (the file has " +
                           std::to_string(model.accessors.size()) + ")");
        const tinygltf::Accessor& a = model.accessors[index];
        what_ = what + " (accessor " + std::to_string(index) + ")";
        if (a.sparse.isSparse) fail(path, what_ + ": sparse accessors are not supported");
        count_ = a.count;
        components_ = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
        component_type_ = a.componentType;
        size_ = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
        normalized_ = a.normalized;
        if (components_ <= 0 || components_ > 4 || size_ <= 0)
            fail(path, what_ + ": unsupported type " + std::to_string(a.type) + " / component type " +
                           std::to_string(a.componentType));
        if (count_ > kMaxElements) fail(path, what_ + ": absurd count " + std::to_string(count_));
        if (count_ == 0) return;
        if (a.bufferView < 0 || static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size())
            fail(path, what_ + ": buffer view " + std::to_string(a.bufferView) + " does not exist");
        const tinygltf::BufferView& view = model.bufferViews[a.bufferView];
        if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size())
            fail(path, what_ + ": buffer " + std::to_string(view.buffer) + " does not exist");
        const std::vector<unsigned char>& buffer = model.buffers[view.buffer].data;
        const std::size_t element = static_cast<std::size_t>(components_) * static_cast<std::size_t>(size_);
        stride_ = view.byteStride ? view.byteStride : element;
        if (stride_ < element || stride_ > 252 + element)
            fail(path, what_ + ": byte stride " + std::to_string(view.byteStride) + " is invalid");
        // All sizes below are bounded: count ≤ 2^32 and stride ≤ 256, so no product overflows.
        if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
            fail(path, what_ + ": buffer view " + std::to_string(a.bufferView) + " (offset " +
                           std::to_string(view.byteOffset) + ", length " + std::to_string(view.byteLength) +
                           ") lies outside its buffer of " + std::to_string(buffer.size()) + " bytes");
        if (a.byteOffset > view.byteLength)
            fail(path, what_ + ": byte offset " + std::to_string(a.byteOffset) + " lies outside its buffer view");
        const std::size_t needed = a.byteOffset + (count_ - 1) * stride_ + element;
        if (needed > view.byteLength)
            fail(path, what_ + ": " + std::to_string(count_) + " elements need " + std::to_string(needed) +
                           " bytes, its buffer view has " + std::to_string(view.byteLength));
        data_ = buffer.data() + view.byteOffset + a.byteOffset;
    }

    std::size_t count() const { return count_; }
    int components() const { return components_; }
    int component_type() const { return component_type_; }
    bool normalized() const { return normalized_; }
    const std::string& what() const { return what_; }

    double get(std::size_t i, int c) const {
        const unsigned char* p = data_ + i * stride_ + static_cast<std::size_t>(c) * size_;
        switch (component_type_) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: return load<float>(p);
            case TINYGLTF_COMPONENT_TYPE_DOUBLE: return load<double>(p);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return scaled(load<std::uint8_t>(p), 255.0);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return scaled(load<std::uint16_t>(p), 65535.0);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return static_cast<double>(load<std::uint32_t>(p));
            case TINYGLTF_COMPONENT_TYPE_BYTE: return signed_scaled(load<std::int8_t>(p), 127.0);
            case TINYGLTF_COMPONENT_TYPE_SHORT: return signed_scaled(load<std::int16_t>(p), 32767.0);
            case TINYGLTF_COMPONENT_TYPE_INT: return static_cast<double>(load<std::int32_t>(p));
            default: fail(path_, what_ + ": unsupported component type " + std::to_string(component_type_));
        }
    }

    /// An unsigned integer element (indices), unscaled.
    std::uint64_t get_index(std::size_t i) const {
        const unsigned char* p = data_ + i * stride_;
        switch (component_type_) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load<std::uint8_t>(p);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load<std::uint16_t>(p);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return load<std::uint32_t>(p);
            default:
                fail(path_, what_ + ": indices must be unsigned byte, short or int, got component type " +
                                std::to_string(component_type_));
        }
    }

private:
    template <class T>
    static T load(const unsigned char* p) {
        T v;
        std::memcpy(&v, p, sizeof v);
        return v;
    }
    double scaled(double v, double max) const { return normalized_ ? v / max : v; }
    double signed_scaled(double v, double max) const { return normalized_ ? std::max(v / max, -1.0) : v; }

    std::string path_, what_;
    const unsigned char* data_ = nullptr;
    std::size_t count_ = 0, stride_ = 0;
    int components_ = 0, component_type_ = 0, size_ = 0;
    bool normalized_ = false;
};

glm::dmat4 node_matrix(const tinygltf::Node& node, const std::string& path, int index) {
    const std::string what = "node " + std::to_string(index) + " ('" + node.name + "')";
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) fail(path, what + ": matrix must have 16 numbers");
        glm::dmat4 m;
        for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = node.matrix[i];  // column-major, as glTF stores it
        return m;
    }
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    if (!node.translation.empty()) {
        if (node.translation.size() != 3) fail(path, what + ": translation must have 3 numbers");
        t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    if (!node.rotation.empty()) {
        if (node.rotation.size() != 4) fail(path, what + ": rotation must have 4 numbers");
        glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);  // (w, x, y, z)
        const double len = glm::length(q);
        if (!(len > 0.0) || !std::isfinite(len)) fail(path, what + ": rotation is not a valid quaternion");
        r = glm::mat4_cast(q / len);
    }
    if (!node.scale.empty()) {
        if (node.scale.size() != 3) fail(path, what + ": scale must have 3 numbers");
        s[0][0] = node.scale[0];
        s[1][1] = node.scale[1];
        s[2][2] = node.scale[2];
    }
    return t * r * s;
}

struct GltfLoader {
    const tinygltf::Model& model;
    const std::string& path;
    LoadedScene scene;
    std::map<std::pair<int, int>, std::shared_ptr<Mesh>> mesh_cache;  // (mesh, primitive) → mesh
    std::size_t skipped_primitives = 0;
    std::vector<bool> on_path;  // nodes on the current root-to-node path (cycle detection)

    GltfLoader(const tinygltf::Model& m, const std::string& p) : model(m), path(p), on_path(m.nodes.size(), false) {}

    bool material_blends(int material) const {
        return material >= 0 && static_cast<std::size_t>(material) < model.materials.size() &&
               model.materials[material].alphaMode == "BLEND";
    }

    std::shared_ptr<Mesh> primitive_mesh(int mesh_index, int prim_index) {
        const auto key = std::make_pair(mesh_index, prim_index);
        if (auto it = mesh_cache.find(key); it != mesh_cache.end()) return it->second;
        const tinygltf::Primitive& prim = model.meshes[mesh_index].primitives[prim_index];
        const std::string what = "meshes[" + std::to_string(mesh_index) + "].primitives[" + std::to_string(prim_index) + "]";
        auto mesh = std::make_shared<Mesh>();

        // Positions.
        const auto pos_it = prim.attributes.find("POSITION");
        if (pos_it == prim.attributes.end()) fail(path, what + ": no POSITION attribute");
        const AccessorReader pos(model, pos_it->second, path, what + " POSITION");
        if (pos.components() != 3) fail(path, pos.what() + ": POSITION must be VEC3");
        mesh->positions.resize(pos.count());
        for (std::size_t i = 0; i < pos.count(); ++i)
            mesh->positions[i] = glm::vec3(pos.get(i, 0), pos.get(i, 1), pos.get(i, 2));

        // Vertex colours (linear); premultiplied by their alpha when the material blends,
        // opaque otherwise (alpha is ignored for OPAQUE/MASK materials).
        if (const auto col_it = prim.attributes.find("COLOR_0"); col_it != prim.attributes.end()) {
            const AccessorReader col(model, col_it->second, path, what + " COLOR_0");
            if (col.components() != 3 && col.components() != 4) fail(path, col.what() + ": COLOR_0 must be VEC3 or VEC4");
            const int ct = col.component_type();
            if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT &&
                !((ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) &&
                  col.normalized()))
                fail(path, col.what() + ": COLOR_0 must be float or normalized unsigned byte/short");
            if (col.count() != pos.count())
                fail(path, col.what() + ": COLOR_0 has " + std::to_string(col.count()) + " elements, POSITION " +
                               std::to_string(pos.count()));
            const bool blend = material_blends(prim.material);
            mesh->colors.resize(col.count());
            for (std::size_t i = 0; i < col.count(); ++i) {
                const double a = col.components() == 4 && blend ? col.get(i, 3) : 1.0;
                mesh->colors[i] = glm::vec4(col.get(i, 0) * a, col.get(i, 1) * a, col.get(i, 2) * a, a);
            }
        }

        // Indices (any unsigned component type), or the vertices in order.
        if (prim.indices >= 0) {
            const AccessorReader idx(model, prim.indices, path, what + " indices");
            if (idx.components() != 1) fail(path, idx.what() + ": indices must be SCALAR");
            if (idx.count() % 3 != 0)
                scene.warnings.push_back(path + ": " + what + ": index count " + std::to_string(idx.count()) +
                                         " is not a multiple of 3; the last indices are ignored");
            mesh->triangles.resize(idx.count() / 3);
            for (std::size_t t = 0; t < mesh->triangles.size(); ++t)
                for (int c = 0; c < 3; ++c) {
                    const std::uint64_t v = idx.get_index(3 * t + c);
                    if (v >= pos.count())
                        fail(path, idx.what() + ": index " + std::to_string(v) + " of triangle " + std::to_string(t) +
                                       " is out of range (" + std::to_string(pos.count()) + " vertices)");
                    mesh->triangles[t][c] = static_cast<std::uint32_t>(v);
                }
        } else {
            mesh->triangles.resize(pos.count() / 3);
            for (std::size_t t = 0; t < mesh->triangles.size(); ++t)
                mesh->triangles[t] = glm::uvec3(3 * t, 3 * t + 1, 3 * t + 2);
        }
        mesh->validate(path + " " + what);
        scene.meshes.push_back(mesh);
        mesh_cache.emplace(key, mesh);
        return mesh;
    }

    void add_node(int index, const glm::dmat4& parent, int depth) {
        if (index < 0 || static_cast<std::size_t>(index) >= model.nodes.size())
            fail(path, "node " + std::to_string(index) + " does not exist (the file has " +
                           std::to_string(model.nodes.size()) + " nodes)");
        if (on_path[index] || depth > kMaxNodeDepth)
            fail(path, "node " + std::to_string(index) + " is its own ancestor (a cycle in the node hierarchy)");
        on_path[index] = true;
        const tinygltf::Node& node = model.nodes[index];
        const glm::dmat4 world = parent * node_matrix(node, path, index);
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 4; ++row)
                if (!std::isfinite(world[col][row]))
                    fail(path, "node " + std::to_string(index) + ": its world matrix is not finite");

        if (node.mesh >= 0) {
            if (static_cast<std::size_t>(node.mesh) >= model.meshes.size())
                fail(path, "node " + std::to_string(index) + ": mesh " + std::to_string(node.mesh) + " does not exist");
            const tinygltf::Mesh& m = model.meshes[node.mesh];
            for (std::size_t p = 0; p < m.primitives.size(); ++p) {
                const tinygltf::Primitive& prim = m.primitives[p];
                if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) {
                    ++skipped_primitives;
                    continue;
                }
                Draw draw;
                draw.mesh = primitive_mesh(node.mesh, static_cast<int>(p)).get();
                draw.model = world;
                if (prim.material >= 0) {
                    if (static_cast<std::size_t>(prim.material) >= model.materials.size())
                        fail(path, "meshes[" + std::to_string(node.mesh) + "].primitives[" + std::to_string(p) +
                                       "]: material " + std::to_string(prim.material) + " does not exist");
                    const tinygltf::Material& mat = model.materials[prim.material];
                    const std::vector<double>& f = mat.pbrMetallicRoughness.baseColorFactor;
                    if (f.size() != 4) fail(path, "material '" + mat.name + "': baseColorFactor must have 4 numbers");
                    for (double v : f)
                        if (!std::isfinite(v)) fail(path, "material '" + mat.name + "': baseColorFactor is not finite");
                    if (mat.alphaMode == "BLEND") {
                        draw.color = glm::vec4(f[0] * f[3], f[1] * f[3], f[2] * f[3], f[3]);
                        draw.state.blend = BlendMode::over;
                    } else {
                        draw.color = glm::vec4(f[0], f[1], f[2], 1.0);
                    }
                    if (!mat.doubleSided) draw.state.cull = CullMode::back;
                } else {
                    draw.state.cull = CullMode::back;  // the default material is single-sided
                }
                scene.draws.push_back(draw);
            }
        }

        if (node.camera >= 0) {
            if (static_cast<std::size_t>(node.camera) >= model.cameras.size())
                fail(path, "node " + std::to_string(index) + ": camera " + std::to_string(node.camera) + " does not exist");
            scene.cameras.push_back(make_camera(model.cameras[node.camera], node.camera, world));
        }

        for (int child : node.children) add_node(child, world, depth + 1);
        on_path[index] = false;
    }

    NamedCamera make_camera(const tinygltf::Camera& c, int index, const glm::dmat4& world) const {
        const std::string what = "camera " + std::to_string(index) + " ('" + c.name + "')";
        NamedCamera cam;
        cam.name = c.name.empty() ? "camera " + std::to_string(index) : c.name;
        cam.view = glm::inverse(world);
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 4; ++row)
                if (!std::isfinite(cam.view[col][row])) fail(path, what + ": its node's world matrix is singular");
        if (c.type == "perspective") {
            const auto& p = c.perspective;
            cam.projection = NamedCamera::Projection::perspective;
            cam.yfov = p.yfov;
            cam.aspect_ratio = p.aspectRatio;
            cam.znear = p.znear;
            cam.zfar = p.zfar > 0.0 ? p.zfar : kInfiniteFar;  // tinygltf: 0 = not given = infinite
            if (!(cam.yfov > 0.0 && cam.yfov < M_PI)) fail(path, what + ": yfov must be in (0, pi), got " + std::to_string(cam.yfov));
            if (!(cam.znear > 0.0 && std::isfinite(cam.znear))) fail(path, what + ": znear must be > 0");
            if (!(cam.zfar > cam.znear)) fail(path, what + ": zfar must be > znear");
            if (!(cam.aspect_ratio >= 0.0 && std::isfinite(cam.aspect_ratio))) fail(path, what + ": aspectRatio must be > 0");
        } else if (c.type == "orthographic") {
            const auto& o = c.orthographic;
            cam.projection = NamedCamera::Projection::orthographic;
            cam.xmag = o.xmag;
            cam.ymag = o.ymag;
            cam.znear = o.znear;
            cam.zfar = o.zfar;
            if (!(cam.xmag != 0.0 && cam.ymag != 0.0 && std::isfinite(cam.xmag) && std::isfinite(cam.ymag)))
                fail(path, what + ": xmag and ymag must be finite and non-zero");
            if (!(std::isfinite(cam.znear) && std::isfinite(cam.zfar) && cam.zfar > cam.znear && cam.znear >= 0.0))
                fail(path, what + ": expected 0 <= znear < zfar, both finite");
        } else {
            fail(path, what + ": unknown camera type '" + c.type + "'");
        }
        return cam;
    }
};

LoadedScene load_gltf(const std::string& path, bool binary) {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(skip_image, nullptr);
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    try {
        ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                    : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    } catch (const std::exception& e) {  // e.g. a JSON parser exception
        fail(path, std::string("cannot parse glTF: ") + e.what());
    }
    if (!ok) fail(path, "cannot read glTF: " + trim(err.empty() ? warn : err));

    GltfLoader g(model, path);
    add_warnings(g.scene.warnings, path, warn);

    // Roots: the default scene, else scene 0, else every node that is no other node's child.
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        int s = model.defaultScene;
        if (s < 0) s = 0;
        if (static_cast<std::size_t>(s) >= model.scenes.size())
            fail(path, "default scene " + std::to_string(s) + " does not exist");
        roots = model.scenes[s].nodes;
    } else {
        std::vector<bool> is_child(model.nodes.size(), false);
        for (const auto& n : model.nodes)
            for (int c : n.children)
                if (c >= 0 && static_cast<std::size_t>(c) < model.nodes.size()) is_child[c] = true;
        for (std::size_t i = 0; i < model.nodes.size(); ++i)
            if (!is_child[i]) roots.push_back(static_cast<int>(i));
    }
    for (int r : roots) g.add_node(r, glm::dmat4(1.0), 0);
    if (g.skipped_primitives)
        g.scene.warnings.push_back(path + ": skipped " + std::to_string(g.skipped_primitives) +
                                   " primitive(s) whose mode is not TRIANGLES");
    if (!model.textures.empty() || !model.images.empty())
        g.scene.warnings.push_back(path + ": textures are not supported yet; " + std::to_string(model.textures.size()) +
                                   " texture(s) ignored");
    return std::move(g.scene);
}

}  // namespace

std::string to_string(NamedCamera::Projection projection) {
    return projection == NamedCamera::Projection::perspective ? "perspective" : "orthographic";
}

Camera NamedCamera::build(double aspect) const {
    if (!(aspect > 0.0 && std::isfinite(aspect)))
        throw std::invalid_argument("NamedCamera::build: aspect must be finite and > 0, got " + std::to_string(aspect));
    Camera camera;
    camera.view = view;
    camera.depth_convention = DepthConvention::reverse_z;
    if (projection == Projection::perspective) {
        camera.projection = perspective(yfov, aspect_ratio > 0.0 ? aspect_ratio : aspect, znear, zfar);
    } else {
        camera.projection = orthographic(-xmag, xmag, -ymag, ymag, znear, zfar);
    }
    return camera;
}

std::string NamedCamera::to_string() const {
    std::ostringstream s;
    s << "NamedCamera('" << name << "', " << mipraster::to_string(projection);
    if (projection == Projection::perspective) {
        s << ", yfov=" << yfov << ", aspect_ratio=" << aspect_ratio;
    } else {
        s << ", xmag=" << xmag << ", ymag=" << ymag;
    }
    s << ", znear=" << znear << ", zfar=" << zfar << ")";
    return s.str();
}

LoadedScene load_scene(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext != ".obj" && ext != ".gltf" && ext != ".glb")
        throw std::invalid_argument("load_scene: cannot tell the format of '" + path +
                                    "' from its extension; supported: .obj, .gltf, .glb");
    if (ext == ".obj") return load_obj(path);
    return load_gltf(path, ext == ".glb");
}

bool scene_bounds(const std::vector<Draw>& draws, glm::dvec3& lo, glm::dvec3& hi) {
    bool any = false;
    glm::dvec3 a(std::numeric_limits<double>::infinity()), b(-std::numeric_limits<double>::infinity());
    for (const Draw& d : draws) {
        if (!d.mesh) continue;
        for (const glm::vec3& p : d.mesh->positions) {
            const glm::dvec4 w = d.model * glm::dvec4(glm::dvec3(p), 1.0);
            if (!(std::abs(w.w) > 0.0)) continue;
            const glm::dvec3 q = glm::dvec3(w) / w.w;
            a = glm::min(a, q);
            b = glm::max(b, q);
            any = true;
        }
    }
    if (any) {
        lo = a;
        hi = b;
    }
    return any;
}

Camera framing_camera(const std::vector<Draw>& draws, double fovy, double aspect) {
    glm::dvec3 lo, hi;
    if (!scene_bounds(draws, lo, hi))
        return Camera::look_at_perspective({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, fovy, aspect, 0.01);
    const glm::dvec3 centre = (lo + hi) * 0.5;
    double radius = glm::length(hi - lo) * 0.5;
    if (!(radius > 0.0)) radius = 1.0;  // a single point (or degenerate bounds)
    // The sphere fits when its distance is radius / sin(half the narrower field of view).
    const double half_fov = std::min(fovy * 0.5, std::atan(std::tan(fovy * 0.5) * aspect));
    const double distance = radius / std::sin(half_fov);
    const glm::dvec3 direction = glm::normalize(glm::dvec3(1.0, 0.6, 1.4));
    const double near = std::max((distance - radius) * 0.5, distance * 1e-4);
    return Camera::look_at_perspective(centre + direction * distance, centre, {0, 1, 0}, fovy, aspect, near);
}

}  // namespace mipraster
