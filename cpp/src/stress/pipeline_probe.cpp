#include "pipeline_probe.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/clip.hpp"
#include "mipraster/pipeline/interpolate.hpp"

namespace mipraster::stress {

namespace {

int bits_of(double magnitude) { return magnitude < 1.0 ? 0 : static_cast<int>(std::floor(std::log2(magnitude))) + 1; }

void probe_piece(const SetupTriangle& t, const ClipWeights* clip_weights, const glm::uvec3& tri,
                 const std::vector<glm::vec2>& uvs, const SamplePattern& pattern, Interpolation interpolation,
                 ProbeStats& stats, const std::function<void(const ProbeSample&)>& visit) {
    // Bit budget: the largest edge value over the piece's pixel bounds (corners of the box).
    for (int i = 0; i < 3; ++i) {
        stats.max_coefficient_bits =
            std::max({stats.max_coefficient_bits, bits_of(std::fabs(double(t.edge_a[i]))), bits_of(std::fabs(double(t.edge_b[i])))});
        const double X = std::max(std::fabs(double(t.min_x)), std::fabs(double(t.max_x) + 1)) * kSubpixelOne;
        const double Y = std::max(std::fabs(double(t.min_y)), std::fabs(double(t.max_y) + 1)) * kSubpixelOne;
        const double e = std::fabs(double(t.edge_a[i])) * X + std::fabs(double(t.edge_b[i])) * Y + std::fabs(double(t.edge_c[i]));
        stats.max_edge_bits = std::max(stats.max_edge_bits, bits_of(e));
    }
    const bool with_uv = !uvs.empty();
    TriangleUvs tuv{};  // value-initialized: read only when the mesh has uvs
    if (with_uv) tuv = TriangleUvs(t, tri, uvs.data(), clip_weights);
    ProbeSample out;
    out.triangle = t.triangle;
    for (int py = t.min_y; py <= t.max_y; ++py)
        for (int px = t.min_x; px <= t.max_x; ++px)
            for (int s = 0; s < pattern.count(); ++s) {
                const std::int64_t X = std::int64_t{px} * kSubpixelOne + pattern.x[s];
                const std::int64_t Y = std::int64_t{py} * kSubpixelOne + pattern.y[s];
                std::int64_t e[3];
                for (int i = 0; i < 3; ++i) e[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
                if ((e[0] | e[1] | e[2]) < 0) continue;
                const glm::dvec3 l = screen_weights(t, e[0], e[1], e[2]);
                out.x = px;
                out.y = py;
                out.s = s;
                out.depth = sample_depth(t, l);
                const glm::dvec3 w = interpolation == Interpolation::screen ? l : perspective_weights(t, l);
                out.weights = original_weights(t, w, clip_weights);
                if (with_uv) out.uv = interpolate_uv<true>(t, tuv, l, interpolation);
                visit(out);
            }
}

}  // namespace

ProbeStats probe_samples(const std::vector<glm::dvec4>& clip, const std::vector<glm::uvec3>& triangles,
                         const std::vector<glm::vec2>& uvs, int width, int height, const SamplePattern& pattern,
                         DepthConvention convention, Interpolation interpolation,
                         const std::function<void(const ProbeSample&)>& visit) {
    ProbeStats stats;
    const ClipVolume volume = make_clip_volume(convention, width, height);
    Viewport viewport;
    viewport.width = width;
    viewport.height = height;
    viewport.depth_convention = convention;
    SetupCounters counters;
    ClipPolygon polygon;
    SetupTriangle st;
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
        const glm::uvec3 tri = triangles[t];
        const std::array<glm::dvec4, 3> p = {clip[tri[0]], clip[tri[1]], clip[tri[2]]};
        bool finite = true;
        for (const glm::dvec4& q : p) finite = finite && std::isfinite(q.x + q.y + q.z + q.w);
        if (!finite) {  // the renderer drops these before clipping
            ++counters.dropped_nonfinite;
            continue;
        }
        const std::array<std::uint8_t, 3> codes = {outcode(p[0], volume), outcode(p[1], volume), outcode(p[2], volume)};
        st.triangle = t;
        st.draw = 0;
        switch (clip_triangle(p, codes, volume, polygon)) {
            case ClipOutcome::outside: break;
            case ClipOutcome::inside:
                st.clip_index = -1;
                if (setup_triangle(p, viewport, CullMode::none, st, counters)) {
                    ++stats.pieces;
                    probe_piece(st, nullptr, tri, uvs, pattern, interpolation, stats, visit);
                }
                break;
            case ClipOutcome::clipped:
                if (projects_to_a_line(p)) break;  // as the renderer: zero area is culled before clipping
                for (int i = 1; i + 1 < polygon.count; ++i) {
                    const ClipVertex* v[3] = {&polygon.vertices[0], &polygon.vertices[i], &polygon.vertices[i + 1]};
                    const ClipWeights weights = {glm::vec3(v[0]->weights), glm::vec3(v[1]->weights), glm::vec3(v[2]->weights)};
                    st.clip_index = 0;
                    if (setup_triangle({v[0]->position, v[1]->position, v[2]->position}, viewport, CullMode::none, st,
                                       counters)) {
                        ++stats.pieces;
                        probe_piece(st, &weights, tri, uvs, pattern, interpolation, stats, visit);
                    }
                }
                break;
        }
    }
    stats.nonfinite_dropped = counters.dropped_nonfinite;
    return stats;
}

}  // namespace mipraster::stress
