// mipraster._core: the scene and render bindings. Links mipraster_core only (GLM and threads), so
// importing it loads no OpenImageIO; file I/O lives in mipraster._image.
#include <pybind11/pybind11.h>

#include "scene.hpp"

PYBIND11_MODULE(_core, m) {
    m.doc() = "mipraster's C++ core: meshes, cameras, draws and the renderer (no file I/O; see mipraster._image).";
    mipraster::bindings::bind_scene(m);
    mipraster::bindings::bind_render(m);
}
