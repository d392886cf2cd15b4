// Scene files: the format chosen by extension (OBJ/MTL in obj_file.cpp, glTF 2.0 in
// gltf_file.cpp), cameras named in files, and a camera that frames a scene.
#include "mipraster/io/scene_file.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "file_extension.hpp"
#include "scene_file_readers.hpp"

namespace mipraster {

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
    LoadedScene scene = ext == ".obj" ? scene_files::load_obj(path) : scene_files::load_gltf(path, ext == ".glb");
    // Not an error (an empty file is a valid scene), but a render of it shows only the clear
    // colour: say so rather than leave a blank image unexplained.
    const bool any_triangle = std::any_of(scene.draws.begin(), scene.draws.end(),
                                          [](const Draw& d) { return d.mesh && !d.mesh->triangles.empty(); });
    if (!any_triangle)
        scene.warnings.push_back(path + ": the file holds no triangles; a render shows only the clear colour");
    return scene;
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
