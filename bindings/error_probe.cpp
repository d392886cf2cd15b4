// Error probe bindings of mipraster._core: the sparse reference that measures a render's error
// (mipraster/pipeline/error_probe.hpp), the same code the CLI's --stats and --error-map run.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "mipraster/pipeline/error_probe.hpp"
#include "scene.hpp"

namespace mipraster::bindings {

namespace {

// An optional (H, W) map as a one-channel Image.
std::optional<Image> optional_map(const std::optional<CArray<float>>& a, const char* name) {
    if (!a) return std::nullopt;
    if (a->ndim() != 2) throw py::value_error(std::string(name) + ": expected an (H, W) map");
    return to_image(*a, name);
}

ErrorProbe measure_error_py(const py::sequence& draw_objects, const Camera& camera, const RenderSettings& settings,
                            const CArray<float>& color, const std::optional<CArray<float>>& halves_map, int pixels,
                            std::uint64_t seed, const std::optional<CArray<float>>& guide, ProbeReference* reuse) {
    std::vector<std::shared_ptr<Mesh>> meshes;
    const std::vector<Draw> draws = core_draws(draw_objects, meshes);
    const Image c = to_image(color, "color");
    const std::optional<Image> h = optional_map(halves_map, "halves_map"), g = optional_map(guide, "guide");
    py::gil_scoped_release release;
    return measure_error(draws, camera, settings, c, h ? &*h : nullptr, pixels, seed, g ? &*g : nullptr, reuse);
}

py::array_t<float> error_guide_py(const CArray<float>& color, const std::optional<CArray<float>>& halves_map) {
    const Image c = to_image(color, "color");
    const std::optional<Image> h = optional_map(halves_map, "halves_map");
    Image g;
    {
        py::gil_scoped_release release;
        g = error_guide(c, h ? &*h : nullptr);
    }
    const py::ssize_t rows = g.height, cols = g.width;
    return vector_to_array(std::move(g.pixels), {rows, cols});
}

}  // namespace

void bind_error_probe(py::module_& m) {
    m.attr("PROBE_REFERENCE_SPP") = kProbeReferenceSpp;
    m.attr("PROBE_MAX_PASSES") = kProbeMaxPasses;
    py::class_<ErrorProbe>(m, "ErrorProbe", "What the sparse reference measured (see mipraster.error_probe).")
        .def_readonly("rmse", &ErrorProbe::rmse,
                      "estimated RMSE of the image (linear R, G, B); an upper bound when upper_bound")
        .def_readonly("stderr", &ErrorProbe::standard_error, "the standard error of rmse")
        .def_readonly("upper_bound", &ErrorProbe::upper_bound,
                      "True when the error was too small to resolve: the image's RMSE is at most rmse")
        .def_readonly("pixels", &ErrorProbe::pixels, "draws n (a pixel drawn twice counts twice)")
        .def_readonly("distinct_pixels", &ErrorProbe::distinct_pixels, "pixels rendered again")
        .def_readonly("reference_spp", &ErrorProbe::reference_spp, "samples per pixel of the reference (all passes)")
        .def_readonly("reference_rmse", &ErrorProbe::reference_rmse, "the reference's own estimated RMSE")
        .def_readonly("rendered_passes", &ErrorProbe::rendered_passes,
                      "reference passes this probe rendered (0: all reused from a ProbeReference)")
        .def_property_readonly(
            "halves_rmse",
            [](const ErrorProbe& p) -> py::object {
                if (p.halves_rmse < 0) return py::none();
                return py::float_(p.halves_rmse);
            },
            "RMS of the halves map, or None without one")
        .def_readonly("ms", &ErrorProbe::ms, "wall time of the probe in milliseconds")
        .def("__repr__", &ErrorProbe::to_string);
    py::class_<ProbeReference>(m, "ProbeReference",
                               "A probe's draws and their reference passes, kept for later probes of the same scene "
                               "(see mipraster.error_probe).")
        .def(py::init<>())
        .def_property_readonly("draws", [](const ProbeReference& r) { return r.chosen.size(); }, "draws n")
        .def_property_readonly("distinct_pixels", [](const ProbeReference& r) { return r.distinct.size(); },
                               "pixels drawn")
        .def_readonly("passes", &ProbeReference::passes, "reference passes of 64 samples rendered so far")
        .def_property_readonly("empty", &ProbeReference::empty, "True until a probe has filled it")
        .def("__repr__", &ProbeReference::to_string);
    m.def("measure_error", &measure_error_py, py::arg("draws"), py::arg("camera"), py::arg("settings"), py::arg("color"),
          py::arg("halves_map"), py::arg("pixels"), py::arg("seed") = 0, py::arg("guide") = py::none(),
          py::arg("reuse") = static_cast<ProbeReference*>(nullptr),
          "Estimates the RMSE of color (H, W, 4), the render of draws / camera / settings, from `pixels` "
          "pixels rendered again at reference quality; `reuse` (a ProbeReference) keeps or supplies the draws "
          "and their reference passes. The GIL is released.");
    m.def("error_guide", &error_guide_py, py::arg("color"), py::arg("halves_map") = py::none(),
          "(H, W) float32: where error is likely (the probe's guide).");
    m.def("probe_reference_passes", &probe_reference_passes, py::arg("spp"),
          "Reference passes of 64 samples a probe of a render with spp samples per pixel starts with.");
    m.def("default_probe_pixels", &default_probe_pixels, py::arg("width"), py::arg("height"), py::arg("spp"),
          "Pixels a probe renders by default.");
}

}  // namespace mipraster::bindings
