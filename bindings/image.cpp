// mipraster._image: image files through mipraster_io (OpenImageIO). A separate module so that
// `import mipraster` stays fast; the Python layer imports it the first time a file is read or written.
#include <stdexcept>
#include <string>
#include <utility>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "common.hpp"
#include "mipraster/io/image_io.hpp"

namespace mipraster::bindings {

namespace {

// A file error from image_io (std::runtime_error naming the path) becomes OSError with .filename.
[[noreturn]] void raise_os_error(const std::string& message, const std::string& path) {
    py::object error = py::reinterpret_borrow<py::object>(PyExc_OSError)(message);
    error.attr("filename") = path;
    PyErr_SetObject(PyExc_OSError, error.ptr());
    throw py::error_already_set();
}

py::array_t<float> read_image_py(const std::string& path) {
    Image image;
    std::string failure;
    {
        py::gil_scoped_release release;
        try {
            image = read_image(path);
        } catch (const std::runtime_error& e) {
            failure = e.what();
            if (failure.empty()) failure = "read_image: cannot read '" + path + "'";
        }
    }
    if (!failure.empty()) raise_os_error(failure, path);
    return image_to_array(std::move(image));
}

void write_image_py(const std::string& path, const CArray<float>& array) {
    const Image image = to_image(array, "image");
    std::string failure;
    {
        py::gil_scoped_release release;
        try {
            write_image(path, image);  // std::invalid_argument (bad extension / image) → ValueError
        } catch (const std::runtime_error& e) {
            failure = e.what();
            if (failure.empty()) failure = "write_image: cannot write '" + path + "'";
        }
    }
    if (!failure.empty()) raise_os_error(failure, path);
}

}  // namespace

}  // namespace mipraster::bindings

PYBIND11_MODULE(_image, m) {
    using namespace mipraster::bindings;
    m.doc() = "mipraster's image files (OpenImageIO): PNG (sRGB 8-bit) and EXR (linear float) output, any input.";
    m.def("read_image", &read_image_py, py::arg("path"),
          "Reads any file OpenImageIO reads into (H, W, 4) float32, linear premultiplied RGBA. 8-bit and\n"
          "16-bit files are decoded from sRGB with straight alpha; float files are read as they are.\n"
          "Raises OSError (with .filename) when the file is missing, unreadable or corrupt.");
    m.def("write_image", &write_image_py, py::arg("path"), py::arg("image"),
          "Writes (H, W, C) float32 (C = 1, 3 or 4; 4 = linear premultiplied RGBA) or (H, W): .png is sRGB\n"
          "8-bit with straight alpha (1 channel: plain grey), .exr is linear float as given. ValueError for\n"
          "another extension or a malformed image, OSError (with .filename) when the file cannot be written.");
}
