#pragma once
// Scene files: Wavefront OBJ (+ MTL) and glTF 2.0 (.gltf with its buffers, .glb) read into
// meshes, draws and cameras. Part of mipraster_io, the one module that includes the file-format
// libraries (tinyobjloader, tinygltf); this header names none of their types.
//
// What loads now: triangle geometry, vertex colours, the material's constant colour (OBJ Kd,
// glTF baseColorFactor), glTF node transforms, alpha blending and face culling, and glTF cameras.
// Texture references (OBJ map_Kd, glTF textures and images) and texture coordinates are skipped:
// they are recorded nowhere until textures and samplers exist (the texture issue). Normals,
// skins, morph targets and animations are ignored as well.
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
///  - `.obj` (+ its `mtllib` MTL files, looked up next to the OBJ): positions, faces (polygons
///    are triangulated), vertex colours of the `v x y z r g b` extension (linear; used only when
///    every vertex has one), and one draw per material with color = Kd taken as linear RGB
///    (faces without a material: white). Texture coordinates are parsed but unused; map_Kd is
///    skipped. OBJ has no cameras.
///  - `.gltf` (JSON with external or data-URI buffers) and `.glb` (binary): the default scene
///    (else scene 0, else every root node); every node's mesh primitives of mode TRIANGLES
///    (others are skipped with a warning) with any index component type, POSITION and COLOR_0
///    (vec3/vec4; float or normalized unsigned byte/short, all linear; vec4 is premultiplied),
///    drawn with the node's world matrix (matrix or TRS, composed down the hierarchy);
///    material baseColorFactor as the draw colour (linear RGBA; alphaMode BLEND blends "over"
///    with the colour premultiplied by its alpha, other modes are opaque: alpha 1); doubleSided
///    false culls back faces. Cameras attached to nodes become NamedCameras in node order.
///    Textures and images are skipped (image files are not even decoded).
/// Throws std::invalid_argument naming the path and the supported extensions for another
/// extension, and std::runtime_error (or std::invalid_argument from Mesh::validate) whose
/// message names the file and the problem for a missing, truncated or corrupt file, an
/// accessor outside its buffer, an index out of range, a node cycle or absurd counts.
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
