#pragma once
// Runs the renderer's own stages (clip, setup, edge test, interpolation, analytic uv
// derivatives) on clip-space triangles and hands every covered sample to a visitor, so the
// stress cases can look at values the framebuffer does not keep: weights, depth, uv and its
// derivatives. This is the code under test, not an oracle.
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mipraster/pipeline/draw.hpp"
#include "mipraster/pipeline/sample_pattern.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"
#include "mipraster/scene/camera.hpp"

namespace mipraster::stress {

struct ProbeSample {
    int x = 0, y = 0, s = 0;       ///< pixel and sample index
    std::uint32_t triangle = 0;    ///< index of the submitted triangle
    glm::dvec3 weights{0.0};       ///< perspective-correct weights of the submitted triangle's vertices
    float depth = 0.0f;            ///< window depth
    UvSample uv;                   ///< uv and its analytic derivatives (zero when no uvs are given)
};

struct ProbeStats {
    std::uint64_t pieces = 0;          ///< set-up (sub-)triangles
    std::uint64_t nonfinite_dropped = 0;
    int max_edge_bits = 0;             ///< bits of the largest |edge value| over the pieces' bounds
    int max_coefficient_bits = 0;      ///< bits of the largest |a|, |b| edge coefficient
};

/// Clips, sets up and rasterizes every triangle of `clip` (clip-space vertices) into a W×H
/// viewport with `pattern`, calling `visit` for each covered sample. `uvs` may be empty.
ProbeStats probe_samples(const std::vector<glm::dvec4>& clip, const std::vector<glm::uvec3>& triangles,
                         const std::vector<glm::vec2>& uvs, int width, int height, const SamplePattern& pattern,
                         DepthConvention convention, Interpolation interpolation,
                         const std::function<void(const ProbeSample&)>& visit);

}  // namespace mipraster::stress
