// Scene bindings of mipraster._core: depth conventions and camera matrices, Camera, Mesh, Draw and
// the built-in demo scene.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "mipraster/core/huge_pages.hpp"
#include "mipraster/pipeline/draw.hpp"
#include "mipraster/scene/camera.hpp"
#include "mipraster/scene/demo_scene.hpp"
#include "mipraster/scene/mesh.hpp"
#include "scene.hpp"

namespace mipraster::bindings {

namespace {

// The mesh arrays are handed to numpy as views of the C++ vectors: these layouts must be packed.
static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be 3 packed floats");
static_assert(sizeof(glm::uvec3) == 3 * sizeof(std::uint32_t), "glm::uvec3 must be 3 packed uint32");
static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "glm::vec4 must be 4 packed floats");
static_assert(sizeof(glm::vec2) == 2 * sizeof(float), "glm::vec2 must be 2 packed floats");

// Copies an (N, C) array into a vector of GLM vectors of C components.
template <class Vec, class T>
std::vector<Vec> copy_rows(const CArray<T>& a, py::ssize_t columns, const char* name) {
    require_shape(a, {-1, columns}, name);
    std::vector<Vec> rows;
    reserve_on_huge_pages(rows, static_cast<std::size_t>(a.shape(0)));  // (read per triangle, all over)
    rows.resize(static_cast<std::size_t>(a.shape(0)));
    if (!rows.empty()) std::memcpy(rows.data(), a.data(), sizeof(Vec) * rows.size());
    return rows;
}

// A read-only (N, C) view of a vector owned by the Python object `owner` (a Mesh).
template <class T, class Vec>
py::object view_rows(const std::vector<Vec>& rows, py::ssize_t columns, py::handle owner) {
    const py::ssize_t n = static_cast<py::ssize_t>(rows.size());
    if (n == 0) return py::array_t<T>({n, columns});  // no storage to point at
    py::array_t<T> a({n, columns}, reinterpret_cast<const T*>(rows.data()), owner);
    a.attr("setflags")(py::arg("write") = false);
    return std::move(a);
}

// Copies an optional per-vertex array, checking it has one row per vertex.
template <class Vec>
std::vector<Vec> copy_per_vertex(const std::optional<CArray<float>>& a, py::ssize_t columns, const char* name,
                                 std::size_t vertex_count) {
    if (!a) return {};
    std::vector<Vec> rows = copy_rows<Vec>(*a, columns, name);
    if (rows.size() != vertex_count)
        throw py::value_error(std::string(name) + ": expected one row per vertex (" + std::to_string(vertex_count) +
                              "), got " + std::to_string(rows.size()));
    return rows;
}

std::shared_ptr<Mesh> make_mesh(const CArray<float>& positions, const CArray<std::uint32_t>& triangles,
                                const std::optional<CArray<float>>& colors, const std::optional<CArray<float>>& uvs,
                                const std::optional<CArray<float>>& normals) {
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = copy_rows<glm::vec3>(positions, 3, "positions");
    mesh->triangles = copy_rows<glm::uvec3>(triangles, 3, "triangles");
    mesh->colors = copy_per_vertex<glm::vec4>(colors, 4, "colors", mesh->positions.size());
    mesh->uvs = copy_per_vertex<glm::vec2>(uvs, 2, "uvs", mesh->positions.size());
    mesh->normals = copy_per_vertex<glm::vec3>(normals, 3, "normals", mesh->positions.size());
    mesh->validate("mesh");
    return mesh;
}

PyDraw make_draw(std::shared_ptr<Mesh> mesh, const std::optional<CArray<double>>& model,
                 const CArray<float>& color, bool depth_test, bool depth_write, BlendMode blend,
                 Interpolation interpolation, CullMode cull, const std::optional<Texture>& texture,
                 const std::optional<Sampler>& sampler, std::optional<float> alpha_cutoff) {
    if (!mesh) throw py::value_error("Draw: mesh is None");
    if (texture && *texture && !mesh->has_uvs())
        throw py::value_error("texture: the mesh has no uvs (give Mesh(..., uvs=...) to texture it)");
    if (sampler) sampler->validate();
    PyDraw d;
    d.draw.mesh = mesh.get();
    d.draw.model = model ? to_dmat4(*model, "model") : glm::dmat4(1.0);
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row)
            if (!std::isfinite(d.draw.model[col][row]))
                throw py::value_error("model[" + std::to_string(row) + ", " + std::to_string(col) +
                                      "] is not finite");
    d.draw.color = to_vec4(color, "color");
    d.draw.state.depth_test = depth_test;
    d.draw.state.depth_write = depth_write;
    d.draw.state.blend = blend;
    d.draw.state.interpolation = interpolation;
    d.draw.state.cull = cull;
    d.draw.state.alpha_cutoff = alpha_cutoff;
    d.draw.state.validate("Draw");  // (std::invalid_argument: a ValueError)
    if (texture) d.draw.texture = *texture;
    if (sampler) d.draw.sampler = *sampler;
    d.mesh = std::move(mesh);
    return d;
}

// make_demo_scene with the draws in their Python form (each holding its mesh).
struct PyDemoScene {
    std::vector<std::shared_ptr<Mesh>> meshes;
    std::vector<PyDraw> draws;
    Camera camera;
    glm::vec4 clear_color{0.0f};
};

PyDemoScene make_py_demo_scene(double aspect) {
    DemoScene demo = make_demo_scene(aspect);
    PyDemoScene out;
    out.meshes = demo.meshes;
    for (const Draw& draw : demo.draws) {
        PyDraw d;
        d.draw = draw;
        for (const auto& mesh : demo.meshes)
            if (mesh.get() == draw.mesh) d.mesh = mesh;
        if (!d.mesh) throw std::logic_error("make_demo_scene: a draw's mesh is not among the scene's meshes");
        out.draws.push_back(std::move(d));
    }
    out.camera = demo.camera;
    out.clear_color = demo.clear_color;
    return out;
}

}  // namespace

void bind_scene(py::module_& m) {
    // --- enums (names as in C++) ----------------------------------------------------------------
    py::enum_<DepthConvention>(m, "DepthConvention",
                               "How a projection maps view depth to clip z (and so the depth test).")
        .value("reverse_z", DepthConvention::reverse_z, "near -> 1, far/infinity -> 0; test GREATER, clear 0")
        .value("opengl", DepthConvention::opengl, "near -> -1, far -> +1; window depth z/2+1/2; test LESS, clear 1");
    py::enum_<BlendMode>(m, "BlendMode", "How a fragment combines with the framebuffer (premultiplied linear).")
        .value("replace", BlendMode::replace, "dst = src")
        .value("add", BlendMode::add, "dst = dst + src")
        .value("over", BlendMode::over, "dst = src + (1 - src.a) dst");
    py::enum_<Interpolation>(m, "Interpolation", "How vertex colours vary across a triangle.")
        .value("flat", Interpolation::flat, "the first vertex's value everywhere")
        .value("screen", Interpolation::screen, "affine in screen space")
        .value("perspective", Interpolation::perspective, "perspective-correct");
    py::enum_<CullMode>(m, "CullMode", "Face culling; front faces are counter-clockwise on screen.")
        .value("none", CullMode::none)
        .value("back", CullMode::back)
        .value("front", CullMode::front);

    // --- camera matrices --------------------------------------------------------------------------
    // Matrices cross the boundary as (4, 4) float64 arrays in the maths convention:
    // clip = projection @ view @ [x, y, z, 1].
    const double inf = std::numeric_limits<double>::infinity();
    m.attr("INFINITE_FAR") = inf;
    m.def(
        "look_at",
        [](const CArray<double>& eye, const CArray<double>& target, const CArray<double>& up) {
            return from_dmat4(look_at(to_dvec3(eye, "eye"), to_dvec3(target, "target"), to_dvec3(up, "up")));
        },
        py::arg("eye"), py::arg("target"), py::arg("up"),
        "Right-handed view matrix: the camera at eye looks at target down its -z axis, +y up.");
    m.def(
        "frustum",
        [](double l, double r, double b, double t, double n, double f, DepthConvention c) {
            return from_dmat4(frustum(l, r, b, t, n, f, c));
        },
        py::arg("left"), py::arg("right"), py::arg("bottom"), py::arg("top"), py::arg("near"), py::arg("far") = inf,
        py::arg("depth_convention") = DepthConvention::reverse_z,
        "Perspective projection of the frustum (left, right, bottom, top) at distance near.");
    m.def(
        "perspective",
        [](double fovy, double aspect, double n, double f, DepthConvention c) {
            return from_dmat4(perspective(fovy, aspect, n, f, c));
        },
        py::arg("fovy"), py::arg("aspect"), py::arg("near"), py::arg("far") = inf,
        py::arg("depth_convention") = DepthConvention::reverse_z,
        "Perspective projection from the vertical field of view (radians) and aspect = width / height.");
    m.def(
        "orthographic",
        [](double l, double r, double b, double t, double n, double f, DepthConvention c) {
            return from_dmat4(orthographic(l, r, b, t, n, f, c));
        },
        py::arg("left"), py::arg("right"), py::arg("bottom"), py::arg("top"), py::arg("near"), py::arg("far"),
        py::arg("depth_convention") = DepthConvention::reverse_z,
        "Orthographic projection of the box [left, right] x [bottom, top] x [-near, -far] in view space.");

    py::class_<Camera>(m, "Camera", "A camera: world -> view -> clip, and the depth convention it follows.")
        .def(py::init([](const CArray<double>& view, const CArray<double>& projection, DepthConvention c) {
                 return Camera::from_matrices(to_dmat4(view, "view"), to_dmat4(projection, "projection"), c);
             }),
             py::arg("view"), py::arg("projection"), py::arg("depth_convention") = DepthConvention::reverse_z)
        .def_static(
            "look_at_perspective",
            [](const CArray<double>& eye, const CArray<double>& target, const CArray<double>& up, double fovy,
               double aspect, double n) {
                return Camera::look_at_perspective(to_dvec3(eye, "eye"), to_dvec3(target, "target"),
                                                   to_dvec3(up, "up"), fovy, aspect, n);
            },
            py::arg("eye"), py::arg("target"), py::arg("up"), py::arg("fovy"), py::arg("aspect"), py::arg("near"),
            "Perspective camera, reverse-Z with an infinite far plane; fovy in radians.")
        .def_static(
            "from_matrices",
            [](const CArray<double>& view, const CArray<double>& projection, DepthConvention c) {
                return Camera::from_matrices(to_dmat4(view, "view"), to_dmat4(projection, "projection"), c);
            },
            py::arg("view"), py::arg("projection"), py::arg("depth_convention") = DepthConvention::opengl,
            "Raw matrices (clip = projection @ view @ p), OpenGL depth convention by default.")
        .def_property_readonly("view", [](const Camera& c) { return from_dmat4(c.view); })
        .def_property_readonly("projection", [](const Camera& c) { return from_dmat4(c.projection); })
        .def_readonly("depth_convention", &Camera::depth_convention)
        .def("__repr__", &Camera::to_string);

    // --- Mesh -------------------------------------------------------------------------------------
    py::class_<Mesh, std::shared_ptr<Mesh>>(
        m, "Mesh",
        "Indexed triangles: positions (N, 3) float32, triangles (T, 3) uint32 and optional colors (N, 4)\n"
        "float32 (linear, premultiplied RGBA), uvs (N, 2) float32 and normals (N, 3) float32. The arrays\n"
        "are copied in once and read back as read-only views.")
        .def(py::init(&make_mesh), py::arg("positions"), py::arg("triangles"), py::arg("colors") = py::none(),
             py::arg("uvs") = py::none(), py::arg("normals") = py::none())
        .def_property_readonly(
            "positions", [](py::object self) { return view_rows<float>(self.cast<const Mesh&>().positions, 3, self); })
        .def_property_readonly("triangles",
                               [](py::object self) {
                                   return view_rows<std::uint32_t>(self.cast<const Mesh&>().triangles, 3, self);
                               })
        .def_property_readonly("colors",
                               [](py::object self) -> py::object {
                                   const Mesh& mesh = self.cast<const Mesh&>();
                                   if (!mesh.has_colors()) return py::none();
                                   return view_rows<float>(mesh.colors, 4, self);
                               })
        .def_property_readonly("uvs",
                               [](py::object self) -> py::object {
                                   const Mesh& mesh = self.cast<const Mesh&>();
                                   if (!mesh.has_uvs()) return py::none();
                                   return view_rows<float>(mesh.uvs, 2, self);
                               })
        .def_property_readonly("normals",
                               [](py::object self) -> py::object {
                                   const Mesh& mesh = self.cast<const Mesh&>();
                                   if (mesh.normals.empty()) return py::none();
                                   return view_rows<float>(mesh.normals, 3, self);
                               })
        .def_property_readonly("vertex_count", [](const Mesh& mesh) { return mesh.positions.size(); })
        .def_property_readonly("triangle_count", [](const Mesh& mesh) { return mesh.triangles.size(); })
        .def("has_colors", &Mesh::has_colors)
        .def("has_uvs", &Mesh::has_uvs)
        .def("validate", &Mesh::validate, py::arg("name") = "mesh",
             "Raises ValueError naming the first non-finite value or out-of-range index.")
        .def("__repr__", &Mesh::to_string);

    // --- Draw -------------------------------------------------------------------------------------
    py::class_<PyDraw>(m, "Draw",
                       "One draw call: a mesh, its model matrix, a constant colour (premultiplied linear RGBA,\n"
                       "multiplied with the vertex colours), an optional base-colour texture with its sampler\n"
                       "(multiplied in too) and the fixed-function state. alpha_cutoff (None: off) alpha-tests\n"
                       "it: a fragment whose shaded alpha is below it writes nothing, one at or above it is written\n"
                       "opaque (rgb / alpha, alpha 1).")
        .def(py::init(&make_draw), py::arg("mesh"), py::arg("model") = py::none(),
             py::arg("color") = std::vector<float>{1.0f, 1.0f, 1.0f, 1.0f}, py::arg("depth_test") = true,
             py::arg("depth_write") = true, py::arg("blend") = BlendMode::replace,
             py::arg("interpolation") = Interpolation::perspective, py::arg("cull") = CullMode::none,
             py::arg("texture") = py::none(), py::arg("sampler") = py::none(), py::arg("alpha_cutoff") = py::none())
        .def_property_readonly("mesh", [](const PyDraw& d) { return d.mesh; })
        .def_property_readonly("model", [](const PyDraw& d) { return from_dmat4(d.draw.model); })
        .def_property_readonly("color", [](const PyDraw& d) { return from_vec4(d.draw.color); })
        .def_property_readonly("depth_test", [](const PyDraw& d) { return d.draw.state.depth_test; })
        .def_property_readonly("depth_write", [](const PyDraw& d) { return d.draw.state.depth_write; })
        .def_property_readonly("blend", [](const PyDraw& d) { return d.draw.state.blend; })
        .def_property_readonly("interpolation", [](const PyDraw& d) { return d.draw.state.interpolation; })
        .def_property_readonly("cull", [](const PyDraw& d) { return d.draw.state.cull; })
        .def_property_readonly("alpha_cutoff", [](const PyDraw& d) { return d.draw.state.alpha_cutoff; })
        .def_property_readonly("texture",
                               [](const PyDraw& d) -> std::optional<Texture> {
                                   if (!d.draw.texture) return std::nullopt;
                                   return d.draw.texture;
                               })
        .def_property_readonly("sampler", [](const PyDraw& d) { return d.draw.sampler; })
        .def("__repr__", [](const PyDraw& d) { return d.draw.to_string(); });

    // --- the built-in demo ------------------------------------------------------------------------
    py::class_<PyDemoScene>(m, "DemoScene", "The built-in demo: a lit, textured cube on a textured checker plane.")
        .def_readonly("meshes", &PyDemoScene::meshes)
        .def_readonly("draws", &PyDemoScene::draws)
        .def_readonly("camera", &PyDemoScene::camera)
        .def_property_readonly("clear_color", [](const PyDemoScene& s) { return from_vec4(s.clear_color); })
        .def("__repr__", [](const PyDemoScene& s) {
            return "DemoScene(draws=" + std::to_string(s.draws.size()) + ", " + s.camera.to_string() + ")";
        });
    m.def("make_demo_scene", &make_py_demo_scene, py::arg("aspect"),
          "Builds the demo for an image of the given aspect ratio (width / height).");
}

}  // namespace mipraster::bindings
