// Texture synthesis bindings of mipraster._core. The Python layer (mipraster.synthesis) checks the
// arguments, decodes 8/16-bit samples to linear float for the distances and gathers the output
// from the sample with the returned source map (so integer samples come back bit-exact).
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "common.hpp"
#include "mipraster/texture/synthesis.hpp"

namespace mipraster::bindings {

Image to_image_any_channels(const CArray<float>& a, const char* name);  // resample.cpp

namespace {

py::dict synthesize_py(const CArray<float>& sample, const SynthesisSettings& settings) {
    Image in = to_image_any_channels(sample, "sample");
    SynthesisResult r;
    {
        py::gil_scoped_release release;
        r = synthesize_texture(in, settings);
    }
    const py::ssize_t h = r.image.height, w = r.image.width;
    py::dict out;
    out["candidates"] = r.candidates;
    out["milliseconds"] = r.milliseconds;
    out["image"] = image_to_array(std::move(r.image));
    out["source"] = vector_to_array(std::move(r.source), {h, w});
    return out;
}

}  // namespace

void bind_synthesis(py::module_& m) {
    m.attr("MAX_SYNTHESIS_DIMENSION") = kMaxSynthesisDimension;
    py::class_<SynthesisSettings>(m, "SynthesisSettings", "Output size, window, seed and options of synthesize().")
        .def(py::init<>())
        .def_readwrite("width", &SynthesisSettings::width)
        .def_readwrite("height", &SynthesisSettings::height)
        .def_readwrite("window", &SynthesisSettings::window, "odd neighbourhood side, 1 <= window <= the sample's sides")
        .def_readwrite("seed", &SynthesisSettings::seed)
        .def_readwrite("epsilon", &SynthesisSettings::epsilon, "candidates within (1 + epsilon) of the best match")
        .def_readwrite("periodic_sample", &SynthesisSettings::periodic_sample,
                       "the sample tiles: its neighbourhoods wrap around its edges")
        .def_readwrite("tileable", &SynthesisSettings::tileable, "the output tiles: its neighbourhoods wrap around")
        .def_readwrite("threads", &SynthesisSettings::threads, "0 = all cores; the output does not depend on it")
        .def("__repr__", &SynthesisSettings::to_string);
    m.def("synthesize", &synthesize_py, py::arg("sample"), py::arg("settings"),
          "Efros-Leung texture synthesis from a linear float (H, W[, C]) sample (the GIL is released). Returns a\n"
          "dict: image (height, width, C) float32, source (height, width) int32 (the sample pixel y*W + x each\n"
          "output pixel copies), candidates (neighbourhoods compared per pixel) and milliseconds.");
}

}  // namespace mipraster::bindings
