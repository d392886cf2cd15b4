#pragma once
// Types shared between the scene and render bindings of mipraster._core.
#include <memory>
#include <vector>

#include <pybind11/pybind11.h>

#include "mipraster/pipeline/draw.hpp"
#include "mipraster/scene/mesh.hpp"

namespace mipraster::bindings {

/// A Draw as Python holds it: the C++ Draw points at its mesh with a raw pointer, so the binding
/// keeps the mesh alive with a shared_ptr next to it (a render copies these, so the meshes outlive
/// the render even if Python drops every reference while the GIL is released).
struct PyDraw {
    std::shared_ptr<Mesh> mesh;
    Draw draw;
};

/// The C++ draws of a sequence of mipraster._core.Draw (TypeError naming a wrong item); their
/// meshes are appended to `meshes`, which the caller keeps while the draws are in use.
std::vector<Draw> core_draws(const pybind11::sequence& draw_objects, std::vector<std::shared_ptr<Mesh>>& meshes);

void bind_scene(pybind11::module_& m);
void bind_render(pybind11::module_& m);

}  // namespace mipraster::bindings
