// mipraster._image: image files through mipraster_io (OpenImageIO). A separate module so that
// `import mipraster` stays fast; the Python layer imports it the first time a file is read or written.
// Scene files (OBJ, glTF) load here too: mipraster_io is the module that holds the file formats.
#include <stdexcept>
#include <string>
#include <utility>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "mipraster/core/memory_limit.hpp"
#include "mipraster/io/image_io.hpp"
#include "mipraster/io/scene_file.hpp"

namespace mipraster::bindings {

namespace {

// A file error from image_io (std::runtime_error naming the path) becomes OSError with .filename.
[[noreturn]] void raise_os_error(const std::string& message, const std::string& path) {
    // OSError(errno, strerror, filename): str() shows the message and the path (an OSError built
    // from the message alone and given .filename afterwards prints "[Errno None] None: ...").
    py::object error = py::reinterpret_borrow<py::object>(PyExc_OSError)(py::none(), message, path);
    PyErr_SetObject(PyExc_OSError, error.ptr());
    throw py::error_already_set();
}

py::array_t<float> read_image_py(const std::string& path, bool srgb) {
    Image image;
    std::string failure;
    {
        py::gil_scoped_release release;
        try {
            ImageReadOptions options;
            options.srgb = srgb;
            image = read_image(path, options);
        } catch (const std::runtime_error& e) {
            failure = e.what();
            if (failure.empty()) failure = "read_image: cannot read '" + path + "'";
        }
    }
    if (!failure.empty()) raise_os_error(failure, path);
    return image_to_array(std::move(image));
}

void write_image_py(const std::string& path, const CArray<float>& array, int bits) {
    const Image image = to_image(array, "image");
    ImageWriteOptions options;
    options.png_bits = bits;
    std::string failure;
    {
        py::gil_scoped_release release;
        try {
            write_image(path, image, options);  // std::invalid_argument (extension, image, bits) → ValueError
        } catch (const std::runtime_error& e) {
            failure = e.what();
            if (failure.empty()) failure = "write_image: cannot write '" + path + "'";
        }
    }
    if (!failure.empty()) raise_os_error(failure, path);
}

// load_scene as plain Python data (numpy arrays, dicts, NamedCamera objects): the Python layer
// turns it into mipraster.Mesh / Scene / Camera objects (those types live in _core).
py::dict load_scene_py(const std::string& path) {
    LoadedScene scene;
    std::string failure;
    {
        py::gil_scoped_release release;
        try {
            scene = load_scene(path);  // std::invalid_argument (extension, geometry) → ValueError
        } catch (const std::runtime_error& e) {
            failure = e.what();
            if (failure.empty()) failure = "load_scene: cannot read '" + path + "'";
        }
    }
    if (!failure.empty()) raise_os_error(failure, path);

    py::list meshes;
    for (const auto& mesh : scene.meshes) {
        std::vector<float> positions(mesh->positions.size() * 3), colors(mesh->colors.size() * 4),
            uvs(mesh->uvs.size() * 2), normals(mesh->normals.size() * 3);
        std::vector<std::uint32_t> triangles(mesh->triangles.size() * 3);
        for (std::size_t i = 0; i < mesh->positions.size(); ++i)
            for (int c = 0; c < 3; ++c) positions[3 * i + c] = mesh->positions[i][c];
        for (std::size_t i = 0; i < mesh->colors.size(); ++i)
            for (int c = 0; c < 4; ++c) colors[4 * i + c] = mesh->colors[i][c];
        for (std::size_t i = 0; i < mesh->uvs.size(); ++i)
            for (int c = 0; c < 2; ++c) uvs[2 * i + c] = mesh->uvs[i][c];
        for (std::size_t i = 0; i < mesh->normals.size(); ++i)
            for (int c = 0; c < 3; ++c) normals[3 * i + c] = mesh->normals[i][c];
        for (std::size_t i = 0; i < mesh->triangles.size(); ++i)
            for (int c = 0; c < 3; ++c) triangles[3 * i + c] = mesh->triangles[i][c];
        const auto n = static_cast<py::ssize_t>(mesh->positions.size());
        const auto t = static_cast<py::ssize_t>(mesh->triangles.size());
        py::object cols = py::none(), uv = py::none(), nrm = py::none();
        if (!mesh->colors.empty()) cols = vector_to_array(std::move(colors), {n, 4});
        if (!mesh->uvs.empty()) uv = vector_to_array(std::move(uvs), {n, 2});
        if (!mesh->normals.empty()) nrm = vector_to_array(std::move(normals), {n, 3});
        meshes.append(py::make_tuple(vector_to_array(std::move(positions), {n, 3}),
                                     vector_to_array(std::move(triangles), {t, 3}), cols, uv, nrm));
    }
    // Textures: level 0 of each distinct texture (draws sharing one share its index), as
    // (name, (H, W, 4) float32 linear premultiplied RGBA). The Python layer makes mipraster.Texture
    // objects of them (Texture lives in _core, which has its own texture cache).
    py::list textures;
    std::vector<const TextureLevel*> texture_keys;
    auto texture_index = [&](const Texture& texture) -> py::object {
        if (!texture) return py::none();
        const TextureLevel* key = &texture.base_level();
        for (std::size_t i = 0; i < texture_keys.size(); ++i)
            if (texture_keys[i] == key) return py::int_(i);
        std::vector<float> texels(key->texels.size() * 4);
        for (std::size_t i = 0; i < key->texels.size(); ++i)
            for (int c = 0; c < 4; ++c) texels[4 * i + c] = key->texels[i][c];
        textures.append(py::make_tuple(texture.name(), vector_to_array(std::move(texels), {key->height, key->width, 4})));
        texture_keys.push_back(key);
        return py::int_(texture_keys.size() - 1);
    };
    py::list draws;
    for (const Draw& d : scene.draws) {
        std::size_t index = 0;
        while (index < scene.meshes.size() && scene.meshes[index].get() != d.mesh) ++index;
        if (index == scene.meshes.size()) throw std::logic_error("load_scene: a draw's mesh is not among the scene's meshes");
        py::dict draw;
        draw["mesh"] = index;
        draw["model"] = from_dmat4(d.model);
        draw["color"] = from_vec4(d.color);
        draw["blend"] = to_string(d.state.blend);
        draw["cull"] = to_string(d.state.cull);
        draw["alpha_cutoff"] = d.state.alpha_cutoff ? py::object(py::float_(*d.state.alpha_cutoff)) : py::none();
        draw["texture"] = texture_index(d.texture);
        py::dict sampler;
        sampler["footprint"] = to_string(d.sampler.footprint);
        sampler["mag_filter"] = to_string(d.sampler.mag_filter);
        sampler["min_filter"] = to_string(d.sampler.min_filter);
        sampler["mip_filter"] = to_string(d.sampler.mip_filter);
        sampler["wrap"] = py::make_tuple(to_string(d.sampler.wrap_u), to_string(d.sampler.wrap_v));
        draw["sampler"] = sampler;
        draws.append(draw);
    }
    py::dict out;
    out["meshes"] = meshes;
    out["draws"] = draws;
    out["textures"] = textures;
    out["cameras"] = py::cast(scene.cameras);
    out["warnings"] = py::cast(scene.warnings);
    return out;
}

}  // namespace

}  // namespace mipraster::bindings

PYBIND11_MODULE(_image, m) {
    using namespace mipraster::bindings;
    m.doc() = "mipraster's image files (OpenImageIO): PNG (sRGB 8-bit) and EXR (linear float) output, any input.";
    m.def("read_image", &read_image_py, py::arg("path"), py::arg("srgb") = true,
          "Reads any file OpenImageIO reads into (H, W, 4) float32, linear premultiplied RGBA. 8-bit and\n"
          "16-bit files are decoded from sRGB (srgb=False: code / max code); float files are read as they are.\n"
          "Raises OSError (with .filename) when the file is missing, unreadable or corrupt.");
    m.def("write_image", &write_image_py, py::arg("path"), py::arg("image"), py::arg("bits") = 8,
          "Writes (H, W, C) float32 (C = 1, 3 or 4; 4 = linear premultiplied RGBA) or (H, W): .png is sRGB\n"
          "with straight alpha, 8 or 16 bits (1 channel: plain grey), .exr is linear float as given. ValueError\n"
          "for another extension, a malformed image or bits, OSError (with .filename) when the file cannot be\n"
          "written.");

    // This module links its own copy of the core, memory limit included: the Python layer hands
    // it the limit set through _core before each call.
    m.def("set_memory_limit", [](std::uint64_t bytes) { mipraster::set_memory_limit(bytes); }, py::arg("bytes"),
          "Sets this module's copy of the memory limit (mipraster.set_memory_limit sets both).");

    using mipraster::NamedCamera;
    py::class_<NamedCamera>(m, "NamedCamera",
                            "A camera from a scene file, kept as parameters (the projection needs the image aspect).")
        .def_readonly("name", &NamedCamera::name)
        .def_property_readonly("projection", [](const NamedCamera& c) { return to_string(c.projection); },
                               "'perspective' or 'orthographic'")
        .def_readonly("yfov", &NamedCamera::yfov, "perspective: vertical field of view, radians")
        .def_readonly("aspect_ratio", &NamedCamera::aspect_ratio, "perspective: the file's width/height, 0 = the image's")
        .def_readonly("xmag", &NamedCamera::xmag, "orthographic: half width")
        .def_readonly("ymag", &NamedCamera::ymag, "orthographic: half height")
        .def_readonly("znear", &NamedCamera::znear)
        .def_readonly("zfar", &NamedCamera::zfar, "inf for an infinite perspective")
        .def_property_readonly("view", [](const NamedCamera& c) { return from_dmat4(c.view); },
                               "4x4 world -> view matrix (a copy)")
        .def(
            "projection_matrix", [](const NamedCamera& c, double aspect) { return from_dmat4(c.build(aspect).projection); },
            py::arg("aspect"), "The reverse-Z projection for an image of the given aspect (width / height).")
        .def("__repr__", &NamedCamera::to_string);
    m.def("load_scene", &load_scene_py, py::arg("path"),
          "Loads a scene file (.obj, .gltf, .glb) into plain data: a dict with 'meshes' (list of\n"
          "(positions (N, 3) float32, triangles (T, 3) uint32, colors (N, 4) float32 or None, uvs (N, 2)\n"
          "float32 or None, normals (N, 3) float32 or None)), 'textures' (list of (name, (H, W, 4) float32\n"
          "linear premultiplied RGBA)), 'draws' (list of dicts: mesh index, model 4x4, color RGBA, blend\n"
          "and cull names, texture index or None, sampler dict: footprint, mag_filter, min_filter,\n"
          "mip_filter names and wrap (u, v) names), 'cameras' (list of NamedCamera) and 'warnings' (list\n"
          "of str: skipped features, missing textures drawn with the error texture). OSError (with .filename) for a\n"
          "missing, unreadable or corrupt file; ValueError for an unsupported extension or bad geometry.");
}
