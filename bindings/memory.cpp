// The process-wide memory limit, the exception raised when work would exceed it, and the large
// render buffers kept between renders.
#include <pybind11/pybind11.h>

#include "mipraster/core/block_recycler.hpp"
#include "mipraster/core/memory_limit.hpp"

namespace py = pybind11;

namespace mipraster::bindings {

void bind_memory(py::module_& m) {
    // Both a ValueError (bad input, as before the limit was configurable) and a MemoryError.
    static PyObject* const error_type = [] {
        py::tuple bases = py::make_tuple(py::handle(PyExc_ValueError), py::handle(PyExc_MemoryError));
        return PyErr_NewExceptionWithDoc("mipraster._core.MemoryLimitError",
                                         "Work refused because its estimated memory exceeds memory_limit().",
                                         bases.ptr(), nullptr);
    }();
    m.attr("MemoryLimitError") = py::handle(error_type);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const MemoryLimitError& e) {
            PyErr_SetString(error_type, e.what());
        }
    });
    m.def("memory_limit", &memory_limit, "The process-wide memory limit in bytes.");
    m.def(
        "set_memory_limit",
        [](const py::int_& bytes) {  // (any Python int: one beyond 64 bits failed as "incompatible arguments")
            const std::string text = py::str(bytes);
            if (PyBool_Check(bytes.ptr())) throw py::type_error("memory limit: expected an integer, got bool " + text);
            const unsigned long long value = PyLong_AsUnsignedLongLong(bytes.ptr());
            if (PyErr_Occurred()) {  // (an OverflowError: negative, or past 64 bits)
                PyErr_Clear();
                if (PyObject_RichCompareBool(bytes.ptr(), py::int_(0).ptr(), Py_LT) == 1)
                    throw py::value_error("memory limit: expected bytes >= 0 (0 = the default), got " + text);
                throw py::value_error("memory limit: " + text + " bytes is beyond 2^64 - 1");
            }
            set_memory_limit(static_cast<std::uint64_t>(value));
        },
        py::arg("bytes"), "Sets the process-wide memory limit in bytes; 0 restores the default.");
    m.attr("DEFAULT_MEMORY_LIMIT") = kDefaultMemoryLimit;
    m.def("kept_buffer_bytes", &recycled_bytes,
          "Bytes of large render buffers (images, clip-space vertices, set-up triangles) kept after\n"
          "renders for the next buffer of the same size, so that a loop of renders does not fault them\n"
          "in again each frame (at most 512 MiB).");
    m.def("release_kept_buffers", &release_recycled_blocks, "Frees the buffers kept_buffer_bytes() counts.");
}

}  // namespace mipraster::bindings
