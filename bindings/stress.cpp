// The stress suite (issue 6): StressRow and the suite runner, with the GIL released while it runs.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "mipraster/stress/stress_cases.hpp"

namespace py = pybind11;

namespace mipraster::bindings {

void bind_stress(py::module_& m) {
    py::class_<StressRow>(m, "StressRow", "One row of the stress report: case, what was tried, figure, bound, pass.")
        .def_readonly("number", &StressRow::number, "The issue's case number, 1..12.")
        .def_readonly("name", &StressRow::name, "Short name of the case, e.g. 'watertight'.")
        .def_readonly("tried", &StressRow::tried, "What was rendered or looked up.")
        .def_readonly("figure", &StressRow::figure, "The measured figure(s).")
        .def_readonly("bound", &StressRow::bound, "What the figure must meet.")
        .def_readonly("passed", &StressRow::pass, "Whether the figure meets the bound.")
        .def_readonly("details", &StressRow::details, "Per-setting measurements behind the figure.")
        .def("to_json", &StressRow::to_json, "The row as a JSON object.")
        .def("__repr__", &StressRow::to_string);
    m.def(
        "run_stress_suite",
        [](const std::string& size) {
            const StressSize s = parse_stress_size(size);
            py::gil_scoped_release release;
            return run_stress_suite(s);
        },
        py::arg("size") = "fast", "Runs every stress case ('fast' or 'full' sizes) -> list of StressRow.");
    m.def("format_stress_report", &format_stress_report, py::arg("rows"), py::arg("with_details") = false,
          "The rows as plain text, one block per row.");
    m.def("stress_rows_to_json", &stress_rows_to_json, py::arg("rows"), "The rows as a JSON array.");
}

}  // namespace mipraster::bindings
