// Texture bindings of mipraster._core: the sampler enums and Sampler, Texture (from uint8, uint16
// or float arrays), vectorized lookups and the process-wide texture cache. The Python layer
// (mipraster.texture) validates the arguments; this module copies the texels in and samples.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "mipraster/core/thread_pool.hpp"
#include "mipraster/texture/sample.hpp"
#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture.hpp"

namespace mipraster::bindings {

namespace {

// Lookups per parallel task; fewer lookups than two tasks' worth run on the calling thread.
constexpr std::size_t kLookupsPerTask = 8192;

struct TexelShape {
    int height, width, channels;
};

// An (H, W) or (H, W, C) array with C = 1..4 and a size the texture accepts; ValueError otherwise
// (checked before any size reaches an int).
TexelShape texel_shape(const py::array& a, const char* name) {
    if (a.ndim() != 2 && !(a.ndim() == 3 && a.shape(2) >= 1 && a.shape(2) <= 4)) {
        std::string got = "(";
        for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
        throw py::value_error(std::string(name) + ": expected shape (H, W) or (H, W, C) with C = 1, 2, 3 or 4, got " +
                              got + (a.ndim() == 1 ? ",)" : ")"));
    }
    for (int axis = 0; axis < 2; ++axis)
        if (a.shape(axis) < 1 || a.shape(axis) > kMaxTextureDimension)
            throw py::value_error(std::string(name) + ": " + (axis ? "width " : "height ") +
                                  std::to_string(a.shape(axis)) + " is out of range; expected 1 to " +
                                  std::to_string(kMaxTextureDimension));
    return {static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)),
            a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1};
}

// Builds a texture from a C-contiguous array with the GIL released (decoding and the finiteness
// check of a large texture take a while). The array stays alive: the caller holds it.
template <class T, class Make>
Texture make_texture(const CArray<T>& texels, Make make) {
    const TexelShape s = texel_shape(texels, "texels");
    const T* data = texels.data();
    py::gil_scoped_release release;
    return make(data, s);
}

// Copies level k (built if missing, with the texture pinned meanwhile) into (H_k, W_k, 4) float32.
py::array_t<float> level_py(const Texture& texture, int k) {
    if (k < 0 || k >= texture.level_count())
        throw py::value_error("k: level " + std::to_string(k) + " is out of range; expected 0 <= k < " +
                              std::to_string(texture.level_count()) + " (the level count)");
    std::vector<float> values;
    int width = 0, height = 0;
    {
        py::gil_scoped_release release;
        const TextureView view(texture);
        const TextureLevel& level = view.level(k);
        width = level.width;
        height = level.height;
        values.resize(level.texels.size() * 4);
        static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "glm::vec4 must be 4 packed floats");
        std::memcpy(values.data(), level.texels.data(), values.size() * sizeof(float));
    }
    return vector_to_array(std::move(values), {height, width, 4});
}

// An (N, 2) array, or (1, 2) for one value used for every lookup (stride 0).
struct PairRows {
    const float* data;
    std::size_t stride;  // floats between consecutive rows: 2, or 0 when broadcast
};

PairRows pair_rows(const CArray<float>& a, py::ssize_t n, const char* name) {
    if (a.ndim() != 2 || a.shape(1) != 2 || (a.shape(0) != n && a.shape(0) != 1)) {
        std::string got = "(";
        for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
        throw py::value_error(std::string(name) + ": expected shape (" + std::to_string(n) + ", 2) or (1, 2), got " +
                              got + (a.ndim() == 1 ? ",)" : ")"));
    }
    return {a.data(), a.shape(0) == 1 && n != 1 ? std::size_t{0} : std::size_t{2}};
}

// Runs body(i) for i in [0, n) on all hardware threads when n is large, else on this thread.
template <class Body>
void for_each_lookup(std::size_t n, Body body) {
    const std::size_t tasks = (n + kLookupsPerTask - 1) / kLookupsPerTask;
    if (tasks < 2) {
        for (std::size_t i = 0; i < n; ++i) body(i);
        return;
    }
    ThreadPool pool(static_cast<int>(std::min<std::size_t>(tasks, static_cast<std::size_t>(resolve_thread_count(0)))));
    pool.parallel_for(tasks, [&](std::size_t t) {
        const std::size_t end = std::min(n, (t + 1) * kLookupsPerTask);
        for (std::size_t i = t * kLookupsPerTask; i < end; ++i) body(i);
    });
}

// sample_texture over N points: uv (N, 2), derivatives (N, 2) or (1, 2); returns (N, 4) float32.
// One TextureView pins the texture for the whole call; the GIL is released meanwhile.
py::array_t<float> sample_py(const Texture& texture, const Sampler& sampler, const CArray<float>& uv,
                             const CArray<float>& duv_dx, const CArray<float>& duv_dy) {
    require_shape(uv, {-1, 2}, "uv");
    const py::ssize_t n = uv.shape(0);
    const PairRows dx = pair_rows(duv_dx, n, "duv_dx"), dy = pair_rows(duv_dy, n, "duv_dy");
    sampler.validate();  // std::invalid_argument → ValueError naming the field
    std::vector<float> out(static_cast<std::size_t>(n) * 4);
    {
        py::gil_scoped_release release;
        const TextureView view(texture);
        const float* p = uv.data();
        for_each_lookup(static_cast<std::size_t>(n), [&](std::size_t i) {
            const glm::vec2 d_x(dx.data[i * dx.stride], dx.data[i * dx.stride + 1]);
            const glm::vec2 d_y(dy.data[i * dy.stride], dy.data[i * dy.stride + 1]);
            const glm::vec4 c = sample_texture(view, sampler, glm::vec2(p[2 * i], p[2 * i + 1]), d_x, d_y);
            std::memcpy(&out[4 * i], &c, sizeof(c));
        });
    }
    return vector_to_array(std::move(out), {n, 4});
}

// texture_lod over N derivative pairs (each (N, 2) or (1, 2)); returns (N,) float64.
py::array_t<double> lod_py(const Texture& texture, const Sampler& sampler, const CArray<float>& duv_dx,
                           const CArray<float>& duv_dy) {
    if (duv_dx.ndim() != 2 || duv_dy.ndim() != 2)
        throw py::value_error("duv_dx, duv_dy: expected shape (N, 2) or (1, 2)");
    const py::ssize_t n = std::max(duv_dx.shape(0), duv_dy.shape(0));
    const PairRows dx = pair_rows(duv_dx, n, "duv_dx"), dy = pair_rows(duv_dy, n, "duv_dy");
    sampler.validate();
    std::vector<double> out(static_cast<std::size_t>(n));
    {
        py::gil_scoped_release release;
        const TextureView view(texture);
        for (std::size_t i = 0; i < out.size(); ++i)
            out[i] = texture_lod(view, sampler, glm::vec2(dx.data[i * dx.stride], dx.data[i * dx.stride + 1]),
                                 glm::vec2(dy.data[i * dy.stride], dy.data[i * dy.stride + 1]));
    }
    return vector_to_array(std::move(out), {n});
}

py::dict cache_stats_dict() {
    const TextureCacheStats s = TextureCache::global().stats();
    py::dict d;
    d["budget_bytes"] = s.budget_bytes;
    d["derived_bytes"] = s.derived_bytes;
    d["levels_built"] = s.levels_built;
    d["tables_built"] = s.tables_built;
    d["evictions"] = s.evictions;
    d["keyed_textures"] = s.keyed_textures;
    return d;
}

}  // namespace

void bind_texture(py::module_& m) {
    // --- limits -------------------------------------------------------------------------------------
    m.attr("MAX_TEXTURE_DIMENSION") = kMaxTextureDimension;
    m.attr("MAX_TEXTURE_BYTES") = kMaxTextureBytes;

    // --- sampler ------------------------------------------------------------------------------------
    py::enum_<WrapMode>(m, "WrapMode", "What lies outside [0, 1) along one axis.")
        .value("repeat", WrapMode::repeat, "the texture tiles")
        .value("clamp", WrapMode::clamp, "the edge texel extends (clamp-to-edge)")
        .value("mirror", WrapMode::mirror, "the texture tiles, every other copy mirrored")
        .value("border", WrapMode::border, "the sampler's border colour");
    py::enum_<TexelFilter>(m, "TexelFilter", "Reconstruction within one level.")
        .value("nearest", TexelFilter::nearest, "the texel whose cell holds the point, i = floor(u w)")
        .value("linear", TexelFilter::linear, "bilinear between the four nearest texel centres, i = floor(u w - 1/2)");
    py::enum_<MipFilter>(m, "MipFilter", "Between mip levels.")
        .value("none", MipFilter::none, "level 0 only")
        .value("nearest", MipFilter::nearest, "the nearest level")
        .value("linear", MipFilter::linear, "linear between the two nearest levels");
    py::enum_<FootprintFilter>(m, "FootprintFilter", "How the pixel's footprint is integrated when minifying.")
        .value("isotropic", FootprintFilter::isotropic, "one lookup at the level of the longer derivative")
        .value("anisotropic", FootprintFilter::anisotropic, "up to max_anisotropy probes along the major axis")
        .value("ewa", FootprintFilter::ewa, "elliptical weighted average (Gaussian over the footprint ellipse)")
        .value("sat", FootprintFilter::sat, "summed-area table: the mean over the footprint's bounding box");

    py::class_<Sampler>(m, "Sampler",
                        "How a texture is read: texel, mip and footprint filters, wrap per axis, border colour\n"
                        "(premultiplied linear RGBA) and LOD controls. Defaults: trilinear, repeat.")
        .def(py::init<>())
        .def_static("from_filter_name", &Sampler::from_filter_name, py::arg("name"),
                    "'nearest', 'bilinear', 'trilinear', 'anisotropic', 'ewa' or 'sat' -> Sampler (ValueError otherwise).")
        .def_readwrite("mag_filter", &Sampler::mag_filter, "texel filter when lambda <= 0 (magnification)")
        .def_readwrite("min_filter", &Sampler::min_filter, "texel filter when lambda > 0, within the chosen level(s)")
        .def_readwrite("mip_filter", &Sampler::mip_filter)
        .def_readwrite("footprint", &Sampler::footprint)
        .def_readwrite("max_anisotropy", &Sampler::max_anisotropy,
                       "anisotropic: most probes per lookup; ewa: largest axis ratio. At least 1.")
        .def_readwrite("wrap_u", &Sampler::wrap_u)
        .def_readwrite("wrap_v", &Sampler::wrap_v)
        .def_property(
            "border_color", [](const Sampler& s) { return from_vec4(s.border_color); },
            [](Sampler& s, const CArray<float>& c) { s.border_color = to_vec4(c, "border_color"); },
            "premultiplied linear RGBA; also returned for a non-finite uv")
        .def_readwrite("lod_bias", &Sampler::lod_bias, "added to lambda before clamping")
        .def_readwrite("min_lod", &Sampler::min_lod)
        .def_readwrite("max_lod", &Sampler::max_lod)
        .def("needs_derivatives", &Sampler::needs_derivatives,
             "True when a lookup depends on the uv derivatives (some filter varies with lambda).")
        .def("uses_mip_levels", &Sampler::uses_mip_levels, "True when a lookup may read levels other than 0.")
        .def("validate", &Sampler::validate,
             "Raises ValueError naming the bad field (non-finite value, max_anisotropy < 1, min_lod > max_lod).")
        .def("__repr__", &Sampler::to_string);

    // --- textures -----------------------------------------------------------------------------------
    py::class_<Texture>(
        m, "Texture",
        "A shared, immutable texture: level 0 holds linear premultiplied RGBA float texels; mip levels and\n"
        "the summed-area table are built the first time a lookup needs them (texture cache). Made by\n"
        "from_uint8, from_uint16 or from_float from C-contiguous (H, W) or (H, W, C) arrays, C = 1 (grey),\n"
        "2 (grey, alpha), 3 (RGB) or 4 (RGBA); the texels are copied.")
        .def_static(
            "from_uint8",
            [](const CArray<std::uint8_t>& texels, bool srgb, std::string name) {
                return make_texture(texels, [&](const std::uint8_t* p, TexelShape s) {
                    return Texture::from_8bit(p, s.width, s.height, s.channels, srgb, std::move(name));
                });
            },
            py::arg("texels"), py::arg("srgb") = true, py::arg("name") = "texture",
            "8-bit texels: colour decoded from sRGB when srgb (else code/255), alpha code/255 (straight),\n"
            "then premultiplied.")
        .def_static(
            "from_uint16",
            [](const CArray<std::uint16_t>& texels, bool srgb, std::string name) {
                return make_texture(texels, [&](const std::uint16_t* p, TexelShape s) {
                    return Texture::from_16bit(p, s.width, s.height, s.channels, srgb, std::move(name));
                });
            },
            py::arg("texels"), py::arg("srgb") = true, py::arg("name") = "texture",
            "16-bit texels: colour decoded from sRGB when srgb (else code/65535), alpha code/65535\n"
            "(straight), then premultiplied.")
        .def_static(
            "from_float",
            [](const CArray<float>& texels, bool premultiplied, std::string name) {
                return make_texture(texels, [&](const float* p, TexelShape s) {
                    return Texture::from_float(p, s.width, s.height, s.channels, premultiplied, std::move(name));
                });
            },
            py::arg("texels"), py::arg("premultiplied") = false, py::arg("name") = "texture",
            "Linear float texels; colour is multiplied by alpha unless premultiplied. ValueError naming a\n"
            "non-finite texel.")
        .def_property_readonly("width", &Texture::width)
        .def_property_readonly("height", &Texture::height)
        .def_property_readonly("level_count", &Texture::level_count, "levels down to 1x1, level 0 included")
        .def_property_readonly("name", &Texture::name)
        .def_property_readonly("built_levels", &Texture::built_levels, "levels beyond 0 built now")
        .def_property_readonly("has_summed_area_table", &Texture::has_summed_area_table)
        .def_property_readonly("derived_bytes", &Texture::derived_bytes,
                               "bytes held now by the built levels and the summed-area table")
        .def_property_readonly(
            "identity", [](const Texture& t) { return reinterpret_cast<std::uintptr_t>(&t.base_level()); },
            "an integer shared by every copy of one texture (copies refer to the same texels)")
        .def("level", &level_py, py::arg("k"),
             "Level k as a new (H_k, W_k, 4) float32 array (linear premultiplied RGBA), built if missing.")
        .def("__repr__", &Texture::to_string);

    m.def("sample_texture", &sample_py, py::arg("texture"), py::arg("sampler"), py::arg("uv"), py::arg("duv_dx"),
          py::arg("duv_dy"),
          "Filtered lookups: uv (N, 2) float32, duv_dx and duv_dy (N, 2) or (1, 2) (one pair for every\n"
          "point) -> (N, 4) float32, linear premultiplied RGBA. A non-finite uv gives the border colour.\n"
          "The GIL is released; large N runs on all hardware threads.");
    m.def("texture_lod", &lod_py, py::arg("texture"), py::arg("sampler"), py::arg("duv_dx"), py::arg("duv_dy"),
          "The level of detail lambda of lookups with these derivatives ((N, 2) or (1, 2) each) -> (N,)\n"
          "float64, clamped to [min_lod, max_lod] and [0, level_count - 1]; <= 0 means magnification.");

    // --- the texture cache --------------------------------------------------------------------------
    m.def("texture_cache_stats", &cache_stats_dict,
          "The process-wide texture cache: a dict with budget_bytes, derived_bytes (mip levels >= 1 and\n"
          "summed-area tables held now), levels_built, tables_built, evictions (since start) and\n"
          "keyed_textures.");
    m.def(
        "set_texture_cache_budget", [](std::size_t budget_bytes) { TextureCache::global().set_budget(budget_bytes); },
        py::arg("budget_bytes"),
        "Bounds the derived data of unpinned textures; least recently used textures' levels are dropped\n"
        "(and rebuilt identically when needed again).");
    m.def(
        "clear_texture_cache", [] { TextureCache::global().clear(); },
        "Drops the derived data of every texture not in use and forgets the keyed textures.");
}

}  // namespace mipraster::bindings
