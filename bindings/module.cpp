// mipraster._core: the scene, render and image-comparison bindings. Links mipraster_core only (GLM and threads), so
// importing it loads no OpenImageIO; file I/O lives in mipraster._image.
#include <pybind11/pybind11.h>

#include "scene.hpp"

namespace mipraster::bindings {
void bind_compare(pybind11::module_& m);  // compare.cpp
void bind_error_probe(pybind11::module_& m);  // error_probe.cpp
void bind_memory(pybind11::module_& m);   // memory.cpp
void bind_texture(pybind11::module_& m);  // texture.cpp
void bind_stress(pybind11::module_& m);   // stress.cpp
void bind_resample(pybind11::module_& m);  // resample.cpp
void bind_synthesis(pybind11::module_& m);  // synthesis.cpp
}  // namespace mipraster::bindings

PYBIND11_MODULE(_core, m) {
    m.doc() = "mipraster's C++ core: meshes, cameras, draws, the renderer and image comparison (no file I/O; see mipraster._image).";
    mipraster::bindings::bind_memory(m);
    mipraster::bindings::bind_texture(m);
    mipraster::bindings::bind_scene(m);
    mipraster::bindings::bind_render(m);
    mipraster::bindings::bind_error_probe(m);
    mipraster::bindings::bind_compare(m);
    mipraster::bindings::bind_stress(m);
    mipraster::bindings::bind_resample(m);
    mipraster::bindings::bind_synthesis(m);
}
