// Render bindings of mipraster._core: settings, sample patterns, the renderer, and the sRGB
// encoding of its output (colour.hpp is part of the core library).
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common.hpp"
#include "mipraster/core/colour.hpp"
#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/framebuffer.hpp"
#include "mipraster/pipeline/renderer.hpp"
#include "mipraster/pipeline/sample_pattern.hpp"
#include "scene.hpp"

namespace mipraster::bindings {

std::vector<Draw> core_draws(const py::sequence& draw_objects, std::vector<std::shared_ptr<Mesh>>& meshes) {
    std::vector<Draw> draws;
    meshes.reserve(meshes.size() + py::len(draw_objects));
    draws.reserve(py::len(draw_objects));
    std::size_t i = 0;
    for (py::handle item : draw_objects) {
        if (!py::isinstance<PyDraw>(item))
            throw py::type_error("draws[" + std::to_string(i) + "]: expected mipraster._core.Draw, got " +
                                 std::string(py::str(py::type::of(item).attr("__name__"))));
        const PyDraw& d = item.cast<const PyDraw&>();
        meshes.push_back(d.mesh);
        draws.push_back(d.draw);
        ++i;
    }
    return draws;
}

namespace {

// Sample offsets from the pixel's top-left corner in pixels, (S, 2) float64 (exact: k/256).
py::array_t<double> pattern_offsets(const SamplePattern& p) {
    py::array_t<double> a({static_cast<py::ssize_t>(p.count()), py::ssize_t{2}});
    auto w = a.mutable_unchecked<2>();
    for (int s = 0; s < p.count(); ++s) {
        w(s, 0) = p.x[static_cast<std::size_t>(s)] / double(kSubpixelOne);
        w(s, 1) = p.y[static_cast<std::size_t>(s)] / double(kSubpixelOne);
    }
    return a;
}

py::dict stats_dict(const RenderStats& s) {
    py::dict d;
    d["triangles_in"] = s.triangles_in;
    d["triangles_clipped"] = s.triangles_clipped;
    d["triangles_outside"] = s.triangles_outside;
    d["triangles_between_samples"] = s.triangles_between_samples;
    d["triangles_backface"] = s.triangles_backface;
    d["triangles_degenerate"] = s.triangles_degenerate;
    d["triangles_nonfinite"] = s.triangles_nonfinite;
    d["triangles_rasterized"] = s.triangles_rasterized;
    d["samples_covered"] = s.samples_covered;
    d["samples_passed"] = s.samples_passed;
    d["shader_invocations"] = s.shader_invocations;
    d["depth_blocks_rejected"] = s.depth_blocks_rejected;
    d["tiles_deferred"] = s.tiles_deferred;
    d["tiles_empty"] = s.tiles_empty;
    d["threads"] = s.threads;
    d["transform_ms"] = s.transform_ms;
    d["setup_ms"] = s.setup_ms;
    d["raster_ms"] = s.raster_ms;
    d["total_ms"] = s.total_ms;
    return d;
}

// Renders with the GIL released. The draws are copied first, each with a shared_ptr to its mesh,
// so nothing Python does meanwhile can free a mesh the renderer reads.
py::dict render_py(const py::sequence& draw_objects, const Camera& camera, const RenderSettings& settings) {
    std::vector<std::shared_ptr<Mesh>> meshes;
    const std::vector<Draw> draws = core_draws(draw_objects, meshes);

    RenderResult result;
    {
        py::gil_scoped_release release;
        result = render(draws, camera, settings);
    }

    // Hand the C++ buffers to numpy without copying them.
    const py::ssize_t h = result.color.height, w = result.color.width;
    py::dict out;
    out["color"] = image_to_array(std::move(result.color));
    out["samples"] = py::none();
    out["sample_depth"] = py::none();
    Framebuffer& fb = result.framebuffer;
    if (settings.keep_samples && !fb.color.empty()) {
        const py::ssize_t s = fb.samples;
        out["samples"] = vector_to_array(std::move(fb.color), {h, w, s, 4});
        if (fb.has_depth()) out["sample_depth"] = vector_to_array(std::move(fb.depth), {h, w, s});
    }
    out["depth"] = py::none();
    if (!result.depth.pixels.empty()) out["depth"] = vector_to_array(std::move(result.depth.pixels), {h, w});
    out["error_map"] = py::none();
    out["error_estimate"] = py::none();
    if (settings.estimate_error) {
        out["error_map"] = vector_to_array(std::move(result.error_map.pixels), {h, w});
        out["error_estimate"] = result.error_estimate.rmse;
    }
    out["pattern"] = pattern_offsets(result.pattern);
    out["pattern_kind"] = to_string(result.pattern.kind);
    out["stats"] = stats_dict(result.stats);
    return out;
}

// The primitive layer, with the GIL released. Positions and indices are copied into the C++
// types (double clip coordinates, uint32 indices); the outputs are handed over without a copy.
py::dict rasterize_py(const CArray<double>& pos_clip, const CArray<std::uint32_t>& triangles,
                      const RasterizeSettings& settings) {
    require_shape(pos_clip, {-1, 4}, "pos_clip");
    require_shape(triangles, {-1, 3}, "triangles");
    std::vector<glm::dvec4> positions(static_cast<std::size_t>(pos_clip.shape(0)));
    std::memcpy(positions.data(), pos_clip.data(), positions.size() * sizeof(glm::dvec4));
    std::vector<glm::uvec3> tris(static_cast<std::size_t>(triangles.shape(0)));
    std::memcpy(tris.data(), triangles.data(), tris.size() * sizeof(glm::uvec3));
    Visibility v;
    {
        py::gil_scoped_release release;
        v = rasterize(positions, tris, settings);
    }
    const py::ssize_t h = v.height, w = v.width, s = v.samples;
    py::dict out;
    out["triangle_id"] = vector_to_array(std::move(v.triangle_id), {h, w, s});
    out["barycentrics"] = vector_to_array(std::move(v.barycentrics), {h, w, s, 2});
    out["depth"] = vector_to_array(std::move(v.depth), {h, w, s});
    out["pattern"] = pattern_offsets(v.pattern);
    out["pattern_kind"] = to_string(v.pattern.kind);
    out["stats"] = stats_dict(v.stats);
    return out;
}

py::array_t<std::uint8_t> to_srgb8_py(const CArray<float>& image) {
    Image img = to_image(image, "image");
    std::vector<std::uint8_t> bytes;
    {
        py::gil_scoped_release release;
        bytes = to_srgb8(img);
    }
    return vector_to_array(std::move(bytes), {img.height, img.width, 4});
}

}  // namespace

void bind_render(py::module_& m) {
    // --- limits -----------------------------------------------------------------------------------
    m.attr("MAX_DIMENSION") = kMaxDimension;
    m.attr("MAX_SAMPLES") = kMaxSamples;
    m.attr("MAX_THREADS") = kMaxThreads;
    m.attr("SUBPIXEL_ONE") = kSubpixelOne;
    m.attr("TILE_SIZE") = kTileSize;

    // --- settings -----------------------------------------------------------------------------------
    py::enum_<AntiAliasing>(m, "AntiAliasing", "SSAA shades every sample; MSAA once per pixel per triangle.")
        .value("ssaa", AntiAliasing::ssaa)
        .value("msaa", AntiAliasing::msaa);
    py::enum_<PatternKind>(m, "PatternKind", "Sample patterns ('automatic' is called 'auto' in names).")
        .value("automatic", PatternKind::automatic, "center for 1 sample, rotated for 4, grid otherwise")
        .value("center", PatternKind::center)
        .value("grid", PatternKind::grid)
        .value("rotated", PatternKind::rotated)
        .value("stratified", PatternKind::stratified);
    m.def("parse_pattern_kind", &parse_pattern_kind, py::arg("name"),
          "'auto', 'center', 'grid', 'rotated' or 'stratified' -> PatternKind (ValueError otherwise).");
    m.def("parse_anti_aliasing", &parse_anti_aliasing, py::arg("name"), "'ssaa' or 'msaa' -> AntiAliasing.");

    py::class_<RenderSettings>(m, "RenderSettings", "Image size, sampling, threads and clear colour of a render.")
        .def(py::init<>())
        .def_readwrite("width", &RenderSettings::width)
        .def_readwrite("height", &RenderSettings::height)
        .def_readwrite("samples", &RenderSettings::samples, "samples per pixel, 1..64")
        .def_readwrite("pattern", &RenderSettings::pattern)
        .def_readwrite("pattern_seed", &RenderSettings::pattern_seed, "seed of the stratified pattern")
        .def_readwrite("anti_aliasing", &RenderSettings::anti_aliasing)
        .def_readwrite("threads", &RenderSettings::threads, "0 = all hardware threads")
        .def_property(
            "clear_color", [](const RenderSettings& s) { return from_vec4(s.clear_color); },
            [](RenderSettings& s, const CArray<float>& c) { s.clear_color = to_vec4(c, "clear_color"); },
            "premultiplied linear RGBA")
        .def_readwrite("keep_samples", &RenderSettings::keep_samples, "return the supersample framebuffer too")
        .def_property(
            "resolve_filter", [](const RenderSettings& s) { return to_string(s.resolve_filter); },
            [](RenderSettings& s, const std::string& name) { s.resolve_filter = parse_resolve_filter(name); },
            "reconstruction filter of the resolve: 'box', 'tent', 'mitchell', 'catmull-rom' or 'lanczos3'")
        .def_readwrite("deferred_shading", &RenderSettings::deferred_shading,
                       "where a tile's triangles overlap deeply and all replace without an alpha test, shade only "
                       "visible samples")
        .def_readwrite("batched_lookups", &RenderSettings::batched_lookups,
                       "look textures up sixteen samples at a time in float (within batch_sampling_tolerance of "
                       "the double-precision reference); False: the reference for every sample")
        .def_readwrite("depth_output", &RenderSettings::depth_output,
                       "return each pixel's view-space depth (nearest sample, +inf where empty)")
        .def_property(
            "derivatives", [](const RenderSettings& s) { return to_string(s.derivatives); },
            [](RenderSettings& s, const std::string& name) { s.derivatives = parse_derivative_mode(name); },
            "uv derivatives of textured draws: 'analytic' or 'quad'")
        .def_property(
            "debug_view", [](const RenderSettings& s) { return to_string(s.debug_view); },
            [](RenderSettings& s, const std::string& name) { s.debug_view = parse_debug_view(name); },
            "'none', 'mip-level' or 'uv': replaces the texture lookup of textured draws")
        .def_readwrite("estimate_error", &RenderSettings::estimate_error,
                       "estimate the error from two interleaved halves of the samples (needs samples >= 2)")
        .def_readwrite("tile_mask", &RenderSettings::tile_mask,
                       "[] = every tile; else one flag per TILE_SIZE^2 tile, row-major: only flagged tiles render")
        .def_readwrite("pixels", &RenderSettings::pixels,
                       "[] = every pixel; else the indices y * width + x of the only pixels to render (one setup; "
                       "the others keep the clear colour)")
        .def("__repr__", &RenderSettings::to_string);

    py::class_<RasterizeSettings>(m, "RasterizeSettings", "Image size, sampling, depth convention and culling of rasterize().")
        .def(py::init<>())
        .def_readwrite("width", &RasterizeSettings::width)
        .def_readwrite("height", &RasterizeSettings::height)
        .def_readwrite("samples", &RasterizeSettings::samples, "samples per pixel, 1..64")
        .def_readwrite("pattern", &RasterizeSettings::pattern)
        .def_readwrite("pattern_seed", &RasterizeSettings::pattern_seed, "seed of the stratified pattern")
        .def_readwrite("threads", &RasterizeSettings::threads, "0 = all hardware threads")
        .def_readwrite("depth_convention", &RasterizeSettings::depth_convention,
                       "opengl: -w <= z <= w, nearer is smaller; reverse_z: 0 <= z <= w, nearer is larger")
        .def_readwrite("cull", &RasterizeSettings::cull)
        .def("__repr__", &RasterizeSettings::to_string);

    m.def(
        "sample_pattern",
        [](PatternKind kind, int samples, std::uint64_t seed) {
            return pattern_offsets(make_sample_pattern(kind, samples, seed));
        },
        py::arg("kind"), py::arg("samples"), py::arg("seed") = 0,
        "Sample offsets from a pixel's top-left corner in pixels, (S, 2) float64 (multiples of 1/256).");
    m.def(
        "interleaved_halves",
        [](PatternKind kind, int samples, std::uint64_t seed) {
            return interleaved_halves(make_sample_pattern(kind, samples, seed));
        },
        py::arg("kind"), py::arg("samples"), py::arg("seed") = 0,
        "The half (0 or 1) of each sample that the error estimate compares: a checkerboard over the\n"
        "pattern's strata. ValueError for fewer than 2 samples.");
    m.def("validate_framebuffer_size", &validate_framebuffer_size, py::arg("width"), py::arg("height"),
          py::arg("samples"), py::arg("with_depth"),
          "Raises ValueError naming the size or sample count that is out of range (or too much memory).");

    // --- render -------------------------------------------------------------------------------------
    m.def("render", &render_py, py::arg("draws"), py::arg("camera"), py::arg("settings"),
          "Renders the draws in order (the GIL is released meanwhile). Returns a dict: color (H, W, 4)\n"
          "float32, samples (H, W, S, 4) and sample_depth (H, W, S) float32 or None, pattern (S, 2),\n"
          "pattern_kind and stats. The arrays own the renderer's buffers: nothing is copied.");

    m.def("rasterize", &rasterize_py, py::arg("pos_clip"), py::arg("triangles"), py::arg("settings"),
          "Clips and rasterizes clip-space triangles (the GIL is released meanwhile). Returns a dict:\n"
          "triangle_id (H, W, S) int32 (-1 where empty), barycentrics (H, W, S, 2) float32 (perspective-\n"
          "correct weights of each triangle's 2nd and 3rd vertex), depth (H, W, S) float32 window depth,\n"
          "pattern (S, 2), pattern_kind and stats. Nothing is copied on the way out.");

    // --- colour ------------------------------------------------------------------------------------
    m.def("to_srgb8", &to_srgb8_py, py::arg("image"),
          "Linear premultiplied (H, W, 4) (or linear (H, W, 3) / (H, W, 1) / (H, W)) float -> straight-alpha\n"
          "sRGB8 (H, W, 4) uint8; colour is un-premultiplied before encoding, alpha stored linearly.");
    m.def("srgb_to_linear", py::vectorize(srgb_to_linear), py::arg("encoded"),
          "sRGB-encoded value in [0, 1] -> linear value (element-wise).");
    m.def("linear_to_srgb", py::vectorize(linear_to_srgb), py::arg("linear"),
          "Linear value -> sRGB-encoded value in [0, 1] (clamped; NaN -> 0; element-wise).");
    m.def("linear_to_srgb8", py::vectorize(linear_to_srgb8), py::arg("linear"),
          "Linear value -> sRGB8 code, rounded to nearest (linear 0.5 -> 188; element-wise).");
}

}  // namespace mipraster::bindings
