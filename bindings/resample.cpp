// Image resampling bindings of mipraster._core: resample() and the per-axis weights. The Python
// layer (mipraster.resample) checks the arguments and converts 8/16-bit images to linear float.
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "common.hpp"
#include "mipraster/core/reconstruction_filter.hpp"
#include "mipraster/core/resample.hpp"

namespace mipraster::bindings {

/// An (H, W) or (H, W, C) float array with C = 1…4 → an Image (a copy); ValueError naming `name`.
Image to_image_any_channels(const CArray<float>& a, const char* name) {
    if (!(a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) >= 1 && a.shape(2) <= 4)))
        throw py::value_error(std::string(name) + ": expected shape (H, W) or (H, W, C) with C = 1 to 4");
    if (a.shape(0) < 1 || a.shape(1) < 1 || a.shape(0) > (py::ssize_t{1} << 30) || a.shape(1) > (py::ssize_t{1} << 30))
        throw py::value_error(std::string(name) + ": expected at least 1x1 pixels (and fewer than 2^30 per side)");
    Image image;
    image.height = static_cast<int>(a.shape(0));
    image.width = static_cast<int>(a.shape(1));
    image.channels = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
    image.pixels.assign(a.data(), a.data() + a.size());
    return image;
}

namespace {

py::array_t<float> resample_py(const CArray<float>& image, int width, int height, const std::string& filter,
                               int threads) {
    const ReconstructionFilter f = parse_reconstruction_filter(filter);
    Image in = to_image_any_channels(image, "image");
    Image out;
    {
        py::gil_scoped_release release;
        out = resample(in, width, height, f, threads);
    }
    return image_to_array(std::move(out));
}

py::tuple resample_weights_py(int source_size, int target_size, const std::string& filter) {
    ResampleWeights w = resample_weights(source_size, target_size, parse_reconstruction_filter(filter));
    const py::ssize_t n = w.target_size, m = static_cast<py::ssize_t>(w.weights.size());
    return py::make_tuple(vector_to_array(std::move(w.first), {n}), vector_to_array(std::move(w.offset), {n + 1}),
                          vector_to_array(std::move(w.weights), {m}), w.scale);
}

}  // namespace

void bind_resample(py::module_& m) {
    m.attr("MAX_RESAMPLE_DIMENSION") = kMaxResampleDimension;
    m.attr("RECONSTRUCTION_FILTERS") = std::string(reconstruction_filter_names());
    m.def("resample", &resample_py, py::arg("image"), py::arg("width"), py::arg("height"), py::arg("filter"),
          py::arg("threads") = 0,
          "Resizes a linear float (H, W[, C]) image to (height, width, C) float32 with a reconstruction filter\n"
          "('box', 'tent', 'mitchell', 'catmull-rom', 'lanczos3'), widened when minifying; the GIL is released.");
    m.def("resample_weights", &resample_weights_py, py::arg("source_size"), py::arg("target_size"), py::arg("filter"),
          "One axis's weights: (first (N,) int32, offset (N+1,) int32, weights (M,) float32, scale). Target pixel i\n"
          "reads source pixels first[i] ... with weights[offset[i]:offset[i+1]].");
    m.def("filter_weight",
          [](const std::string& f, double x) { return filter_weight(parse_reconstruction_filter(f), x); },
          py::arg("filter"), py::arg("x"),
          "The 1-D kernel of a reconstruction filter at x (pixels).");
    m.def("filter_radius", [](const std::string& f) { return filter_radius(parse_reconstruction_filter(f)); },
          py::arg("filter"), "Half-width of a reconstruction filter's support in pixels.");
}

}  // namespace mipraster::bindings
