#pragma once
// Scene files: Wavefront OBJ (+ MTL) and glTF 2.0 (.gltf with its buffers, .glb) read into
// meshes, draws and cameras. Part of mipraster_io, the one module that includes the file-format
// libraries (tinyobjloader, tinygltf); this header names none of their types.
//
// What loads now: triangle geometry, vertex colours, texture coordinates and normals, the
// material's constant colour (OBJ Kd, glTF baseColorFactor) and base colour texture (OBJ map_Kd,
// glTF baseColorTexture) with its sampler, glTF node transforms, alpha blending and face culling,
// and glTF cameras. Image files are decoded by the io module (texture_file.hpp, OpenImageIO).
// Other textures (normal, metallic-roughness, occlusion, emissive maps), skins, morph targets and
// animations are ignored; normals are carried on the meshes but shading does not use them yet.
#include <memory>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "mipraster/pipeline/draw.hpp"
#include "mipraster/scene/camera.hpp"
#include "mipraster/scene/mesh.hpp"

namespace mipraster {

/// A camera from a scene file, kept as parameters: the projection needs the image's aspect
/// ratio, which is known only at render time (build()).
struct NamedCamera {
    enum class Projection { perspective, orthographic };

    std::string name;
    Projection projection = Projection::perspective;
    double yfov = 0.0;          ///< perspective: vertical field of view, radians
    double aspect_ratio = 0.0;  ///< perspective: width/height from the file; 0 = the image's
    double xmag = 0.0, ymag = 0.0;  ///< orthographic: half width and half height of the view
    double znear = 0.0;         ///< near plane distance (> 0 for perspective)
    double zfar = kInfiniteFar; ///< far plane distance; kInfiniteFar for an infinite perspective
    glm::dmat4 view{1.0};       ///< world → view: the inverse of the camera node's world matrix

    /// The camera for an image of the given aspect (width / height): reverse-Z perspective
    /// (infinite far plane when zfar is infinite; the file's aspect ratio when it gives one) or
    /// reverse-Z orthographic [−xmag, xmag]×[−ymag, ymag]×[−znear, −zfar].
    /// Throws std::invalid_argument for a non-positive or non-finite aspect.
    Camera build(double aspect) const;

    std::string to_string() const;
};

std::string to_string(NamedCamera::Projection projection);

/// Everything a scene file gave: meshes (owned here; draws point into them), draws in file order
/// with their world (model) matrices, cameras, and warnings about what was skipped.
struct LoadedScene {
    std::vector<std::shared_ptr<Mesh>> meshes;
    std::vector<Draw> draws;
    std::vector<NamedCamera> cameras;
    std::vector<std::string> warnings;  ///< skipped primitives, unsupported features, loader notes
};

/// Loads a scene file, choosing the reader by extension (case-insensitive):
///  - `.obj` (+ its `mtllib` MTL files, looked up next to the OBJ; every file of the line, names
///    with spaces or `\`): positions, faces (polygons are triangulated: a quad along its shorter
///    diagonal unless that one lies outside it, larger polygons by ear clipping), vertex colours
///    of the `v x y z r g b` extension (linear; used only when every vertex has one), texture
///    coordinates (`vt`, with v flipped: v' = 1 − v, DESIGN.md §1) and normals (`vn`), and one draw
///    per material with color = Kd taken as linear RGB (white when the material gives no Kd or
///    when faces have no material or an undefined one, with a warning). A material with d < 1
///    (else Tr > 0: d = 1 − Tr) blends "over" with the colour premultiplied by d, as glTF BLEND.
///    Vertices are split by their (position, vt, vn) index triple, so each mesh is compact and a
///    position with two texture coordinates becomes two vertices; a mesh has uvs (normals) only
///    when every face of its draw gives them. A material with `map_Kd` textures its faces with
///    texture coordinates: the file relative to the MTL file's folder, else the OBJ's (`\` read as
///    `/`; a path that is not there, such as another machine's absolute path, falls back to its
///    file name there, and letter case is ignored when needed, with a warning), decoded as sRGB
///    (`-colorspace linear`: linear), its alpha used only when d < 1, with the default sampler
///    (trilinear, repeat; `-clamp on`: clamp); its `-s` scale and `-o` offset are applied to the
///    uvs (uv·s + o, before the flip); `-mm`, `-t` and `-cc on` are warned about and not applied,
///    other options skipped.
///    Its faces without texture coordinates become a separate untextured draw, with a warning.
///    The text may have a byte order mark, CRLF or CR line ends, `\` continuations and comments
///    after statements; l and p elements are skipped with a warning. OBJ has no cameras.
///  - `.gltf` (JSON with external or data-URI buffers and images) and `.glb` (binary, images in
///    bufferViews too): the default scene (else scene 0, else every root node); every node's
///    mesh primitives of mode TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN (strips and fans become
///    triangles in the glTF spec's order, which keeps their winding for culling; fewer than 3
///    vertices give none and a warning; points and lines are skipped with a warning), indexed
///    with any index component type or not, from dense or sparse accessors (sparse: the base
///    values from its bufferView, or zeros without one, with sparse.values written over the
///    elements sparse.indices names), POSITION, COLOR_0 (vec3/vec4; float or normalized
///    unsigned byte/short, all linear; vec4 is premultiplied), the texture coordinates the
///    material's baseColorTexture reads (TEXCOORD_<texCoord>; TEXCOORD_0 for other materials;
///    vec2, float or normalized unsigned byte/short; in files that use KHR_mesh_quantization
///    also byte/short, normalized or not, and unnormalized unsigned byte/short) as uvs and NORMAL (vec3; float or
///    normalized byte/short) as normals, drawn with the node's world matrix (matrix or TRS,
///    composed down the hierarchy); material baseColorFactor as the draw colour (linear RGBA;
///    alphaMode BLEND blends "over" with the colour premultiplied by its alpha, other modes are
///    opaque: alpha 1); doubleSided false culls back faces. The material's
///    pbrMetallicRoughness.baseColorTexture becomes draw.texture: its image decoded from sRGB
///    into linear premultiplied RGBA (external files relative to the .gltf, percent-decoded;
///    data URIs and bufferViews from memory), its alpha ignored unless the material blends; the
///    texture's sampler becomes draw.sampler: wrapS/wrapT 10497 REPEAT → repeat, 33071
///    CLAMP_TO_EDGE → clamp, 33648 MIRRORED_REPEAT → mirror; magFilter 9728 NEAREST / 9729
///    LINEAR → mag_filter; minFilter 9728 / 9729 → min_filter nearest / linear with mip_filter
///    none, 9984 NEAREST_MIPMAP_NEAREST, 9985 LINEAR_MIPMAP_NEAREST, 9986 NEAREST_MIPMAP_LINEAR,
///    9987 LINEAR_MIPMAP_LINEAR → (min_filter, mip_filter) = (nearest, nearest), (linear,
///    nearest), (nearest, linear), (linear, linear); undefined filters keep the library default
///    (trilinear), the footprint is isotropic, and values that are no glTF enum are warned about
///    and replaced by the defaults. A baseColorTexture on a primitive without the TEXCOORD_n it
///    reads, or whose texture has no source image is skipped with a warning (the draw is
///    untextured). The texture's KHR_texture_transform is applied to the mesh's uvs as they are
///    read: uv' = T(offset)·R(rotation)·S(scale)·uv with R = [[cos, sin], [−sin, cos]] (row by
///    row, as Khronos' sample models use it), and its texCoord overrides the texture's. A mesh node
///    with EXT_mesh_gpu_instancing is drawn once per instance: each triangle primitive, with all
///    its instances in order, as draws that share the primitive's mesh, at model = node world
///    matrix × T·R·S of the instance (TRANSLATION and SCALE VEC3 float, ROTATION VEC4 quaternion
///    x, y, z, w, float or normalized byte/short; a missing one is the identity; other attributes
///    such as _ID are not read; the node's children are not instanced; a node without a mesh ignores
///    the extension, one without any of the three attributes is drawn once with a warning). Cameras
///    attached to nodes become NamedCameras in node order. Each extension in extensionsUsed that can
///    change how the file looks and that the loader does not apply (KHR_materials_pbrSpecularGlossiness,
///    KHR_node_visibility, and extensions it does not know) gives one warning naming it; lights,
///    KHR_materials_* lighting and material effects, and extensions whose fallback is drawn
///    (compressed geometry, other image formats, MSFT_lod), animation and metadata give none.
/// A texture file that is missing, unreadable or corrupt does not stop the load: the draw gets
/// error_texture() (an 8×8 magenta/black checker) and a warning naming the material and the
/// file. Images are shared through the texture cache (load_texture), so loading the same files
/// again reuses their textures.
/// Throws std::invalid_argument naming the path and the supported extensions for another
/// extension, and std::runtime_error (or std::invalid_argument from Mesh::validate) whose
/// message names the file and the problem for a missing, truncated or corrupt file, an
/// accessor outside its buffer or of the wrong type or count (e.g. TEXCOORD_0 that is not VEC2),
/// a sparse accessor whose indices are out of range, not strictly increasing or of a type other
/// than unsigned byte/short/int, whose index or value views lie outside their buffers, or whose
/// sparse count exceeds its count, an extensionsRequired entry other than EXT_mesh_gpu_instancing,
/// KHR_materials_unlit, KHR_mesh_quantization and KHR_texture_transform (e.g. Draco or meshopt
/// compression), KHR_texture_transform values of the wrong type or length
/// (naming the material), EXT_mesh_gpu_instancing accessors of unequal counts, of the wrong type,
/// with non-finite values or a zero quaternion (naming the node and the accessor), an index out of
/// range (vertex, texture coordinate, normal, material, texture, sampler, image source, instance
/// accessor), an image bufferView outside its buffer, a node cycle or absurd counts; MemoryLimitError
/// when a node's instances × (its draws and the triangles a render sets up) exceed memory_limit().
LoadedScene load_scene(const std::string& path);

/// World-space axis-aligned bounds of the draws' vertices (model matrices applied). Returns
/// false (and leaves lo/hi alone) when there are no vertices.
bool scene_bounds(const std::vector<Draw>& draws, glm::dvec3& lo, glm::dvec3& hi);

/// A camera that frames the draws: it looks at the centre of their bounding box from the
/// direction (1, 0.6, 1.4) (normalized), far enough that the bounding sphere fits the vertical
/// and horizontal field of view; reverse-Z with an infinite far plane. An empty scene gives a
/// camera at (0, 0, 3) looking at the origin.
Camera framing_camera(const std::vector<Draw>& draws, double fovy, double aspect);

}  // namespace mipraster
