// Image comparison bindings of mipraster._core: CompareSettings, CompareReport and compare_images
// (mipraster/core/compare.hpp). The Python layer (mipraster.compare) validates the arguments and
// reads files; this module compares two float arrays.
#include <cstring>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "common.hpp"
#include "mipraster/core/compare.hpp"

namespace mipraster::bindings {

namespace {

// An (H, W) or (H, W, C) float array (any C >= 1) → an Image (a copy).
Image to_compare_image(const CArray<float>& a, const char* name) {
    if (a.ndim() != 2 && a.ndim() != 3) {
        std::string got = "(";
        for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
        throw py::value_error(std::string(name) + ": expected shape (H, W) or (H, W, C), got " + got +
                              (a.ndim() == 1 ? ",)" : ")"));
    }
    Image image;
    image.height = static_cast<int>(a.shape(0));
    image.width = static_cast<int>(a.shape(1));
    image.channels = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
    if (static_cast<py::ssize_t>(image.height) != a.shape(0) || static_cast<py::ssize_t>(image.width) != a.shape(1) ||
        (a.ndim() == 3 && static_cast<py::ssize_t>(image.channels) != a.shape(2)))
        throw py::value_error(std::string(name) + ": image too large");
    image.pixels.resize(static_cast<std::size_t>(a.size()));
    if (a.size() > 0) std::memcpy(image.pixels.data(), a.data(), sizeof(float) * static_cast<std::size_t>(a.size()));
    return image;
}

CompareReport compare_py(const CArray<float>& actual, const CArray<float>& expected, const CompareSettings& settings) {
    const Image a = to_compare_image(actual, "actual");
    const Image b = to_compare_image(expected, "expected");
    py::gil_scoped_release release;
    return compare_images(a, b, settings);  // std::invalid_argument → ValueError
}

std::string report_repr(const CompareReport& r) {
    return "CompareReport(passed=" + std::string(r.passed ? "True" : "False") + ", " + std::to_string(r.width) + "x" +
           std::to_string(r.height) + "x" + std::to_string(r.channels) + ", failing_values=" +
           std::to_string(r.failing_values) + ", max_abs_error=" + py::repr(py::float_(r.max_abs_error)).cast<std::string>() +
           ")";
}

}  // namespace

void bind_compare(py::module_& m) {
    py::class_<CompareSettings>(
        m, "CompareSettings",
        "Thresholds of compare_images(): a value fails when |actual - expected| > fail_threshold; the\n"
        "comparison fails when more than fail_fraction of the values fail, or any differs by more than\n"
        "hard_fail_threshold (all strict).")
        .def(py::init([](double fail_threshold, double fail_fraction, double hard_fail_threshold) {
                 CompareSettings s;
                 s.fail_threshold = fail_threshold;
                 s.fail_fraction = fail_fraction;
                 s.hard_fail_threshold = hard_fail_threshold;
                 return s;
             }),
             py::arg("fail_threshold") = CompareSettings{}.fail_threshold,
             py::arg("fail_fraction") = CompareSettings{}.fail_fraction,
             py::arg("hard_fail_threshold") = CompareSettings{}.hard_fail_threshold)
        .def_readwrite("fail_threshold", &CompareSettings::fail_threshold,
                       "a value fails when it differs by more than this (default 1/255)")
        .def_readwrite("fail_fraction", &CompareSettings::fail_fraction,
                       "the comparison fails when more than this fraction of the values fail (default 0)")
        .def_readwrite("hard_fail_threshold", &CompareSettings::hard_fail_threshold,
                       "the comparison fails when any value differs by more than this (default 1; inf disables)")
        .def("validate", &CompareSettings::validate,
             "Raises ValueError naming the setting when a threshold is NaN or negative, or fail_fraction is\n"
             "outside [0, 1].")
        .def("__repr__", &CompareSettings::to_string);

    py::class_<CompareReport>(
        m, "CompareReport",
        "What an image comparison found (mipraster.compare). Errors are |actual - expected| per value\n"
        "(every channel of every pixel); equal values differ by 0, a NaN in either image differs by +inf\n"
        "and always fails. str(report) is a short human-readable report; use report.passed for the\n"
        "verdict (bool(report) raises TypeError so that `assert report` cannot pass by mistake).")
        .def_readonly("passed", &CompareReport::passed,
                      "the verdict: failing_fraction <= fail_fraction and no value beyond hard_fail_threshold")
        .def_readonly("width", &CompareReport::width, "image width in pixels")
        .def_readonly("height", &CompareReport::height, "image height in pixels")
        .def_readonly("channels", &CompareReport::channels, "channels per pixel")
        .def_readonly("values_compared", &CompareReport::values_compared, "width * height * channels")
        .def_readonly("max_abs_error", &CompareReport::max_abs_error, "largest |actual - expected| (inf with NaN)")
        .def_readonly("mean_abs_error", &CompareReport::mean_abs_error, "mean |actual - expected| over every value")
        .def_readonly("rmse", &CompareReport::rmse, "root mean square error")
        .def_readonly("psnr", &CompareReport::psnr, "peak signal-to-noise ratio in dB, peak 1.0; inf when identical")
        .def_readonly("failing_values", &CompareReport::failing_values,
                      "values that differ by more than fail_threshold (NaN included)")
        .def_readonly("failing_fraction", &CompareReport::failing_fraction, "failing_values / values_compared")
        .def_readonly("hard_failing_values", &CompareReport::hard_failing_values,
                      "values that differ by more than hard_fail_threshold (NaN included)")
        .def_readonly("nan_values", &CompareReport::nan_values, "values where either image holds a NaN")
        .def_readonly("worst_x", &CompareReport::worst_x, "column of the first largest error; -1 when nothing differs")
        .def_readonly("worst_y", &CompareReport::worst_y, "row (0 = top) of the first largest error; -1 when nothing differs")
        .def_readonly("worst_channel", &CompareReport::worst_channel,
                      "channel of the first largest error; -1 when nothing differs")
        .def_readonly("worst_actual", &CompareReport::worst_actual, "the actual value at the worst position")
        .def_readonly("worst_expected", &CompareReport::worst_expected, "the expected value at the worst position")
        .def_property_readonly(
            "settings", [](const CompareReport& r) { return r.settings; },
            "the thresholds the verdict used (a copy, CompareSettings)")
        .def("__str__", &CompareReport::to_string)
        .def("__repr__", &report_repr)
        .def("__bool__", [](const CompareReport&) -> bool {
            throw py::type_error("the truth value of a CompareReport is ambiguous: use report.passed");
        });

    m.def("compare_images", &compare_py, py::arg("actual"), py::arg("expected"), py::arg("settings") = CompareSettings{},
          "Compares two (H, W) or (H, W, C) float32 images value by value -> CompareReport (the GIL is\n"
          "released meanwhile). ValueError naming both sizes when they differ, or naming a bad setting.");
}

}  // namespace mipraster::bindings
