// glTF 2.0 files (.gltf with .bin or data-URI buffers, .glb) through tinygltf: accessors (dense
// and sparse) read with bounds checks, node transforms, materials, samplers and cameras. The only
// file that includes tinygltf.
#include "scene_file_readers.hpp"

#include "mipraster/core/constants.hpp"
#include "mipraster/core/memory_limit.hpp"
#include "mipraster/io/texture_file.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include <tiny_gltf.h>

namespace mipraster {
namespace scene_files {

namespace {

/// The node hierarchy is walked at most this deep (the recursion's stack; a deeper file is hostile).
constexpr int kMaxNodeDepth = 1024;
static_assert(kMaxNodeDepth > 0, "limits must be positive");

/// The encoded bytes of data-URI images, by image index, kept by keep_data_uri_image.
struct EmbeddedImages {
    std::map<int, std::vector<unsigned char>> bytes;
};

// tinygltf's image callback: decode nothing (textures are decoded by the io module's
// load_texture through OpenImageIO). Only data-URI images are kept, as encoded bytes: external
// files are read again relative to the glTF file by load_texture (which shares them), and
// bufferView images are read from their buffer, with bounds checks, by the loader (tinygltf
// passes a pointer it has not checked, so it is not touched here).
bool keep_data_uri_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                         const unsigned char* bytes, int size, void* user) {
    if (image->uri.empty() && image->bufferView < 0 && bytes != nullptr && size > 0)
        static_cast<EmbeddedImages*>(user)->bytes[index].assign(bytes, bytes + size);
    return true;
}

/// The bytes of base64 `text` (RFC 4648, with or without '=' padding); false where it holds
/// another character or a dangling one.
bool decode_base64(std::string_view text, std::vector<unsigned char>& out) {
    while (!text.empty() && text.back() == '=') text.remove_suffix(1);
    out.clear();
    out.reserve(text.size() / 4 * 3 + 2);
    std::uint32_t bits = 0;
    int count = 0;
    for (const char c : text) {
        const int v = c >= 'A' && c <= 'Z'   ? c - 'A'
                      : c >= 'a' && c <= 'z' ? c - 'a' + 26
                      : c >= '0' && c <= '9' ? c - '0' + 52
                      : c == '+'             ? 62
                      : c == '/'             ? 63
                                             : -1;
        if (v < 0) return false;
        bits = bits << 6 | static_cast<std::uint32_t>(v);
        if (++count == 4) {
            out.insert(out.end(), {static_cast<unsigned char>(bits >> 16), static_cast<unsigned char>(bits >> 8),
                                   static_cast<unsigned char>(bits)});
            bits = 0, count = 0;
        }
    }
    if (count == 1) return false;
    if (count >= 2) out.push_back(static_cast<unsigned char>(bits >> (count == 2 ? 4 : 10)));
    if (count == 3) out.push_back(static_cast<unsigned char>(bits >> 2));
    return true;
}

/// A URI reference with its %XX escapes decoded (glTF URIs are percent-encoded); an invalid
/// escape is kept as it is.
std::string percent_decode(const std::string& uri) {
    auto hex = [](char c) {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
            out += static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

/// Reads an accessor's elements as doubles (normalized integers mapped to [0, 1] / [−1, 1]),
/// after checking that every byte it names lies inside its buffer. A sparse accessor is
/// materialized first into an owned, tightly packed copy, which is then read like a dense one.
class AccessorReader {
public:
    AccessorReader(const tinygltf::Model& model, int index, const std::string& path, const std::string& what)
        : path_(path), what_(what) {
        if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
            fail(path, what + ": accessor " + std::to_string(index) + " does not exist (the file has " +
                           std::to_string(model.accessors.size()) + ")");
        const tinygltf::Accessor& a = model.accessors[index];
        what_ = what + " (accessor " + std::to_string(index) + (a.name.empty() ? "" : " '" + a.name + "'") + ")";
        count_ = a.count;
        components_ = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
        component_type_ = a.componentType;
        size_ = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
        normalized_ = a.normalized;
        if (components_ <= 0 || components_ > 16 || size_ <= 0)
            fail(path, what_ + ": unsupported type " + std::to_string(a.type) + " / component type " +
                           std::to_string(a.componentType));
        if (count_ > kMaxElements) fail(path, what_ + ": absurd count " + std::to_string(count_));
        if (a.sparse.isSparse) {
            materialize_sparse(model, a);
        } else if (count_ > 0) {
            read_dense(model, a);
        }
    }
    // data_ may point into owned_: a copy would point into the original's.
    AccessorReader(const AccessorReader&) = delete;
    AccessorReader& operator=(const AccessorReader&) = delete;

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

    std::size_t element_size() const { return static_cast<std::size_t>(components_) * static_cast<std::size_t>(size_); }

    /// Buffer view `index`, after checking that it and its buffer exist and that it lies inside the
    /// buffer; `part` ("" or "sparse indices: " / "sparse values: ") says which part of the accessor
    /// uses it.
    const tinygltf::BufferView& checked_view(const tinygltf::Model& model, int index, const std::string& part) const {
        if (index < 0 || static_cast<std::size_t>(index) >= model.bufferViews.size())
            fail(path_, what_ + ": " + part + "buffer view " + std::to_string(index) + " does not exist");
        const tinygltf::BufferView& view = model.bufferViews[index];
        if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size())
            fail(path_, what_ + ": " + part + "buffer " + std::to_string(view.buffer) + " does not exist");
        const std::size_t buffer_size = model.buffers[view.buffer].data.size();
        if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset)
            fail(path_, what_ + ": " + part + "buffer view " + std::to_string(index) + " (offset " +
                            std::to_string(view.byteOffset) + ", length " + std::to_string(view.byteLength) +
                            ") lies outside its buffer of " + std::to_string(buffer_size) + " bytes");
        return view;
    }

    /// The bytes [offset, offset + needed) of buffer view `index`, which hold `elements` elements,
    /// after checking that they lie inside the view (and the view inside its buffer).
    const unsigned char* view_range(const tinygltf::Model& model, int index, std::size_t offset, std::size_t needed,
                                    std::size_t elements, const std::string& part) const {
        const tinygltf::BufferView& view = checked_view(model, index, part);
        if (offset > view.byteLength || needed > view.byteLength - offset)
            fail(path_, what_ + ": " + part + std::to_string(elements) + " elements need " + std::to_string(needed) +
                            " bytes from byte offset " + std::to_string(offset) + ", buffer view " +
                            std::to_string(index) + " has " + std::to_string(view.byteLength));
        return model.buffers[view.buffer].data.data() + view.byteOffset + offset;
    }

    /// Points data_ at the accessor's count_ (> 0) elements in its buffer view, stride_ apart.
    void read_dense(const tinygltf::Model& model, const tinygltf::Accessor& a) {
        const tinygltf::BufferView& view = checked_view(model, a.bufferView, "");
        const std::size_t element = element_size();
        stride_ = view.byteStride ? view.byteStride : element;
        if (stride_ < element || stride_ > 252 + element)
            fail(path_, what_ + ": byte stride " + std::to_string(view.byteStride) + " is invalid");
        // count ≤ 2^32 and stride ≤ 256: the product does not overflow.
        data_ = view_range(model, a.bufferView, a.byteOffset, (count_ - 1) * stride_ + element, count_, "");
    }

    /// A sparse accessor (glTF 2.0 §3.6.2.3) copied into owned_, tightly packed: the base values
    /// from its buffer view (zeros when it has none), then element sparse.indices[k] replaced by
    /// sparse.values[k]. The indices must be unsigned byte/short/int, strictly increasing and below
    /// count; both arrays are tightly packed in their views.
    void materialize_sparse(const tinygltf::Model& model, const tinygltf::Accessor& a) {
        const auto& sparse = a.sparse;
        if (sparse.count < 1)
            fail(path_, what_ + ": sparse count " + std::to_string(sparse.count) + " must be at least 1");
        const std::size_t n = static_cast<std::size_t>(sparse.count);
        if (n > count_)
            fail(path_, what_ + ": sparse count " + std::to_string(n) + " is larger than the accessor's count " +
                            std::to_string(count_));
        const int index_type = sparse.indices.componentType;
        if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(path_, what_ + ": sparse indices must be unsigned byte, short or int, got component type " +
                            std::to_string(index_type));
        if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0)
            fail(path_, what_ + ": sparse byte offsets must not be negative");

        const std::size_t element = element_size();
        // Without a base view, a few bytes of JSON can ask for count × element bytes of zeros.
        check_memory(static_cast<std::uint64_t>(count_) * element, path_ + ": " + what_ + " (a sparse accessor)");
        owned_.assign(count_ * element, 0);
        if (a.bufferView >= 0) {
            read_dense(model, a);
            for (std::size_t i = 0; i < count_; ++i) std::memcpy(&owned_[i * element], data_ + i * stride_, element);
        }
        const std::size_t index_size = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(index_type));
        const unsigned char* indices = view_range(model, sparse.indices.bufferView, sparse.indices.byteOffset,
                                                  n * index_size, n, "sparse indices: ");
        const unsigned char* values = view_range(model, sparse.values.bufferView, sparse.values.byteOffset,
                                                 n * element, n, "sparse values: ");
        for (std::size_t k = 0; k < n; ++k) {
            const std::uint64_t i = unsigned_at(indices + k * index_size, index_type);
            if (i >= count_)
                fail(path_, what_ + ": sparse index " + std::to_string(i) + " (element " + std::to_string(k) +
                                ") is out of range (the accessor's count is " + std::to_string(count_) + ")");
            if (k > 0 && i <= unsigned_at(indices + (k - 1) * index_size, index_type))
                fail(path_, what_ + ": sparse indices are not strictly increasing: " +
                                std::to_string(unsigned_at(indices + (k - 1) * index_size, index_type)) +
                                " is followed by " + std::to_string(i) + " (element " + std::to_string(k) + ")");
            std::memcpy(&owned_[i * element], values + k * element, element);
        }
        data_ = owned_.data();
        stride_ = element;
    }

    /// The unsigned integer of component type `type` (unsigned byte, short or int) at p.
    static std::uint64_t unsigned_at(const unsigned char* p, int type) {
        switch (type) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load<std::uint8_t>(p);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load<std::uint16_t>(p);
            default: return load<std::uint32_t>(p);
        }
    }

    std::string path_, what_;
    std::vector<unsigned char> owned_;  // a sparse accessor's materialized elements
    const unsigned char* data_ = nullptr;
    std::size_t count_ = 0, stride_ = 0;
    int components_ = 0, component_type_ = 0, size_ = 0;
    bool normalized_ = false;
};

/// T·R·S (glTF 2.0 §3.5.3) from a translation, a rotation quaternion (x, y, z, w), normalized here,
/// and a scale. Nodes and EXT_mesh_gpu_instancing instances both build their matrices here, so an
/// instance and a node with the same numbers get the same matrix, bit for bit. A quaternion of
/// length zero or not finite is an error naming `what`.
glm::dmat4 trs_matrix(const glm::dvec3& translation, const glm::dvec4& rotation, const glm::dvec3& scale,
                      const std::string& path, const std::string& what) {
    glm::dmat4 t(1.0), s(1.0);
    t[3] = glm::dvec4(translation, 1.0);
    const glm::dquat q(rotation.w, rotation.x, rotation.y, rotation.z);  // glm takes (w, x, y, z)
    const double len = glm::length(q);
    if (!(len > 0.0) || !std::isfinite(len)) fail(path, what + " is not a valid quaternion");
    const glm::dmat4 r = glm::mat4_cast(q / len);
    s[0][0] = scale.x;
    s[1][1] = scale.y;
    s[2][2] = scale.z;
    return t * r * s;
}

glm::dmat4 node_matrix(const tinygltf::Node& node, const std::string& path, int index) {
    const std::string what = "node " + std::to_string(index) + " ('" + node.name + "')";
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) fail(path, what + ": matrix must have 16 numbers");
        glm::dmat4 m;
        for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = node.matrix[i];  // column-major, as glTF stores it
        return m;
    }
    glm::dvec3 t(0.0), s(1.0);
    glm::dvec4 r(0.0, 0.0, 0.0, 1.0);
    if (!node.translation.empty()) {
        if (node.translation.size() != 3) fail(path, what + ": translation must have 3 numbers");
        t = glm::dvec3(node.translation[0], node.translation[1], node.translation[2]);
    }
    if (!node.rotation.empty()) {
        if (node.rotation.size() != 4) fail(path, what + ": rotation must have 4 numbers");
        r = glm::dvec4(node.rotation[0], node.rotation[1], node.rotation[2], node.rotation[3]);
    }
    if (!node.scale.empty()) {
        if (node.scale.size() != 3) fail(path, what + ": scale must have 3 numbers");
        s = glm::dvec3(node.scale[0], node.scale[1], node.scale[2]);
    }
    return trs_matrix(t, r, s, path, what + ": rotation");
}

/// Whether a primitive mode is one of triangles (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN; −1: not
/// given, TRIANGLES) rather than POINTS, LINES, LINE_LOOP, LINE_STRIP or a value glTF does not define.
bool draws_triangles(int mode) {
    return mode == -1 || mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
           mode == TINYGLTF_MODE_TRIANGLE_FAN;
}

/// Which texture coordinate set (TEXCOORD_<set>) becomes a primitive's uvs, and the affine map
/// that KHR_texture_transform applies to it: uv' = T(offset)·R(rotation)·S(scale)·uv.
struct UvChoice {
    int set = 0;
    bool transformed = false;  // (the identity is skipped: it would turn an infinite v into NaN u)
    glm::dvec2 offset{0.0}, scale{1.0};
    double rotation = 0.0;

    /// The transformed uv. R is [[cos, sin], [−sin, cos]] (row by row), the rotation Khronos'
    /// sample models, Blender and three.js use: the extension's GLSL listing fills a column-major
    /// mat3 with the same numbers, which reads as the transpose (KhronosGroup/glTF issue #1563);
    /// its example (offset (0, 1), rotation π/2, scale ½ selects the lower-left quadrant) agrees
    /// with this form only.
    glm::vec2 apply(glm::dvec2 uv) const {
        const double c = std::cos(rotation), s = std::sin(rotation);
        const glm::dvec2 scaled = uv * scale;
        return glm::vec2(c * scaled.x + s * scaled.y + offset.x, -s * scaled.x + c * scaled.y + offset.y);
    }
};

/// Each node's parent (−1: none). glTF's nodes form disjoint trees: a node is listed as a child at
/// most once, by one parent. A node shared by two parents would be drawn once per path to it, twice
/// as often with each level of sharing: a file of a kilobyte could ask for millions of draws.
std::vector<int> node_parents(const tinygltf::Model& model, const std::string& path) {
    std::vector<int> parent(model.nodes.size(), -1);
    for (std::size_t p = 0; p < model.nodes.size(); ++p)
        for (int child : model.nodes[p].children) {
            if (child < 0 || static_cast<std::size_t>(child) >= model.nodes.size()) continue;  // (add_node names it)
            const int first = parent[static_cast<std::size_t>(child)];
            if (first >= 0)
                fail(path, "node " + std::to_string(child) + " is listed as a child " +
                               (static_cast<std::size_t>(first) == p
                                    ? "twice by node " + std::to_string(p)
                                    : "by both node " + std::to_string(first) + " and node " + std::to_string(p)) +
                               " (a glTF node has at most one parent)");
            parent[static_cast<std::size_t>(child)] = static_cast<int>(p);
        }
    return parent;
}

struct GltfLoader {
    const tinygltf::Model& model;
    const std::string& path;
    const EmbeddedImages& embedded;
    LoadedScene scene;
    // (mesh, primitive, morph weights, skin or −1) → mesh
    std::map<std::tuple<int, int, std::vector<double>, int>, std::shared_ptr<Mesh>> mesh_cache;
    std::map<std::pair<int, bool>, Texture> texture_cache;            // (image, ignore alpha) → texture
    std::set<std::string> warned;                                     // warnings given once
    std::size_t skipped_primitives = 0;
    std::vector<bool> on_path;  // nodes on the current root-to-node path (cycle detection)
    std::vector<int> parents;   // node_parents
    std::map<int, glm::dmat4> globals;  // global_matrix's, by node
    bool quantized = false;     // the file uses KHR_mesh_quantization (integer texture coordinates)

    GltfLoader(const tinygltf::Model& m, const std::string& p, const EmbeddedImages& e, std::vector<int> parent)
        : model(m), path(p), embedded(e), on_path(m.nodes.size(), false), parents(std::move(parent)) {
        const auto lists = [&](const std::vector<std::string>& names) {
            return std::find(names.begin(), names.end(), "KHR_mesh_quantization") != names.end();
        };
        quantized = lists(m.extensionsUsed) || lists(m.extensionsRequired);
    }

    void warn_once(const std::string& message) {
        if (warned.insert(message).second) scene.warnings.push_back(path + ": " + message);
    }

    static std::string material_name(const tinygltf::Material& mat, int index) {
        const std::string where = "materials[" + std::to_string(index) + "]";
        return mat.name.empty() ? "material " + where : "material '" + mat.name + "' (" + where + ")";
    }

    /// The draw's colour, blending, alpha test, culling, base colour texture and sampler from its material.
    void apply_material(Draw& draw, const tinygltf::Primitive& prim, int mesh_index, int prim_index) {
        const std::string prim_what =
            "meshes[" + std::to_string(mesh_index) + "].primitives[" + std::to_string(prim_index) + "]";
        if (prim.material < 0) {
            draw.state.cull = CullMode::back;  // the default material is single-sided
            return;
        }
        if (static_cast<std::size_t>(prim.material) >= model.materials.size())
            fail(path, prim_what + ": material " + std::to_string(prim.material) + " does not exist (the file has " +
                           std::to_string(model.materials.size()) + ")");
        const tinygltf::Material& mat = model.materials[prim.material];
        const std::string name = material_name(mat, prim.material);
        const std::vector<double>& f = mat.pbrMetallicRoughness.baseColorFactor;
        if (f.size() != 4) fail(path, name + ": baseColorFactor must have 4 numbers");
        for (double v : f)
            if (!std::isfinite(v)) fail(path, name + ": baseColorFactor is not finite");
        if (mat.alphaMode != "OPAQUE" && mat.alphaMode != "MASK" && mat.alphaMode != "BLEND")
            warn_once(name + ": alphaMode '" + mat.alphaMode + "' is not OPAQUE, MASK or BLEND; using OPAQUE");
        const bool blend = mat.alphaMode == "BLEND";
        // MASK: alpha-tested against alphaCutoff (tinygltf gives the spec's default, 0.5, when the
        // file has none), then drawn opaque with replace blending.
        const bool mask = mat.alphaMode == "MASK";
        if (blend || mask) {
            draw.color = glm::vec4(f[0] * f[3], f[1] * f[3], f[2] * f[3], f[3]);
            if (blend) draw.state.blend = BlendMode::over;
        } else {
            draw.color = glm::vec4(f[0], f[1], f[2], 1.0);
        }
        for (int c = 0; c < 4; ++c)  // (finite doubles beyond float's range, or their products)
            if (!std::isfinite(draw.color[c]))
                fail(path, name + ": baseColorFactor is beyond float's range (the colour overflows to infinity)");
        if (mask) {
            const double cutoff = mat.alphaCutoff;
            if (cutoff >= 0.0 && cutoff <= 1.0) {
                draw.state.alpha_cutoff = static_cast<float>(cutoff);
            } else {
                warn_once(name + ": alphaCutoff " + std::to_string(cutoff) + " is not in [0, 1]; using " +
                          std::to_string(kDefaultAlphaCutoff));
                draw.state.alpha_cutoff = kDefaultAlphaCutoff;
            }
        }
        if (!mat.doubleSided) draw.state.cull = CullMode::back;

        // Base colour texture, on the uvs base_color_uvs chose (and transformed) for the mesh.
        const tinygltf::TextureInfo& info = mat.pbrMetallicRoughness.baseColorTexture;
        if (info.index < 0) return;
        if (static_cast<std::size_t>(info.index) >= model.textures.size())
            fail(path, name + ": baseColorTexture index " + std::to_string(info.index) +
                           " does not exist (the file has " + std::to_string(model.textures.size()) + " textures)");
        const tinygltf::Texture& tex = model.textures[info.index];
        const std::string tex_what = "textures[" + std::to_string(info.index) + "]";
        Sampler sampler = sampler_of(tex.sampler, tex_what);  // checks the index even when unused below
        const int source = texture_source(tex, tex_what);
        if (!draw.mesh->has_uvs()) {
            warn_once(prim_what + " has no TEXCOORD_" + std::to_string(base_color_uvs(prim.material).set) +
                      " but its " + name +
                      " has a baseColorTexture; drawn without the texture");
            return;
        }
        if (source < 0) {
            warn_once(tex_what + " (used by " + name +
                      ") has no source image (only extension images such as KTX2 or AVIF?); drawn without it");
            return;
        }
        draw.texture = image_texture(source, name, /*ignore_alpha=*/!(blend || mask));
        draw.sampler = sampler;
    }

    /// The image a texture draws: its EXT_texture_webp source where it has one (that extension asks
    /// clients that read WebP to prefer it; the core source is then a PNG or JPEG fallback, or
    /// absent), else its core source; −1 for none. An index that does not exist is an error.
    int texture_source(const tinygltf::Texture& tex, const std::string& tex_what) {
        int source = tex.source;
        std::string what = tex_what + ": source image ";
        const auto webp = tex.extensions.find("EXT_texture_webp");
        if (webp != tex.extensions.end() && webp->second.IsObject() && webp->second.Has("source")) {
            const tinygltf::Value& v = webp->second.Get("source");
            if (!v.IsInt()) fail(path, tex_what + ": EXT_texture_webp source is not an image index");
            source = v.GetNumberAsInt();
            what = tex_what + ": EXT_texture_webp source image ";
            if (source < 0) fail(path, what + std::to_string(source) + " is not an image index");
        }
        if (source >= 0 && static_cast<std::size_t>(source) >= model.images.size())
            fail(path, what + std::to_string(source) + " does not exist (the file has " +
                           std::to_string(model.images.size()) + " images)");
        return source;
    }

    /// glTF sampler → Sampler. Undefined filters keep the library default (trilinear); undefined
    /// wraps are REPEAT. Unknown enum values are warned about and replaced by the defaults.
    Sampler sampler_of(int index, const std::string& tex_what) {
        Sampler s;
        if (index < 0) return s;
        if (static_cast<std::size_t>(index) >= model.samplers.size())
            fail(path, tex_what + ": sampler " + std::to_string(index) + " does not exist (the file has " +
                           std::to_string(model.samplers.size()) + " samplers)");
        const tinygltf::Sampler& g = model.samplers[index];
        const std::string what = "samplers[" + std::to_string(index) + "]";
        auto wrap = [&](int mode, const char* field) {
            switch (mode) {
                case TINYGLTF_TEXTURE_WRAP_REPEAT: return WrapMode::repeat;
                case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return WrapMode::clamp;
                case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return WrapMode::mirror;
                default:
                    warn_once(what + ": " + field + " " + std::to_string(mode) +
                              " is not a glTF wrap mode; using REPEAT");
                    return WrapMode::repeat;
            }
        };
        s.wrap_u = wrap(g.wrapS, "wrapS");
        s.wrap_v = wrap(g.wrapT, "wrapT");
        switch (g.magFilter) {
            case -1: break;
            case TINYGLTF_TEXTURE_FILTER_NEAREST: s.mag_filter = TexelFilter::nearest; break;
            case TINYGLTF_TEXTURE_FILTER_LINEAR: s.mag_filter = TexelFilter::linear; break;
            default:
                warn_once(what + ": magFilter " + std::to_string(g.magFilter) + " is not a glTF filter; using LINEAR");
        }
        // minFilter = texel filter within a level + filter between levels.
        switch (g.minFilter) {
            case -1: break;
            case TINYGLTF_TEXTURE_FILTER_NEAREST:
                s.min_filter = TexelFilter::nearest, s.mip_filter = MipFilter::none;
                break;
            case TINYGLTF_TEXTURE_FILTER_LINEAR:
                s.min_filter = TexelFilter::linear, s.mip_filter = MipFilter::none;
                break;
            case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
                s.min_filter = TexelFilter::nearest, s.mip_filter = MipFilter::nearest;
                break;
            case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
                s.min_filter = TexelFilter::linear, s.mip_filter = MipFilter::nearest;
                break;
            case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
                s.min_filter = TexelFilter::nearest, s.mip_filter = MipFilter::linear;
                break;
            case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR:
                s.min_filter = TexelFilter::linear, s.mip_filter = MipFilter::linear;
                break;
            default:
                warn_once(what + ": minFilter " + std::to_string(g.minFilter) +
                          " is not a glTF filter; using LINEAR_MIPMAP_LINEAR");
        }
        return s;
    }

    /// The texture of image `index` (sRGB colour; alpha ignored for opaque materials), decoded once
    /// per load. An image that cannot be read gives the error texture and a warning naming the
    /// material and the file; an image whose bufferView lies outside its buffer is an error.
    Texture image_texture(int index, const std::string& material, bool ignore_alpha) {
        const auto key = std::make_pair(index, ignore_alpha);
        if (auto it = texture_cache.find(key); it != texture_cache.end()) return it->second;
        const tinygltf::Image& image = model.images[index];
        const std::string what =
            "images[" + std::to_string(index) + "]" + (image.name.empty() ? "" : " ('" + image.name + "')");
        TextureFileOptions options;
        options.srgb = true;  // glTF base colour textures are sRGB
        options.ignore_alpha = ignore_alpha;
        Texture texture;
        std::string source;  // the file or the embedded image, for the warning
        const unsigned char* view_bytes = nullptr;
        std::size_t view_size = 0;
        if (image.uri.empty() && image.bufferView >= 0)
            buffer_view_bytes(image.bufferView, what, view_bytes, view_size);  // a bad view is an error, not a warning
        try {
            if (image.uri.rfind("data:", 0) == 0) {  // tinygltf decodes PNG, JPEG, BMP and GIF data URIs only
                source = what + " (data URI)";
                const std::size_t comma = image.uri.find(',');
                const std::string header = image.uri.substr(0, std::min<std::size_t>(comma, 64));
                std::vector<unsigned char> bytes;
                if (comma == std::string::npos || header.size() < 7 ||
                    header.compare(header.size() - 7, 7, ";base64") != 0 ||
                    !decode_base64(std::string_view(image.uri).substr(comma + 1), bytes))
                    throw std::runtime_error("'" + header + "' is not a base64 data URI");
                texture = load_texture_from_memory(bytes.data(), bytes.size(), path + " " + what, options);
            } else if (!image.uri.empty()) {
                const std::string uri = percent_decode(image.uri);
                source = "'" + uri + "'";
                if (uri.find("://") != std::string::npos)
                    throw std::runtime_error("only relative file URIs are supported");
                source = "'" + directory_of(path) + uri + "'";
                texture = load_texture(directory_of(path) + uri, options);
            } else if (image.bufferView >= 0) {
                source = what + " (bufferView " + std::to_string(image.bufferView) + ")";
                texture = load_texture_from_memory(view_bytes, view_size, path + " " + what, options);
            } else {
                source = what + " (data URI)";
                const auto it = embedded.bytes.find(index);
                if (it == embedded.bytes.end()) throw std::runtime_error("the data URI holds no bytes");
                texture = load_texture_from_memory(it->second.data(), it->second.size(), path + " " + what, options);
            }
        } catch (const std::exception& e) {  // missing, unreadable, corrupt or too large
            warn_once(material + ": cannot load its base colour texture " + source + " (" + e.what() +
                      "); drawing the error texture instead");
            texture = error_texture();
        }
        texture_cache.emplace(key, texture);
        return texture;
    }

    /// The bytes of a bufferView, after checking that they lie inside its buffer.
    void buffer_view_bytes(int index, const std::string& what, const unsigned char*& bytes, std::size_t& size) const {
        if (index < 0 || static_cast<std::size_t>(index) >= model.bufferViews.size())
            fail(path, what + ": buffer view " + std::to_string(index) + " does not exist");
        const tinygltf::BufferView& view = model.bufferViews[index];
        if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size())
            fail(path, what + ": buffer " + std::to_string(view.buffer) + " does not exist");
        const std::vector<unsigned char>& buffer = model.buffers[view.buffer].data;
        if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
            fail(path, what + ": buffer view " + std::to_string(index) + " (offset " + std::to_string(view.byteOffset) +
                           ", length " + std::to_string(view.byteLength) + ") lies outside its buffer of " +
                           std::to_string(buffer.size()) + " bytes");
        bytes = buffer.data() + view.byteOffset;
        size = view.byteLength;
    }

    /// Whether the material's alpha counts: it blends (BLEND) or is alpha-tested (MASK).
    bool material_uses_alpha(int material) const {
        if (material < 0 || static_cast<std::size_t>(material) >= model.materials.size()) return false;
        const std::string& mode = model.materials[material].alphaMode;
        return mode == "BLEND" || mode == "MASK";
    }

    /// The primitive's vertices in drawing order: its indices (any unsigned component type, each
    /// checked against the vertex count), or 0, 1, …, vertex_count − 1 when it has none.
    std::vector<std::uint32_t> vertex_sequence(const tinygltf::Primitive& prim, std::size_t vertex_count,
                                               const std::string& what) const {
        std::vector<std::uint32_t> sequence;
        if (prim.indices == -1) {  // (tinygltf's "none", a written -1 too; other negatives are named below)
            sequence.resize(vertex_count);
            for (std::size_t i = 0; i < vertex_count; ++i) sequence[i] = static_cast<std::uint32_t>(i);
            return sequence;
        }
        const AccessorReader idx(model, prim.indices, path, what + " indices");
        if (idx.components() != 1) fail(path, idx.what() + ": indices must be SCALAR");
        sequence.resize(idx.count());
        for (std::size_t i = 0; i < idx.count(); ++i) {
            const std::uint64_t v = idx.get_index(i);
            if (v >= vertex_count)
                fail(path, idx.what() + ": index " + std::to_string(v) + " (element " + std::to_string(i) +
                               ") is out of range (" + std::to_string(vertex_count) + " vertices)");
            sequence[i] = static_cast<std::uint32_t>(v);
        }
        return sequence;
    }

    /// The triangles of a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN vertex sequence v, in the order
    /// of the glTF 2.0 spec (§3.7.2.1): strip triangle i is (v[i], v[i+1+i%2], v[i+2−i%2]), i.e. odd
    /// triangles swap their last two vertices so that all keep the strip's winding (back-face
    /// culling depends on it); fan triangle i is (v[i+1], v[i+2], v[0]). Leftover vertices (a
    /// TRIANGLES count that is no multiple of 3) and strips or fans of fewer than 3 vertices give
    /// a warning.
    std::vector<glm::uvec3> assemble_triangles(int mode, const std::vector<std::uint32_t>& v,
                                               const std::string& what) {
        const std::size_t n = v.size();
        std::vector<glm::uvec3> triangles;
        if (mode == TINYGLTF_MODE_TRIANGLES || mode == -1) {
            if (n % 3 != 0)
                scene.warnings.push_back(path + ": " + what + ": vertex count " + std::to_string(n) +
                                         " is not a multiple of 3; the last vertices are ignored");
            triangles.resize(n / 3);
            for (std::size_t t = 0; t < triangles.size(); ++t) triangles[t] = {v[3 * t], v[3 * t + 1], v[3 * t + 2]};
            return triangles;
        }
        const bool strip = mode == TINYGLTF_MODE_TRIANGLE_STRIP;
        if (n < 3) {
            scene.warnings.push_back(path + ": " + what + ": a triangle " + (strip ? "strip" : "fan") + " of " +
                                     std::to_string(n) + " vertices has no triangle");
            return triangles;
        }
        triangles.resize(n - 2);
        for (std::size_t i = 0; i < n - 2; ++i)
            triangles[i] = strip ? glm::uvec3(v[i], v[i + 1 + i % 2], v[i + 2 - i % 2])
                                 : glm::uvec3(v[i + 1], v[i + 2], v[0]);
        return triangles;
    }

    /// The texture coordinate set the base colour texture of material `material` reads
    /// (baseColorTexture.texCoord, or its KHR_texture_transform's texCoord) and that extension's
    /// transform; set 0 and the identity for no material, an untextured one or one that does not
    /// exist (apply_material reports that). Malformed transform values are an error naming the
    /// material.
    UvChoice base_color_uvs(int material) const {
        UvChoice choice;
        if (material < 0 || static_cast<std::size_t>(material) >= model.materials.size()) return choice;
        const tinygltf::Material& mat = model.materials[material];
        const tinygltf::TextureInfo& info = mat.pbrMetallicRoughness.baseColorTexture;
        if (info.index < 0) return choice;
        choice.set = info.texCoord;
        const auto ext = info.extensions.find("KHR_texture_transform");
        if (ext == info.extensions.end()) return choice;

        choice.transformed = true;
        const std::string what = material_name(mat, material) + ": KHR_texture_transform ";
        const tinygltf::Value& t = ext->second;  // (an object: tinygltf drops extensions that are not)
        const auto finite_number = [](const tinygltf::Value& v) {
            return v.IsNumber() && std::isfinite(v.GetNumberAsDouble());
        };
        const auto pair = [&](const char* key, glm::dvec2 value) {
            if (!t.Has(key)) return value;
            const tinygltf::Value& v = t.Get(key);
            if (!v.IsArray() || v.ArrayLen() != 2 || !finite_number(v.Get(0)) || !finite_number(v.Get(1)))
                fail(path, what + key + " must be 2 finite numbers");
            return glm::dvec2(v.Get(0).GetNumberAsDouble(), v.Get(1).GetNumberAsDouble());
        };
        choice.offset = pair("offset", choice.offset);
        choice.scale = pair("scale", choice.scale);
        if (t.Has("rotation")) {
            if (!finite_number(t.Get("rotation"))) fail(path, what + "rotation must be a finite number");
            choice.rotation = t.Get("rotation").GetNumberAsDouble();
        }
        if (t.Has("texCoord")) {  // overrides the textureInfo's
            const tinygltf::Value& v = t.Get("texCoord");
            if (!v.IsInt() || v.GetNumberAsInt() < 0) fail(path, what + "texCoord must be an integer >= 0");
            choice.set = v.GetNumberAsInt();
        }
        return choice;
    }

    /// Whether a TEXCOORD_n component type is allowed: float or normalized unsigned byte/short
    /// (glTF 2.0), and in files that use KHR_mesh_quantization also byte and short (normalized or
    /// not) and unnormalized unsigned byte/short, read as their integer values.
    bool texcoord_type_allowed(int type, bool normalized) const {
        if (float_or_unit_unsigned(type, normalized)) return true;
        return quantized && (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                             type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT || type == TINYGLTF_COMPONENT_TYPE_BYTE ||
                             type == TINYGLTF_COMPONENT_TYPE_SHORT);
    }

    /// Morph target deltas of TEXCOORD_n and COLOR_n: float, or normalized (un)signed byte/short
    /// (and with KHR_mesh_quantization, texture coordinate deltas as plain byte/short too).
    bool delta_type_allowed(int type, bool normalized) const {
        const bool small_integer = type == TINYGLTF_COMPONENT_TYPE_BYTE || type == TINYGLTF_COMPONENT_TYPE_SHORT ||
                                   type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                   type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        return type == TINYGLTF_COMPONENT_TYPE_FLOAT || (small_integer && (normalized || quantized));
    }

    /// Float, or normalized unsigned byte/short: glTF 2.0's types for colours, weights and uvs.
    static bool float_or_unit_unsigned(int type, bool normalized) {
        return type == TINYGLTF_COMPONENT_TYPE_FLOAT ||
               ((type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) &&
                normalized);
    }

    /// An error unless vertex attribute r (`name` in the message) has one element per vertex.
    void check_per_vertex(const AccessorReader& r, const std::string& name, std::size_t vertices) const {
        if (r.count() != vertices)
            fail(path, r.what() + ": " + name + " has " + std::to_string(r.count()) + " elements, POSITION " +
                           std::to_string(vertices));
    }

    /// The morph target weights a node's mesh is drawn at: the node's, else the mesh's defaults
    /// (none: the base shape); empty when all are zero, so that such nodes share one mesh.
    std::vector<double> morph_weights(const tinygltf::Node& node, int index, const tinygltf::Mesh& m) {
        const std::vector<double>& w = node.weights.empty() ? m.weights : node.weights;
        std::size_t targets = 0;
        for (const tinygltf::Primitive& prim : m.primitives) targets = std::max(targets, prim.targets.size());
        const std::string whose = node.weights.empty() ? "its mesh's weights" : "its weights";
        if (!w.empty() && w.size() != targets)
            fail(path, "node " + std::to_string(index) + ": " + whose + " has " + std::to_string(w.size()) +
                           " entries for " + std::to_string(targets) + " morph targets");
        for (double x : w)
            if (!std::isfinite(x)) fail(path, "node " + std::to_string(index) + ": " + whose + " are not finite");
        return std::all_of(w.begin(), w.end(), [](double x) { return x == 0.0; }) ? std::vector<double>{} : w;
    }

    /// Adds each morph target's `name` deltas times its weight to `values` (one per vertex):
    /// POSITION (VEC3), TEXCOORD_n (VEC2) and COLOR_n (VEC4, or VEC3 with an alpha delta of 0) —
    /// normals and tangents, the other standard targets, do not change an unlit render. True when
    /// some delta was added.
    template <int N>
    bool morph(const tinygltf::Primitive& prim, const std::vector<double>& weights, const std::string& name,
               std::vector<glm::vec<N, double>>& values, const std::string& what) {
        const bool colour = name.rfind("COLOR_", 0) == 0;
        bool added = false;
        for (std::size_t t = 0; t < weights.size() && t < prim.targets.size(); ++t) {
            const auto it = prim.targets[t].find(name);
            if (weights[t] == 0.0 || it == prim.targets[t].end()) continue;
            const AccessorReader d(model, it->second, path, what + " targets[" + std::to_string(t) + "] " + name);
            const int width = d.components();
            if (width != N && !(colour && width == 3))
                fail(path,
                     d.what() + ": " + name + " must be " + (colour ? "VEC3 or VEC4" : "VEC" + std::to_string(N)));
            if (name != "POSITION" && !delta_type_allowed(d.component_type(), d.normalized()))
                fail(path, d.what() + ": " + name + " deltas must be float or normalized byte/short, got component " +
                               "type " + std::to_string(d.component_type()));
            check_per_vertex(d, "the target's " + name, values.size());
            for (std::size_t i = 0; i < values.size(); ++i)
                for (int c = 0; c < width; ++c) values[i][c] += weights[t] * d.get(i, c);
            added = true;
        }
        return added;
    }

    /// A node's matrix in the scene: its ancestors' matrices times its own (nodes have one parent).
    glm::dmat4 global_matrix(int node) {
        std::vector<int> chain;  // node, its parent, … up to a root or a node already known
        int n = node;
        for (; n >= 0 && !globals.count(n); n = parents[static_cast<std::size_t>(n)]) {
            if (chain.size() > static_cast<std::size_t>(kMaxNodeDepth))
                fail(path, "node " + std::to_string(node) + ": its ancestors form a cycle or lie more than " +
                               std::to_string(kMaxNodeDepth) + " levels deep");
            chain.push_back(n);
        }
        glm::dmat4 m = n >= 0 ? globals[n] : glm::dmat4(1.0);
        for (auto c = chain.rbegin(); c != chain.rend(); ++c)
            globals[*c] = m = m * node_matrix(model.nodes[static_cast<std::size_t>(*c)], path, *c);
        return m;
    }

    /// Skin k's joint matrices at the nodes' own transforms (the rest pose; animations are not
    /// played): each joint's global matrix times its inverse bind matrix.
    std::vector<glm::dmat4> joint_matrices(int k) {
        if (k < 0 || static_cast<std::size_t>(k) >= model.skins.size())
            fail(path, "skin " + std::to_string(k) + " does not exist (the file has " +
                           std::to_string(model.skins.size()) + ")");
        const tinygltf::Skin& skin = model.skins[static_cast<std::size_t>(k)];
        const std::string what = "skins[" + std::to_string(k) + "]";
        std::vector<glm::dmat4> joints(skin.joints.size(), glm::dmat4(1.0));
        if (skin.inverseBindMatrices >= 0) {
            const AccessorReader ibm(model, skin.inverseBindMatrices, path, what + " inverseBindMatrices");
            if (ibm.components() != 16) fail(path, ibm.what() + ": inverseBindMatrices must be MAT4");
            if (ibm.count() != joints.size())
                fail(path, ibm.what() + ": has " + std::to_string(ibm.count()) + " matrices for " +
                               std::to_string(joints.size()) + " joints");
            for (std::size_t j = 0; j < joints.size(); ++j)
                for (int c = 0; c < 16; ++c) joints[j][c / 4][c % 4] = ibm.get(j, c);  // (column-major)
        }
        for (std::size_t j = 0; j < joints.size(); ++j) {
            const int node = skin.joints[j];
            if (node < 0 || static_cast<std::size_t>(node) >= model.nodes.size())
                fail(path, what + ": joint " + std::to_string(j) + " is node " + std::to_string(node) +
                               ", which does not exist");
            joints[j] = global_matrix(node) * joints[j];
        }
        return joints;
    }

    /// Moves each vertex by its joints' matrices weighted by its weights (JOINTS_n / WEIGHTS_n, every
    /// set the primitive has): linear blend skinning, into the scene's space.
    void apply_skin(const tinygltf::Primitive& prim, const std::vector<glm::dmat4>& joints,
                    std::vector<glm::dvec3>& positions, const std::string& what) {
        std::vector<glm::dvec3> skinned(positions.size(), glm::dvec3(0.0));  // Σ weight · joint · position
        for (int set = 0;; ++set) {
            const auto j_it = prim.attributes.find("JOINTS_" + std::to_string(set));
            const auto w_it = prim.attributes.find("WEIGHTS_" + std::to_string(set));
            if (j_it == prim.attributes.end() || w_it == prim.attributes.end()) break;
            const AccessorReader index(model, j_it->second, path, what + " JOINTS_" + std::to_string(set));
            const AccessorReader weight(model, w_it->second, path, what + " WEIGHTS_" + std::to_string(set));
            const int it = index.component_type();
            if (index.components() != 4 || index.normalized() ||
                (it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT))
                fail(path, index.what() + ": JOINTS must be VEC4 of unsigned byte or short");
            if (weight.components() != 4 || !float_or_unit_unsigned(weight.component_type(), weight.normalized()))
                fail(path, weight.what() + ": WEIGHTS must be VEC4 of float or normalized unsigned byte or short");
            check_per_vertex(index, "JOINTS_" + std::to_string(set), positions.size());
            check_per_vertex(weight, "WEIGHTS_" + std::to_string(set), positions.size());
            for (std::size_t i = 0; i < positions.size(); ++i)
                for (int c = 0; c < 4; ++c) {
                    const double w = weight.get(i, c);
                    if (w == 0.0) continue;
                    const double j = index.get(i, c);
                    if (j >= static_cast<double>(joints.size()))
                        fail(path, index.what() + ": vertex " + std::to_string(i) + " names joint " +
                                       std::to_string(static_cast<long long>(j)) + " of " +
                                       std::to_string(joints.size()));
                    skinned[i] += w * glm::dvec3(joints[static_cast<std::size_t>(j)] * glm::dvec4(positions[i], 1.0));
                }
        }
        positions = std::move(skinned);
    }

    /// The mesh of a primitive, its positions, uvs and colours moved by its morph targets at `weights`
    /// (morph_weights) and its positions, when `skin` is not −1, by that skin's `joints` (joint_matrices).
    std::shared_ptr<Mesh> primitive_mesh(int mesh_index, int prim_index, const std::vector<double>& weights, int skin,
                                         const std::vector<glm::dmat4>& joints) {
        const auto key = std::make_tuple(mesh_index, prim_index, weights, skin);
        if (auto it = mesh_cache.find(key); it != mesh_cache.end()) return it->second;
        const tinygltf::Primitive& prim = model.meshes[mesh_index].primitives[prim_index];
        const std::string what =
            "meshes[" + std::to_string(mesh_index) + "].primitives[" + std::to_string(prim_index) + "]";
        auto mesh = std::make_shared<Mesh>();

        // Positions.
        const auto pos_it = prim.attributes.find("POSITION");
        if (pos_it == prim.attributes.end()) fail(path, what + ": no POSITION attribute");
        const AccessorReader pos(model, pos_it->second, path, what + " POSITION");
        if (pos.components() != 3) fail(path, pos.what() + ": POSITION must be VEC3");
        std::vector<glm::dvec3> positions(pos.count());
        for (std::size_t i = 0; i < pos.count(); ++i)
            positions[i] = glm::dvec3(pos.get(i, 0), pos.get(i, 1), pos.get(i, 2));
        morph(prim, weights, "POSITION", positions, what);
        if (skin >= 0) apply_skin(prim, joints, positions, what);
        mesh->positions.resize(pos.count());
        for (std::size_t i = 0; i < pos.count(); ++i) mesh->positions[i] = glm::vec3(positions[i]);

        // Vertex colours (linear); premultiplied by their alpha when the material blends or masks,
        // opaque otherwise (alpha is ignored for OPAQUE materials).
        if (const auto col_it = prim.attributes.find("COLOR_0"); col_it != prim.attributes.end()) {
            const AccessorReader col(model, col_it->second, path, what + " COLOR_0");
            if (col.components() != 3 && col.components() != 4)
                fail(path, col.what() + ": COLOR_0 must be VEC3 or VEC4");
            if (!float_or_unit_unsigned(col.component_type(), col.normalized()))
                fail(path, col.what() + ": COLOR_0 must be float or normalized unsigned byte/short");
            check_per_vertex(col, "COLOR_0", pos.count());
            // Morphed (the spec's COLOR_n deltas, then a clamp to [0, 1]) before premultiplying.
            std::vector<glm::dvec4> colours(col.count());
            for (std::size_t i = 0; i < col.count(); ++i)
                colours[i] = glm::dvec4(col.get(i, 0), col.get(i, 1), col.get(i, 2),
                                        col.components() == 4 ? col.get(i, 3) : 1.0);
            // The spec's colours lie in [0, 1] (normalized integers always do): float values beyond
            // are clamped, with a warning (a NaN is left to mesh->validate, which names it).
            std::size_t outside = 0, first = 0;
            for (std::size_t i = 0; i < colours.size(); ++i)
                for (int c = 0; c < 4; ++c)
                    if (colours[i][c] < 0.0 || colours[i][c] > 1.0) {
                        if (outside++ == 0) first = i;
                        colours[i][c] = std::clamp(colours[i][c], 0.0, 1.0);
                    }
            if (outside > 0) {
                const glm::dvec4 raw(col.get(first, 0), col.get(first, 1), col.get(first, 2),
                                     col.components() == 4 ? col.get(first, 3) : 1.0);
                std::ostringstream value;
                value << "(" << raw.r << ", " << raw.g << ", " << raw.b << ", " << raw.a << ")";
                warn_once(col.what() + ": " + std::to_string(outside) +
                          " value(s) outside [0, 1], the spec's range (vertex " + std::to_string(first) + " is " +
                          value.str() + "); clamped to [0, 1]");
            }
            if (morph(prim, weights, "COLOR_0", colours, what))
                for (glm::dvec4& c : colours) c = glm::clamp(c, 0.0, 1.0);
            const bool alpha = material_uses_alpha(prim.material);
            mesh->colors.resize(col.count());
            for (std::size_t i = 0; i < col.count(); ++i) {
                const glm::dvec4& c = colours[i];
                const double a = alpha ? c.a : 1.0;
                mesh->colors[i] = glm::vec4(c.r * a, c.g * a, c.b * a, a);
            }
        }

        // Texture coordinates: the set the material's base colour texture reads (TEXCOORD_0 when it
        // has none), with its KHR_texture_transform applied here (an affine map of the uvs commutes
        // with perspective-correct interpolation, so this is exact); float or normalized unsigned
        // byte/short (glTF's uv convention is ours). The material is this primitive's own, as is
        // this mesh (cached by (mesh, primitive)), so neither choice reaches another draw.
        const UvChoice choice = base_color_uvs(prim.material);
        const std::string uv_name = "TEXCOORD_" + std::to_string(choice.set);
        if (const auto uv_it = prim.attributes.find(uv_name); uv_it != prim.attributes.end()) {
            const AccessorReader uv(model, uv_it->second, path, what + " " + uv_name);
            if (uv.components() != 2) fail(path, uv.what() + ": " + uv_name + " must be VEC2");
            const int ct = uv.component_type();
            if (!texcoord_type_allowed(ct, uv.normalized()))
                fail(path, uv.what() + ": " + uv_name + " must be float or normalized unsigned byte/short" +
                               (quantized ? " (or byte/short, normalized or not, and unsigned byte/short with "
                                            "KHR_mesh_quantization)"
                                          : "") +
                               ", got component type " + std::to_string(ct) + (uv.normalized() ? " (normalized)" : ""));
            check_per_vertex(uv, uv_name, pos.count());
            std::vector<glm::dvec2> values(uv.count());
            for (std::size_t i = 0; i < uv.count(); ++i) values[i] = glm::dvec2(uv.get(i, 0), uv.get(i, 1));
            morph(prim, weights, uv_name, values, what);  // (before the texture transform, which maps the result)
            mesh->uvs.resize(uv.count());
            for (std::size_t i = 0; i < uv.count(); ++i)
                mesh->uvs[i] = choice.transformed ? choice.apply(values[i]) : glm::vec2(values[i]);
        }

        // Normals: float (or normalized signed byte/short, as KHR_mesh_quantization allows).
        if (const auto n_it = prim.attributes.find("NORMAL"); n_it != prim.attributes.end()) {
            const AccessorReader nrm(model, n_it->second, path, what + " NORMAL");
            if (nrm.components() != 3) fail(path, nrm.what() + ": NORMAL must be VEC3");
            const int ct = nrm.component_type();
            if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT &&
                !((ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_SHORT) && nrm.normalized()))
                fail(path, nrm.what() + ": NORMAL must be float or normalized byte/short, got component type " +
                               std::to_string(ct));
            check_per_vertex(nrm, "NORMAL", pos.count());
            mesh->normals.resize(nrm.count());
            for (std::size_t i = 0; i < nrm.count(); ++i)
                mesh->normals[i] = glm::vec3(nrm.get(i, 0), nrm.get(i, 1), nrm.get(i, 2));
        }

        // Triangles: the vertex sequence (the indices, or the vertices in order) assembled by mode.
        mesh->triangles = assemble_triangles(prim.mode, vertex_sequence(prim, pos.count(), what), what);
        mesh->validate(path + " " + what);
        scene.meshes.push_back(mesh);
        mesh_cache.emplace(key, mesh);
        return mesh;
    }

    /// Adds the draws and cameras of the hierarchy below root, depth first, each node before its
    /// children. A walk with its own stack, not a recursion: at the depth limit the recursion's
    /// frames took 0.8 MB of the thread's stack, 8.5 MB with AddressSanitizer (more than there was).
    void add_tree(int root) {
        struct Visit {
            int index;
            glm::dmat4 world;
            int depth;
            std::size_t next_child;
        };
        std::vector<Visit> path_from_root = {{root, add_node(root, glm::dmat4(1.0), 0), 0, 0}};
        while (!path_from_root.empty()) {
            Visit& v = path_from_root.back();
            const std::vector<int>& children = model.nodes[static_cast<std::size_t>(v.index)].children;
            if (v.next_child == children.size()) {
                on_path[v.index] = false;
                path_from_root.pop_back();
                continue;
            }
            const int child = children[v.next_child++], depth = v.depth + 1;
            const glm::dmat4 world = add_node(child, v.world, depth);
            path_from_root.push_back({child, world, depth, 0});  // (v is not used past this)
        }
    }

    /// Checks node `index` (depth levels below its root), adds its draws and camera and marks it
    /// on the path from the root (add_tree clears the mark after its children); its world matrix.
    glm::dmat4 add_node(int index, const glm::dmat4& parent, int depth) {
        if (index < 0 || static_cast<std::size_t>(index) >= model.nodes.size())
            fail(path, "node " + std::to_string(index) + " does not exist (the file has " +
                           std::to_string(model.nodes.size()) + " nodes)");
        if (on_path[index])
            fail(path, "node " + std::to_string(index) + " is its own ancestor (a cycle in the node hierarchy)");
        if (depth > kMaxNodeDepth)
            fail(path, "node " + std::to_string(index) + " lies more than " + std::to_string(kMaxNodeDepth) +
                           " levels below its root, deeper than this loader follows the node hierarchy");
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
            std::vector<Draw> draws;  // one per triangle primitive, at the node's world matrix
            std::uint64_t triangles = 0;
            const std::vector<double> weights = morph_weights(node, index, m);
            const std::vector<glm::dmat4> joints =
                node.skin >= 0 ? joint_matrices(node.skin) : std::vector<glm::dmat4>{};
            for (std::size_t p = 0; p < m.primitives.size(); ++p) {
                const tinygltf::Primitive& prim = m.primitives[p];
                if (!draws_triangles(prim.mode)) {
                    ++skipped_primitives;
                    continue;
                }
                // A skinned primitive's vertices are placed by its joints alone: the spec has the
                // node's own transform ignored.
                const bool skinned =
                    node.skin >= 0 && prim.attributes.count("JOINTS_0") && prim.attributes.count("WEIGHTS_0");
                if (node.skin >= 0 && !skinned)
                    warn_once("node " + std::to_string(index) + " has a skin, but its mesh's primitive " +
                              std::to_string(p) + " has no JOINTS_0 and WEIGHTS_0: drawn unskinned, at the node");
                Draw draw;
                const int skin = skinned ? node.skin : -1;
                draw.mesh = primitive_mesh(node.mesh, static_cast<int>(p), weights, skin, joints).get();
                draw.model = skinned ? glm::dmat4(1.0) : world;
                apply_material(draw, prim, node.mesh, static_cast<int>(p));
                triangles += draw.mesh->triangles.size();
                draws.push_back(draw);
            }
            if (const auto instances = instance_matrices(node, index, world, draws.size(), triangles)) {
                // Primitive by primitive, each with all its instances, as a GPU draws them (the order
                // matters to blending only); every instance shares the primitive's mesh.
                for (const Draw& draw : draws)
                    for (const glm::dmat4& instance : *instances) {
                        scene.draws.push_back(draw);
                        scene.draws.back().model = instance;
                    }
            } else {
                scene.draws.insert(scene.draws.end(), draws.begin(), draws.end());
            }
        }

        if (node.camera >= 0) {
            if (static_cast<std::size_t>(node.camera) >= model.cameras.size())
                fail(path, "node " + std::to_string(index) + ": camera " + std::to_string(node.camera) +
                               " does not exist");
            scene.cameras.push_back(make_camera(model.cameras[node.camera], node.camera, world));
        }
        return world;
    }

    /// The world matrices of a mesh node's EXT_mesh_gpu_instancing instances: world × T·R·S of each
    /// instance, from its TRANSLATION (VEC3 float), ROTATION (VEC4 quaternion x, y, z, w: float, or
    /// normalized byte/short) and SCALE (VEC3 float) accessors, each optional (identity when missing)
    /// and all of one count; other attributes (_ID, custom ones) are not read. std::nullopt when the
    /// node has no such extension, or one without any of the three (with a warning): the node is
    /// drawn once. Before anything is read, instances × (a matrix, `draws` draws and `triangles`
    /// triangles set up by a render) are checked against the memory limit, so a few bytes of JSON
    /// cannot ask for billions of draws. Errors name the node and the accessor.
    std::optional<std::vector<glm::dmat4>> instance_matrices(const tinygltf::Node& node, int index,
                                                             const glm::dmat4& world, std::size_t draws,
                                                             std::uint64_t triangles) {
        const auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
        if (ext == node.extensions.end()) return std::nullopt;
        const std::string what =
            "node " + std::to_string(index) + " ('" + node.name + "'): EXT_mesh_gpu_instancing";
        const tinygltf::Value& e = ext->second;  // (an object: tinygltf drops extensions that are not)
        if (!e.Has("attributes") || !e.Get("attributes").IsObject())
            fail(path, what + ": attributes must be an object");
        const tinygltf::Value& attributes = e.Get("attributes");

        // The accessors, and their common count, from the accessors' headers alone.
        struct Attribute {
            const char* name;
            int accessor;
        };
        std::array<Attribute, 3> trs{{{"TRANSLATION", -1}, {"ROTATION", -1}, {"SCALE", -1}}};
        const Attribute* first = nullptr;
        std::size_t count = 0;
        for (Attribute& a : trs) {
            if (!attributes.Has(a.name)) continue;
            const tinygltf::Value& v = attributes.Get(a.name);
            if (!v.IsInt() || v.GetNumberAsInt() < 0)
                fail(path, what + ": " + a.name + " must be an accessor index");
            a.accessor = v.GetNumberAsInt();
            if (static_cast<std::size_t>(a.accessor) >= model.accessors.size())
                fail(path, what + ": " + a.name + ": accessor " + std::to_string(a.accessor) +
                               " does not exist (the file has " + std::to_string(model.accessors.size()) + ")");
            const std::size_t n = model.accessors[a.accessor].count;
            if (first == nullptr) {
                first = &a;
                count = n;
            } else if (n != count) {
                fail(path, what + ": " + a.name + " (accessor " + std::to_string(a.accessor) + ") has " +
                               std::to_string(n) + " elements, " + first->name + " (accessor " +
                               std::to_string(first->accessor) + ") " + std::to_string(count) +
                               "; every instance attribute must have the same count");
            }
        }
        if (first == nullptr) {
            warn_once(what + " has no TRANSLATION, ROTATION or SCALE attribute; drawn once at the node's transform");
            return std::nullopt;
        }
        const std::string counted = what + " " + first->name + " (accessor " + std::to_string(first->accessor) + ")";
        if (count > kMaxElements) fail(path, counted + ": absurd instance count " + std::to_string(count));
        // Every instance is a matrix here and a draw per primitive, and a render transforms and sets
        // up its triangles anew.
        const double bytes = static_cast<double>(count) *
                             (sizeof(glm::dmat4) + static_cast<double>(draws) * sizeof(Draw) +
                              static_cast<double>(triangles) * sizeof(SetupTriangle));
        check_memory(bytes < 0x1p63 ? static_cast<std::uint64_t>(bytes) : std::numeric_limits<std::uint64_t>::max(),
                     path + ": " + counted + ": " + std::to_string(count) + " instances of " +
                         std::to_string(triangles) + " triangle(s)");

        // The accessors, checked and read as everywhere (bounds, strides, sparse, normalized integers).
        std::array<std::optional<AccessorReader>, 3> readers;
        for (std::size_t k = 0; k < trs.size(); ++k) {
            if (trs[k].accessor < 0) continue;
            const std::string name = trs[k].name;
            const AccessorReader& r = readers[k].emplace(model, trs[k].accessor, path, what + " " + name);
            const int ct = r.component_type();
            const bool is_rotation = name == "ROTATION";
            if (r.components() != (is_rotation ? 4 : 3))
                fail(path, r.what() + ": " + name + " must be " + (is_rotation ? "VEC4" : "VEC3"));
            if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT &&
                !(is_rotation && r.normalized() &&
                  (ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_SHORT)))
                fail(path, r.what() + ": " + name + " must be float" +
                               (is_rotation ? " or normalized byte/short" : "") + ", got component type " +
                               std::to_string(ct) + (r.normalized() ? " (normalized)" : ""));
        }

        std::vector<glm::dmat4> matrices(count);
        for (std::size_t i = 0; i < count; ++i) {
            double v[3][4] = {{0.0, 0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 1.0}, {1.0, 1.0, 1.0, 0.0}};  // the identity
            for (std::size_t k = 0; k < readers.size(); ++k) {
                if (!readers[k]) continue;
                for (int c = 0; c < readers[k]->components(); ++c) {
                    v[k][c] = readers[k]->get(i, c);
                    if (!std::isfinite(v[k][c]))
                        fail(path, readers[k]->what() + ": " + trs[k].name + " of instance " + std::to_string(i) +
                                       " is not finite");
                }
            }
            const std::string instance = what + " instance " + std::to_string(i);
            matrices[i] = world * trs_matrix(glm::dvec3(v[0][0], v[0][1], v[0][2]),
                                             glm::dvec4(v[1][0], v[1][1], v[1][2], v[1][3]),
                                             glm::dvec3(v[2][0], v[2][1], v[2][2]), path, instance + ": ROTATION");
            for (int col = 0; col < 4; ++col)
                for (int row = 0; row < 4; ++row)
                    if (!std::isfinite(matrices[i][col][row]))
                        fail(path, instance + ": its world matrix is not finite");
        }
        return matrices;
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
            if (!(cam.yfov > 0.0 && cam.yfov < M_PI))
                fail(path, what + ": yfov must be in (0, pi), got " + std::to_string(cam.yfov));
            if (!(cam.znear > 0.0 && std::isfinite(cam.znear))) fail(path, what + ": znear must be > 0");
            if (!(cam.zfar > cam.znear)) fail(path, what + ": zfar must be > znear");
            if (!(cam.aspect_ratio >= 0.0 && std::isfinite(cam.aspect_ratio)))
                fail(path, what + ": aspectRatio must be > 0");
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

/// The glTF extensions a file may list in extensionsRequired and still load as its author meant:
/// those this loader reads (KHR_texture_transform on the base colour texture; KHR_mesh_quantization's
/// integer POSITION, NORMAL and TEXCOORD_n; EXT_mesh_gpu_instancing's instance transforms;
/// EXT_texture_webp's WebP images) and those that do not change what it draws (KHR_materials_unlit:
/// its renders are unlit anyway).
const std::set<std::string> kSupportedRequiredExtensions = {"EXT_mesh_gpu_instancing", "EXT_texture_webp",
                                                            "KHR_materials_unlit", "KHR_mesh_quantization",
                                                            "KHR_texture_transform"};

/// Extensions in extensionsUsed that cannot change this loader's unlit base-colour render, or whose
/// fallback it draws, so they get no warning: compressed geometry (a file that only uses it carries
/// the uncompressed data, which is read) and other image formats (a texture keeps a PNG/JPEG source;
/// one without is warned about by the material), detail levels (MSFT_lod: the node's own mesh is the
/// full detail), animation (the rest pose is drawn, as for core glTF animations), metadata, and
/// normal/roughness texture packing (lighting). Lights (KHR_lights_*, EXT_lights_*) and materials
/// (KHR_materials_*, see unapplied_extension_effect) are matched by prefix.
const std::set<std::string> kInvisibleExtensions = {
    "EXT_instance_features", "EXT_mesh_features", "EXT_mesh_manifold", "EXT_meshopt_compression",
    "EXT_structural_metadata", "EXT_texture_avif", "KHR_animation_pointer",
    "KHR_draco_mesh_compression", "KHR_meshopt_compression", "KHR_texture_basisu", "KHR_xmp", "KHR_xmp_json_ld",
    "MSFT_lod", "MSFT_packing_normalRoughnessMetallic", "MSFT_packing_occlusionRoughnessMetallic",
    "MSFT_texture_dds"};

/// What a render misses when the file uses `extension` and this loader does not apply it: "" for
/// one it applies (kSupportedRequiredExtensions) or that cannot change the render (kInvisibleExtensions,
/// lights, and KHR_materials_* other than pbrSpecularGlossiness: sheen, clearcoat, transmission,
/// volume, ior, specular, emissive strength, iridescence, … are lighting and material effects an
/// unlit render never shows, and variants are alternatives to the default materials, which are the
/// ones drawn). Extensions it does not know might change anything: they are named too.
std::string unapplied_extension_effect(const std::string& extension) {
    const auto starts = [&](const char* prefix) { return extension.rfind(prefix, 0) == 0; };
    if (kSupportedRequiredExtensions.count(extension) || kInvisibleExtensions.count(extension)) return "";
    if (extension == "KHR_materials_pbrSpecularGlossiness")
        return "its diffuseFactor and diffuseTexture, the base colour of the materials that use it, are not read "
               "(they are drawn with their pbrMetallicRoughness base colour, white when they give none)";
    if (extension == "KHR_node_visibility") return "the nodes it hides are drawn";
    if (starts("KHR_materials_") || starts("KHR_lights_") || starts("EXT_lights_")) return "";
    return "this loader does not know it, and whatever it changes is not drawn";
}

/// glTF 2.x only: a file of another major version (1.0 lays its objects out otherwise) or whose
/// minVersion is above 2.0 is an error naming the version, as the spec has loaders refuse them.
void check_version(const tinygltf::Model& model, const std::string& path) {
    int major = 0, minor = 0;
    const auto parses = [&](const std::string& v) { return std::sscanf(v.c_str(), "%d.%d", &major, &minor) == 2; };
    const std::string& version = model.asset.version;
    if (!version.empty() && (!parses(version) || major != 2))
        fail(path, "glTF version '" + version + "' is not supported (this loader reads glTF 2.x)");
    const std::string& least = model.asset.minVersion;
    if (!least.empty() && (!parses(least) || major != 2 || minor != 0))
        fail(path, "the file needs glTF " + least + " (asset.minVersion); this loader reads glTF 2.0");
}

/// A file that requires another extension (compressed geometry, other image formats, …) cannot
/// be drawn right: an error naming it. tinygltf only records the list, and without this the load
/// failed later on what the extension changes, e.g. "accessor[1] invalid bufferView" for Draco.
void check_required_extensions(const tinygltf::Model& model, const std::string& path) {
    for (const std::string& extension : model.extensionsRequired) {
        if (kSupportedRequiredExtensions.count(extension)) continue;
        std::string supported;
        for (const std::string& e : kSupportedRequiredExtensions) supported += (supported.empty() ? "" : ", ") + e;
        fail(path, "the file requires the glTF extension '" + extension +
                       "', which this loader does not support (it supports " + supported + ")");
    }
}

/// A .glb file's version (the header's second word) must be 2: version 1 (glTF 1.0's
/// KHR_binary_glTF) lays its chunks out otherwise, and tinygltf read it as version 2.
void check_glb_version(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char header[8] = {};
    if (!in.read(reinterpret_cast<char*>(header), sizeof header) || std::memcmp(header, "glTF", 4) != 0)
        return;  // (tinygltf names a short file or a wrong magic)
    const std::uint32_t version = static_cast<std::uint32_t>(header[4]) | static_cast<std::uint32_t>(header[5]) << 8 |
                                  static_cast<std::uint32_t>(header[6]) << 16 |
                                  static_cast<std::uint32_t>(header[7]) << 24;
    if (version != 2)
        fail(path, "GLB version " + std::to_string(version) + " is not supported (glTF 2.0 needs GLB version 2)");
}

// tinygltf's FileExists callback, for regular files only: a buffer whose uri named a directory
// was opened and its "size" allocated (std::bad_alloc).
bool regular_file_exists(const std::string& path, void*) {
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}

}  // namespace

LoadedScene load_gltf(const std::string& path, bool binary) {
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks({regular_file_exists, tinygltf::ExpandFilePath, tinygltf::ReadWholeFile,
                           tinygltf::WriteWholeFile, nullptr});
    EmbeddedImages embedded;
    loader.SetImageLoader(keep_data_uri_image, &embedded);
    if (binary) check_glb_version(path);
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    try {
        ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                    : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    } catch (const std::exception& e) {  // e.g. a JSON parser exception
        fail(path, std::string("cannot parse glTF: ") + e.what());
    }
    // tinygltf reads extensionsRequired before the buffers and accessors, so the list is there even
    // when the load failed on what an unsupported extension changes: that is the error to report.
    check_version(model, path);
    check_required_extensions(model, path);
    if (!ok) fail(path, "cannot read glTF: " + trim(err.empty() ? warn : err));

    GltfLoader g(model, path, embedded, node_parents(model, path));
    // tinygltf's notes about external image files it could not read are dropped: images are
    // loaded (or warned about, naming the material) by image_texture.
    std::istringstream lines(warn);
    std::string kept, line;
    while (std::getline(lines, line))
        if (line.rfind("File not found : ", 0) != 0 && line.rfind("File read error : ", 0) != 0 &&
            line.rfind("File is empty : ", 0) != 0 && line.rfind("Failed to load external 'uri' for image[", 0) != 0)
            kept += line + "\n";
    add_warnings(g.scene.warnings, path, kept);
    // An extension the file uses that changes what it looks like but is not applied is named (once).
    for (const std::string& extension : model.extensionsUsed)
        if (const std::string effect = unapplied_extension_effect(extension); !effect.empty())
            g.warn_once("the file uses the glTF extension '" + extension + "', which this loader does not apply: " +
                        effect);

    // Roots: the default scene, else scene 0, else every node that is no other node's child.
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        int s = model.defaultScene;
        if (s < 0) s = 0;
        if (static_cast<std::size_t>(s) >= model.scenes.size())
            fail(path, "default scene " + std::to_string(s) + " does not exist");
        roots = model.scenes[s].nodes;
        // A scene's nodes are roots, each listed once: a child or a repeat would be drawn twice.
        const std::string scene_what = "scenes[" + std::to_string(s) + "].nodes";
        std::set<int> listed;
        for (int r : roots) {
            if (r < 0 || static_cast<std::size_t>(r) >= model.nodes.size()) continue;  // (add_node names it)
            if (!listed.insert(r).second)
                fail(path, "node " + std::to_string(r) + " is listed twice in " + scene_what);
            if (const int parent = g.parents[static_cast<std::size_t>(r)]; parent >= 0)
                fail(path, "node " + std::to_string(r) + " is listed in " + scene_what + " and as a child of node " +
                               std::to_string(parent) + " (a scene lists only root nodes)");
        }
    } else {
        std::vector<bool> is_child(model.nodes.size(), false);
        for (const auto& n : model.nodes)
            for (int c : n.children)
                if (c >= 0 && static_cast<std::size_t>(c) < model.nodes.size()) is_child[c] = true;
        for (std::size_t i = 0; i < model.nodes.size(); ++i)
            if (!is_child[i]) roots.push_back(static_cast<int>(i));
    }
    for (int r : roots) g.add_tree(r);
    if (g.skipped_primitives)
        g.scene.warnings.push_back(path + ": skipped " + std::to_string(g.skipped_primitives) +
                                   " primitive(s) of mode POINTS or LINES, or of an unknown mode (only triangles "
                                   "are drawn)");
    return std::move(g.scene);
}

}  // namespace scene_files
}  // namespace mipraster
