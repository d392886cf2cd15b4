#pragma once
// Helpers shared by the binding files: numpy arrays that own C++ vectors (no copy), conversions
// between numpy and GLM, and argument checks that raise ValueError naming the argument.
#include <array>
#include <cstddef>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "mipraster/core/image.hpp"

namespace mipraster::bindings {

namespace py = pybind11;

/// C-contiguous arrays of T; other dtypes and layouts are converted (copied) on the way in.
template <class T>
using CArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

/// Hands a vector's storage to numpy without copying: the vector moves to the heap and a capsule,
/// the array's base object, deletes it when the last array referring to it goes away.
template <class T, class Allocator>
py::array_t<T> vector_to_array(std::vector<T, Allocator>&& values, std::vector<py::ssize_t> shape) {
    using Vector = std::vector<T, Allocator>;
    auto owned = std::make_unique<Vector>(std::move(values));
    T* data = owned->data();
    py::capsule owner(owned.get(), [](void* p) { delete static_cast<Vector*>(p); });
    owned.release();  // the capsule owns it now
    return py::array_t<T>(std::move(shape), data, owner);
}

/// Raises ValueError unless `a` has exactly the given shape (−1 = any extent).
inline void require_shape(const py::array& a, std::initializer_list<py::ssize_t> shape, const char* name) {
    bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
    std::size_t i = 0;
    for (py::ssize_t extent : shape) {
        if (ok && extent >= 0 && a.shape(static_cast<py::ssize_t>(i)) != extent) ok = false;
        ++i;
    }
    if (ok) return;
    auto show = [](auto begin, auto end) {
        std::string s = "(";
        for (auto it = begin; it != end; ++it) {
            s += (it == begin ? "" : ", ") + (*it < 0 ? std::string("N") : std::to_string(*it));
        }
        return s + (std::distance(begin, end) == 1 ? ",)" : ")");
    };
    std::vector<py::ssize_t> got(a.shape(), a.shape() + a.ndim());
    throw py::value_error(std::string(name) + ": expected shape " + show(shape.begin(), shape.end()) + ", got " +
                          show(got.begin(), got.end()));
}

/// A (4, 4) array in the maths convention (m[row, col], column vectors) → GLM (m[col][row]).
inline glm::dmat4 to_dmat4(const CArray<double>& a, const char* name) {
    require_shape(a, {4, 4}, name);
    auto r = a.unchecked<2>();
    glm::dmat4 m(0.0);
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) m[col][row] = r(row, col);
    return m;
}

inline py::array_t<double> from_dmat4(const glm::dmat4& m) {
    py::array_t<double> a({4, 4});
    auto w = a.mutable_unchecked<2>();
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) w(row, col) = m[col][row];
    return a;
}

inline glm::dvec3 to_dvec3(const CArray<double>& a, const char* name) {
    require_shape(a, {3}, name);
    return {a.at(0), a.at(1), a.at(2)};
}

inline glm::vec4 to_vec4(const CArray<float>& a, const char* name) {
    require_shape(a, {4}, name);
    return {a.at(0), a.at(1), a.at(2), a.at(3)};
}

inline py::tuple from_vec4(const glm::vec4& v) { return py::make_tuple(v.r, v.g, v.b, v.a); }

/// An (H, W, C) or (H, W) float array (C = 1, 3 or 4) → an Image (a copy: Image owns a vector).
inline Image to_image(const CArray<float>& a, const char* name) {
    if (a.ndim() == 2 || (a.ndim() == 3 && (a.shape(2) == 1 || a.shape(2) == 3 || a.shape(2) == 4))) {
        Image image;
        image.height = static_cast<int>(a.shape(0));
        image.width = static_cast<int>(a.shape(1));
        image.channels = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
        if (static_cast<py::ssize_t>(image.height) != a.shape(0) || static_cast<py::ssize_t>(image.width) != a.shape(1))
            throw py::value_error(std::string(name) + ": image too large");
        image.pixels.resize(static_cast<std::size_t>(a.size()));
        if (a.size() > 0) std::memcpy(image.pixels.data(), a.data(), sizeof(float) * static_cast<std::size_t>(a.size()));
        return image;
    }
    std::string got = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
    throw py::value_error(std::string(name) + ": expected shape (H, W, C) with C = 1, 3 or 4, or (H, W); got " +
                          got + (a.ndim() == 1 ? ",)" : ")"));
}

/// An Image's pixels as an (H, W, C) numpy array that takes over the vector (no copy).
inline py::array_t<float> image_to_array(Image&& image) {
    const py::ssize_t h = image.height, w = image.width, c = image.channels;
    return vector_to_array(std::move(image.pixels), {h, w, c});
}

}  // namespace mipraster::bindings
