#include "mipraster/pipeline/renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <type_traits>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "mipraster/core/constants.hpp"
#include "mipraster/core/huge_pages.hpp"
#include "mipraster/core/memory_limit.hpp"
#include "mipraster/core/thread_pool.hpp"
#include "mipraster/pipeline/binning.hpp"
#include "mipraster/pipeline/clip.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/triangle_setup.hpp"
#include "mipraster/pipeline/vertex_transform.hpp"
#include "tile_blocks.hpp"

namespace mipraster {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A run of one draw's triangles; one task clips, sets up and bins a chunk of one or more runs.
struct ChunkRange {
    std::uint32_t draw, first, last;
};

// One draw's triangles with its vertices in clip space, the clip volume's outcode of each vertex
// (kNonFinite marks a NaN or infinite coordinate, e.g. from a degenerate matrix) and the screen
// position of each vertex inside the volume: the input of clipping, setup and binning, whether it
// came from a camera (render) or not (rasterize).
struct ClipSpaceGeometry {
    RecycledVector<glm::dvec4> positions;
    std::vector<std::uint8_t> outcodes;
    RecycledVector<ScreenVertex> screen;  // (set and read only where the outcode is 0)
    const std::vector<glm::uvec3>* triangles = nullptr;
    CullMode cull = CullMode::none;
};

// Outcodes of positions [lo, hi), and the screen positions of those inside the volume: a triangle
// of three such vertices is set up without clipping, and each vertex is projected once instead of
// once for each of its triangles. Four at a time where the CPU has classify_and_project_four.
void classify_and_project(ClipSpaceGeometry& g, std::size_t lo, std::size_t hi, const ClipVolume& volume,
                          const Viewport& viewport) {
    std::size_t i = lo;
    if (setup_in_fours())
        for (; i + 4 <= hi; i += 4)
            classify_and_project_four(&g.positions[i], volume, viewport, &g.outcodes[i], &g.screen[i]);
    for (; i < hi; ++i) {
        const glm::dvec4& p = g.positions[i];
        const bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.w);
        g.outcodes[i] = finite ? outcode(p, volume) : kNonFinite;
        if (g.outcodes[i] == 0) g.screen[i] = project_vertex(p, viewport);
    }
}

// Sizes a geometry's per-vertex arrays for n vertices.
void resize_vertices(ClipSpaceGeometry& g, std::size_t n) {
    reserve_on_huge_pages(g.positions, n);
    g.positions.resize(n);
    g.outcodes.resize(n);
    reserve_on_huge_pages(g.screen, n);
    g.screen.resize(n);
}

// Vertices per task of the per-vertex stages, and per run of each stage within a task.
constexpr std::size_t kVertexBlock = 1 << 16;
constexpr std::size_t kVertexRun = 512;

// Triangles per chunk: enough chunks for load balance, few enough that per-chunk tile tables stay
// small. The split never changes the output (see BinnedChunk).
constexpr std::size_t kMinChunkTriangles = 256;

void validate_draws(const std::vector<Draw>& draws) {
    for (std::size_t i = 0; i < draws.size(); ++i) {
        const std::string name = "draws[" + std::to_string(i) + "]";
        if (!draws[i].mesh) throw std::invalid_argument(name + ".mesh is null");
        draws[i].mesh->validate(name + ".mesh");
        if (draws[i].mesh->triangles.size() >= (std::size_t{1} << 32))
            throw std::invalid_argument(name + ".mesh has too many triangles (at most 2^32 - 1)");
        for (int c = 0; c < 4; ++c)
            if (!std::isfinite(draws[i].color[c]))
                throw std::invalid_argument(name + ".color has a non-finite component");
        if (draws[i].texture) {
            if (!draws[i].mesh->has_uvs())
                throw std::invalid_argument(name + " has a texture ('" + draws[i].texture.name() +
                                            "') but its mesh has no uvs");
            draws[i].sampler.validate();
        }
        draws[i].state.validate(name + ".state");
    }
}

PipelineKey pipeline_key(const Draw& draw, Interpolation interpolation, const Camera& camera,
                         const RenderSettings& settings) {
    PipelineKey key;
    key.depth = !draw.state.depth_test ? DepthFunc::none
                : camera.depth_convention == DepthConvention::opengl ? DepthFunc::less
                                                                     : DepthFunc::greater;
    key.blend = draw.state.blend;
    if (!draw.mesh->has_colors()) key.shading = Shading::constant;  // nothing to interpolate
    else if (interpolation == Interpolation::flat) key.shading = Shading::flat;
    else if (interpolation == Interpolation::screen) key.shading = Shading::screen;
    else key.shading = Shading::perspective;
    key.samples = settings.samples == 1 ? SampleMode::single
                  : settings.anti_aliasing == AntiAliasing::msaa ? SampleMode::msaa
                                                                 : SampleMode::ssaa;
    // Derivatives only where λ matters: a sampler that ignores it, e.g. bilinear without mip
    // levels, gets the kernel that computes none (debug views always need them).
    if (draw.texture)
        key.texturing = draw.sampler.needs_derivatives() || settings.debug_view != DebugView::none ? Texturing::lod
                                                                                                   : Texturing::fixed;
    return key;
}

// View-space depth of each pixel's nearest sample. A drawn sample always differs from the clear
// depth (the depth test is strict), so a pixel whose samples all hold it is empty: +inf.
void resolve_view_depth(const SampleWindow& depth, int x0, int y0, int x1, int y1, float clear_depth,
                        const DepthDecoder& decoder, Image& out) {
    const bool reverse = decoder.convention == DepthConvention::reverse_z;  // nearer = larger
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const float* z = depth.at(x, y, 0);
            float nearest = clear_depth;
            for (int s = 0; s < depth.samples; ++s) nearest = reverse ? std::max(nearest, z[s]) : std::min(nearest, z[s]);
            out.at(x, y, 0) = nearest == clear_depth ? std::numeric_limits<float>::infinity()
                                                     : static_cast<float>(decoder.view_depth(nearest));
        }
}

// Appends a set-up triangle with streaming stores (kStreamedSetupBytes). (Readers on other
// threads need the fence in setup_chunk first.)
inline void append_streamed(RecycledVector<SetupTriangle>& triangles, const SetupTriangle& t) {
    triangles.emplace_back();  // (default-initialized: nothing stored)
#if defined(__SSE2__)
    static_assert(sizeof(SetupTriangle) % 16 == 0 && kBlockAlignment % 16 == 0, "records on 16-byte boundaries");
    const auto* from = reinterpret_cast<const __m128i*>(&t);
    auto* to = reinterpret_cast<__m128i*>(&triangles.back());
    for (std::size_t i = 0; i < sizeof(SetupTriangle) / 16; ++i) _mm_stream_si128(to + i, _mm_loadu_si128(from + i));
#else
    triangles.back() = t;
#endif
}

// Clip and set up one run of triangles into `chunk`, each kept through `keep`.
template <class Keep>
void setup_range(const ChunkRange& range, const ClipSpaceGeometry& vertices, const ClipVolume& volume,
                 const Viewport& viewport, BinnedChunk& chunk, SetupCounters& counters, std::uint64_t& clipped,
                 Keep&& keep) {
    SetupTriangle st;
    ClipPolygon polygon;
    // Triangles inside the clip volume wait in fours for setup_four_triangles where the CPU has it;
    // a clipped one lets those waiting through first, so that the order stays.
    const bool fours = setup_in_fours();
    const ScreenVertex* waiting[4][3];
    std::uint32_t waiting_triangle[4];
    int waiting_count = 0;
    const auto set_up_waiting = [&] {
        if (!waiting_count) return;
        SetupTriangle four[4];
        const int set_up = setup_four_triangles(waiting, waiting_count, viewport, vertices.cull, four, counters);
        for (int i = 0; i < waiting_count; ++i) {
            if (!(set_up >> i & 1)) continue;
            four[i].triangle = waiting_triangle[i];
            four[i].draw = range.draw;
            four[i].clip_index = -1;
            keep(four[i]);
        }
        waiting_count = 0;
    };
    for (std::uint32_t t = range.first; t < range.last; ++t) {
        const glm::uvec3 tri = (*vertices.triangles)[t];
        const std::array<std::uint8_t, 3> codes = {vertices.outcodes[tri[0]], vertices.outcodes[tri[1]],
                                                   vertices.outcodes[tri[2]]};
        if ((codes[0] | codes[1] | codes[2]) & kNonFinite) {
            ++counters.dropped_nonfinite;
            continue;
        }
        if ((codes[0] | codes[1] | codes[2]) == 0 && fours) {
            for (int k = 0; k < 3; ++k) waiting[waiting_count][k] = &vertices.screen[tri[k]];
            waiting_triangle[waiting_count] = t;
            if (++waiting_count == 4) set_up_waiting();
            continue;
        }
        set_up_waiting();
        st.triangle = t;
        st.draw = range.draw;
        if ((codes[0] | codes[1] | codes[2]) == 0) {  // inside: its vertices are projected already
            st.clip_index = -1;
            const std::array<ScreenVertex, 3> v = {vertices.screen[tri[0]], vertices.screen[tri[1]],
                                                   vertices.screen[tri[2]]};
            if (setup_triangle(v, viewport, vertices.cull, st, counters)) keep(st);
            continue;
        }
        const std::array<glm::dvec4, 3> p = {vertices.positions[tri[0]], vertices.positions[tri[1]],
                                             vertices.positions[tri[2]]};
        switch (clip_triangle(p, codes, volume, polygon)) {
            case ClipOutcome::inside:  // (only for outcodes that OR to 0: set up above)
            case ClipOutcome::outside: ++counters.culled_outside; break;
            case ClipOutcome::clipped: {
                ++clipped;
                if (projects_to_a_line(p)) {  // zero area: clipping would round area into it
                    ++counters.culled_degenerate;
                    break;
                }
                // Fan-triangulate the clipped polygon; each piece keeps its original-triangle weights.
                SetupCounters pieces;
                bool any = false;
                for (int i = 1; i + 1 < polygon.count; ++i) {
                    const ClipVertex* v[3] = {&polygon.vertices[0], &polygon.vertices[i], &polygon.vertices[i + 1]};
                    st.clip_index = static_cast<std::int32_t>(chunk.clip_weights.size());
                    const std::array<glm::dvec4, 3> piece = {v[0]->position, v[1]->position, v[2]->position};
                    if (setup_triangle(piece, viewport, vertices.cull, st, pieces)) {
                        any = true;
                        keep(st);
                        chunk.clip_weights.push_back(
                            {glm::vec3(v[0]->weights), glm::vec3(v[1]->weights), glm::vec3(v[2]->weights)});
                    }
                }
                // The counters count submitted triangles: a clipped one that drew nothing counts
                // once, under the first reason that applies to its pieces.
                if (!any) {
                    if (pieces.culled_backface) ++counters.culled_backface;
                    else if (pieces.dropped_nonfinite) ++counters.dropped_nonfinite;
                    else if (pieces.culled_outside) ++counters.culled_outside;
                    else if (pieces.culled_between_samples) ++counters.culled_between_samples;
                    else ++counters.culled_degenerate;
                }
                break;
            }
        }
    }
    set_up_waiting();
}

// Clip, set up and bin one chunk: its runs in order (`streamed`: their records with streaming
// stores; enough_overdraw: setup_and_bin's).
void setup_chunk(const std::vector<ChunkRange>& runs, const std::vector<ClipSpaceGeometry>& geometry,
                 const ClipVolume& volume, const Viewport& viewport, const TileGrid& grid,
                 const std::vector<double>& enough_overdraw, bool streamed, BinnedChunk& chunk,
                 SetupCounters& counters, std::uint64_t& clipped) {
    std::size_t count = 0;
    double enough = 0.0;  // (the largest of its draws')
    for (const ChunkRange& run : runs) {
        count += run.last - run.first;
        if (!enough_overdraw.empty()) enough = std::max(enough, enough_overdraw[run.draw]);
    }
    reserve_on_huge_pages(chunk.triangles, count);
    ChunkBinner binner(chunk, grid, !enough_overdraw.empty(), enough);
    const auto keep = [&](const SetupTriangle& t) {
        binner.add(t);
        if (streamed) append_streamed(chunk.triangles, t);
        else chunk.triangles.push_back(t);
    };
    for (const ChunkRange& run : runs)
        setup_range(run, geometry[run.draw], volume, viewport, chunk, counters, clipped, keep);
#if defined(__SSE2__)
    if (streamed) _mm_sfence();  // (the streaming stores before the hand-off to the threads that rasterize)
#endif
    binner.finish();
    chunk.one_draw = runs.size() == 1;
}

// Stage 2: clip, set up and bin every draw's triangles, in parallel over chunks of consecutive
// triangles; adds the triangle counts to `stats`. With each tile's overlap estimate unless
// `enough_overdraw` is empty: per draw, the overdraw from which a tile's estimate says all that
// is asked of it (ChunkBinner), +∞ for the exact sum.
std::vector<BinnedChunk> setup_and_bin(const std::vector<ClipSpaceGeometry>& geometry, const ClipVolume& volume,
                                       const Viewport& viewport, const TileGrid& grid,
                                       const std::vector<double>& enough_overdraw, ThreadPool& pool,
                                       RenderStats& stats) {
    // Each draw in runs of `size` triangles, a chunk each; the runs of small draws gather into
    // chunks of up to kMinChunkTriangles (each chunk has a table per tile, and each tile looks at
    // every chunk: ten thousand two-triangle draws took 13× the time of one draw of them all).
    std::vector<std::vector<ChunkRange>> chunk_runs;  // each chunk's runs
    std::size_t gathered = kMinChunkTriangles;        // triangles in chunk_runs.back() while it gathers
    for (std::uint32_t d = 0; d < geometry.size(); ++d) {
        const std::size_t n = geometry[d].triangles->size();
        stats.triangles_in += n;
        const std::size_t size = std::max(kMinChunkTriangles, n / (4 * static_cast<std::size_t>(pool.size())) + 1);
        for (std::size_t first = 0; first < n; first += size) {
            const ChunkRange run{d, static_cast<std::uint32_t>(first),
                                 static_cast<std::uint32_t>(std::min(n, first + size))};
            const std::size_t count = run.last - run.first;
            if (count < kMinChunkTriangles && gathered + count <= kMinChunkTriangles) {
                chunk_runs.back().push_back(run);
                gathered += count;
            } else {
                chunk_runs.push_back({run});
                gathered = count;
            }
        }
    }
    const bool streamed = stats.triangles_in * sizeof(SetupTriangle) > kStreamedSetupBytes;
    std::vector<BinnedChunk> chunks(chunk_runs.size());
    std::vector<SetupCounters> setup_counters(chunk_runs.size());
    std::vector<std::uint64_t> clipped(chunk_runs.size(), 0);
    pool.parallel_for(chunk_runs.size(), [&](std::size_t i) {
        SetupCounters counters;  // (stored once: neighbouring chunks' counters share cache lines)
        std::uint64_t clipped_here = 0;
        setup_chunk(chunk_runs[i], geometry, volume, viewport, grid, enough_overdraw, streamed, chunks[i], counters,
                    clipped_here);
        setup_counters[i] = counters;
        clipped[i] = clipped_here;
    });
    for (std::size_t i = 0; i < chunk_runs.size(); ++i) {
        stats.triangles_clipped += clipped[i];
        stats.triangles_outside += setup_counters[i].culled_outside;
        stats.triangles_between_samples += setup_counters[i].culled_between_samples;
        stats.triangles_backface += setup_counters[i].culled_backface;
        stats.triangles_degenerate += setup_counters[i].culled_degenerate;
        stats.triangles_nonfinite += setup_counters[i].dropped_nonfinite;
        stats.triangles_rasterized += chunks[i].triangles.size();
    }
    return chunks;
}

// Calls f(draw, begin, end) for each run of one draw's triangles in the chunk's list for `tile`
// (submission order): the whole list where the chunk holds one draw.
template <class F>
void for_each_draw_run(const BinnedChunk& chunk, std::size_t tile, F&& f) {
    const std::uint32_t* begin = chunk.tile_triangles.data() + chunk.tile_start[tile];
    const std::uint32_t* const end = chunk.tile_triangles.data() + chunk.tile_start[tile + 1];
    while (begin != end) {
        const std::uint32_t draw = chunk.triangles[*begin].draw;
        const std::uint32_t* run = chunk.one_draw ? end : begin + 1;
        while (run != end && chunk.triangles[*run].draw == draw) ++run;
        f(draw, begin, run);
        begin = run;
    }
}

// Stage 3 for one tile: every chunk's triangles that touch it, in submission order: one kernel
// call per run of one draw's triangles.
void rasterize_tile_chunks(std::size_t tile, const std::vector<BinnedChunk>& chunks, const std::vector<TileKernel>& kernels,
                           const std::vector<DrawInputs>& inputs, const TileTarget& target, TileCounters& counters) {
    for (const BinnedChunk& chunk : chunks)
        for_each_draw_run(chunk, tile, [&](std::uint32_t draw, const std::uint32_t* begin, const std::uint32_t* end) {
            const TriangleBatch batch{chunk.triangles.data(), begin, static_cast<std::size_t>(end - begin),
                                      chunk.clip_weights.data()};
            kernels[draw](target, inputs[draw], batch, counters);
        });
}

// Whether any triangle's bounds reach the tile.
bool tile_has_triangles(std::size_t tile, const std::vector<BinnedChunk>& chunks) {
    for (const BinnedChunk& chunk : chunks)
        if (chunk.tile_start[tile] != chunk.tile_start[tile + 1]) return true;
    return false;
}

// About how many times over the tile's triangles cover it (binning added up each chunk's
// tile_overlap_area).
double tile_overdraw(std::size_t tile, const std::vector<BinnedChunk>& chunks, const TileTarget& target) {
    double area = 0.0;
    for (const BinnedChunk& chunk : chunks) area += chunk.tile_area[tile];
    return area / (double(target.x1 - target.x0) * double(target.y1 - target.y0));
}

// Whether the tile may be deferred: every triangle in it is of a draw that may (`deferrable`).
bool tile_deferrable(std::size_t tile, const std::vector<BinnedChunk>& chunks, const std::vector<char>& deferrable) {
    for (const BinnedChunk& chunk : chunks)
        for (std::uint32_t i = chunk.tile_start[tile]; i < chunk.tile_start[tile + 1]; ++i)
            if (!deferrable[chunk.triangles[chunk.tile_triangles[i]].draw]) return false;
    return true;
}

// Whether deferring the tile's shading pays (with RenderSettings::deferred_shading): overdraw from
// min_overdraw on (kDeferredMinOverdraw, or kDeferredMinOverdrawMsaa), and for a tile without
// textures also big enough triangles (kDeferredMinUntexturedGain). `deferrable`: per draw, whether
// it may be deferred; every_draw: all may (else the tile's triangles are checked).
bool defer_tile(std::size_t tile, const std::vector<BinnedChunk>& chunks, const std::vector<DrawInputs>& inputs,
                const std::vector<char>& deferrable, bool every_draw, double min_overdraw, const TileTarget& target) {
    const double overdraw = tile_overdraw(tile, chunks, target);
    if (overdraw < min_overdraw) return false;
    if (!every_draw && !tile_deferrable(tile, chunks, deferrable)) return false;
    std::size_t triangles = 0;
    bool textured = false;
    for (const BinnedChunk& chunk : chunks)
        for_each_draw_run(chunk, tile, [&](std::uint32_t draw, const std::uint32_t* begin, const std::uint32_t* end) {
            textured = textured || inputs[draw].texture;
            triangles += static_cast<std::size_t>(end - begin);
        });
    if (textured) return true;
    const double tile_area = double(target.x1 - target.x0) * double(target.y1 - target.y0);
    const double mean_area = overdraw * tile_area / double(triangles);  // (overdraw > 0: some triangle)
    return (overdraw - 1.0) * (overdraw - 1.0) * mean_area >= kDeferredMinUntexturedGain;
}

// Deferred shading of one tile (RenderSettings::deferred_shading): the pre-pass rasterizes and
// depth-tests every triangle as the forward kernels would, recording for each sample the triangle
// it ends up with (MSAA: and where that triangle shades the pixel); then each draw shades the
// samples its triangles own, once each (MSAA: once per pixel and owner).
void rasterize_tile_deferred(std::size_t tile, const std::vector<BinnedChunk>& chunks,
                             const std::vector<TileKernel>& prepass_kernels,
                             const std::vector<OwnedShadingKernel>& shading_kernels, const std::vector<DrawInputs>& inputs,
                             const TileTarget& target, bool msaa, TileCounters& counters) {
    thread_local std::vector<std::int32_t> owners;
    thread_local std::vector<std::uint8_t> shade_at;
    thread_local std::vector<OwnerRef> refs;
    const std::size_t samples = std::size_t{kTileSize} * kTileSize * static_cast<std::size_t>(target.color.samples);
    owners.assign(samples, -1);
    refs.clear();
    TileTarget deferred = target;
    deferred.owners = owners.data();
    deferred.owner_refs = &refs;
    if (msaa) {
        shade_at.resize(samples);  // (written with each owner)
        deferred.owner_shade_at = shade_at.data();
    }
    rasterize_tile_chunks(tile, chunks, prepass_kernels, inputs, deferred, counters);
    // refs follow submission order: each draw's triangles come together.
    for (std::size_t i = 0; i < refs.size();) {
        const std::uint32_t draw = refs[i].triangle->draw;
        shading_kernels[draw](deferred, inputs[draw], draw, counters);
        while (i < refs.size() && refs[i].triangle->draw == draw) ++i;
    }
    ++counters.tiles_deferred;
}

// The viewport of a render whose pixels hold the samples of `pattern`: their extent bounds each
// triangle's pixels (Viewport).
Viewport sample_viewport(int width, int height, DepthConvention convention, const SamplePattern& pattern) {
    Viewport v{width, height, convention};
    v.sample_x0 = *std::min_element(pattern.x.begin(), pattern.x.end());
    v.sample_x1 = *std::max_element(pattern.x.begin(), pattern.x.end());
    v.sample_y0 = *std::min_element(pattern.y.begin(), pattern.y.end());
    v.sample_y1 = *std::max_element(pattern.y.begin(), pattern.y.end());
    return v;
}

// The pixel rectangle of a tile; its storage windows are the caller's to set.
TileTarget tile_target(const TileGrid& grid, std::size_t tile, const SamplePattern& pattern) {
    const int tx = static_cast<int>(tile) % grid.tiles_x, ty = static_cast<int>(tile) / grid.tiles_x;
    TileTarget target;
    target.pattern = &pattern;
    target.x0 = tx * kTileSize;
    target.y0 = ty * kTileSize;
    target.x1 = std::min((tx + 1) * kTileSize, grid.width);
    target.y1 = std::min((ty + 1) * kTileSize, grid.height);
    return target;
}

void add_counters(const std::vector<TileCounters>& tiles, RenderStats& stats) {
    for (const TileCounters& c : tiles) {
        stats.samples_covered += c.samples_covered;
        stats.samples_passed += c.samples_passed;
        stats.shader_invocations += c.shader_invocations;
        stats.depth_blocks_rejected += c.depth_blocks_rejected;
        stats.tiles_deferred += c.tiles_deferred;
        stats.tiles_empty += c.tiles_empty;
    }
}

// Per vertex and per triangle of the input, what transform, setup and binning hold.
std::uint64_t geometry_bytes(std::uint64_t vertices, std::uint64_t triangles) {
    return vertices * (sizeof(glm::dvec4) + 1 + sizeof(ScreenVertex)) +
           triangles * (sizeof(SetupTriangle) + 2 * sizeof(std::uint32_t));
}

// What a render allocates, estimated before it allocates: the output images, the kept samples,
// each worker's tile buffers, and the geometry.
std::uint64_t render_bytes(const std::vector<Draw>& draws, const RenderSettings& settings, int threads,
                           bool needs_depth, bool depth_output) {
    const std::uint64_t pixels = std::uint64_t(settings.width) * std::uint64_t(settings.height);
    // Colour, depth, and deferred shading's owner per sample (an int32).
    const std::uint64_t sample_bytes = (4 + (needs_depth ? 1 : 0) + (settings.deferred_shading ? 1 : 0)) * sizeof(float);
    std::uint64_t bytes = pixels * 4 * sizeof(float);  // the resolved colour
    if (depth_output) bytes += pixels * sizeof(float);
    if (settings.estimate_error) bytes += pixels * sizeof(float);  // the error map
    // Kept samples, or a resolve filter wider than a pixel: a whole-frame sample buffer.
    const bool wide_resolve = settings.resolve_filter != ResolveFilter::box && settings.samples > 1;
    if (settings.keep_samples || wide_resolve)
        bytes += framebuffer_bytes(settings.width, settings.height, settings.samples, needs_depth);
    if (wide_resolve) bytes += pixels * std::uint64_t(settings.samples) * 4 * sizeof(double);  // its row sums
    bytes += std::uint64_t(threads) * kTileSize * kTileSize * std::uint64_t(settings.samples) * sample_bytes;
    for (const Draw& d : draws) bytes += geometry_bytes(d.mesh->positions.size(), d.mesh->triangles.size());
    return bytes;
}

// Sparse listed pixels (RenderSettings::pixels) cost 1.7–3× a pixel of a whole tile (each span
// repeats the edge setup of the tile's triangles): from this share of a tile's pixels on, the
// tile is rasterized whole.
constexpr double kWholeTileShare = 0.5;
static_assert(kWholeTileShare > 0.0 && kWholeTileShare <= 1.0, "a share of a tile's pixels");

// One row of listed pixels inside one tile: [x0, x1) × [y, y + 1).
struct PixelSpan {
    int y, x0, x1;
};

// RenderSettings::pixels as row spans per tile (empty lists when no pixels are listed). Throws
// std::invalid_argument for an index outside the image.
std::vector<std::vector<PixelSpan>> pixel_spans(const std::vector<std::uint32_t>& pixels, const TileGrid& grid) {
    std::vector<std::vector<PixelSpan>> spans(static_cast<std::size_t>(grid.count()));
    const std::uint64_t n = std::uint64_t(grid.width) * std::uint64_t(grid.height);
    for (std::size_t i = 0; i < pixels.size(); ++i)
        if (pixels[i] >= n)
            throw std::invalid_argument("pixels[" + std::to_string(i) + "] = " + std::to_string(pixels[i]) +
                                        " is outside the " + std::to_string(grid.width) + "x" +
                                        std::to_string(grid.height) + " image (expected y * width + x < " +
                                        std::to_string(n) + ")");
    std::vector<std::uint32_t> sorted = pixels;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    for (std::uint32_t p : sorted) {  // row-major order: a tile's spans come row by row, left to right
        const int x = static_cast<int>(p % std::uint32_t(grid.width));
        const int y = static_cast<int>(p / std::uint32_t(grid.width));
        std::vector<PixelSpan>& tile = spans[std::size_t(y / kTileSize) * grid.tiles_x + std::size_t(x / kTileSize)];
        if (!tile.empty() && tile.back().y == y && tile.back().x1 == x) ++tile.back().x1;
        else tile.push_back({y, x, x + 1});
    }
    return spans;
}

std::string render_description(int width, int height, int samples) {
    return std::to_string(width) + "x" + std::to_string(height) + " pixels at " + std::to_string(samples) +
           (samples == 1 ? " sample" : " samples") + " per pixel";
}

}  // namespace


std::string to_string(AntiAliasing aa) { return aa == AntiAliasing::msaa ? "msaa" : "ssaa"; }

AntiAliasing parse_anti_aliasing(const std::string& name) {
    if (name == "ssaa") return AntiAliasing::ssaa;
    if (name == "msaa") return AntiAliasing::msaa;
    throw std::invalid_argument("anti-aliasing: unknown mode '" + name + "'; expected ssaa or msaa");
}

RenderResult render(const std::vector<Draw>& draws, const Camera& camera, const RenderSettings& settings) {
    const auto start = Clock::now();
    // Validate everything before allocating anything large.
    const bool needs_depth = std::any_of(draws.begin(), draws.end(), [](const Draw& d) { return d.state.depth_test; });
    validate_framebuffer_size(settings.width, settings.height, settings.samples, needs_depth);
    RenderResult result;
    result.pattern = make_sample_pattern(settings.pattern, settings.samples, settings.pattern_seed);
    validate_draws(draws);
    const std::vector<std::uint8_t> halves =
        settings.estimate_error ? interleaved_halves(result.pattern) : std::vector<std::uint8_t>{};
    {
        const TileGrid g = TileGrid::for_viewport(settings.width, settings.height);
        if (!settings.tile_mask.empty() && settings.tile_mask.size() != static_cast<std::size_t>(g.count()))
            throw std::invalid_argument("tile_mask: expected " + std::to_string(g.count()) + " flags (" +
                                        std::to_string(g.tiles_x) + " x " + std::to_string(g.tiles_y) +
                                        " tiles of " + std::to_string(kTileSize) + " px), got " +
                                        std::to_string(settings.tile_mask.size()));
        if (!settings.pixels.empty() && !settings.tile_mask.empty())
            throw std::invalid_argument("pixels: give either a pixel list or a tile_mask, not both");
        if (!settings.pixels.empty() && settings.resolve_filter != ResolveFilter::box && settings.samples > 1)
            throw std::invalid_argument("pixels: a render of listed pixels needs the box resolve (a " +
                                        to_string(settings.resolve_filter) + " filter reads unrendered neighbours)");
    }
    const bool depth_output = settings.depth_output && needs_depth;
    const DepthDecoder decoder = depth_output ? camera.depth_decoder() : DepthDecoder{};
    const int threads = resolve_thread_count(settings.threads);
    check_memory(render_bytes(draws, settings, threads, needs_depth, depth_output),
                 "a render of " + render_description(settings.width, settings.height, settings.samples));
    const LeasedPool leased = lease_thread_pool(threads);
    ThreadPool& pool = *leased;
    RenderStats& stats = result.stats;
    stats.threads = threads;

    // Stage 1: vertex transform, per draw, in parallel over blocks of vertices.
    auto t0 = Clock::now();
    const ClipVolume volume = make_clip_volume(camera.depth_convention, settings.width, settings.height);
    const Viewport viewport = sample_viewport(settings.width, settings.height, camera.depth_convention, result.pattern);
    std::vector<ClipSpaceGeometry> geometry(draws.size());
    for (std::size_t d = 0; d < draws.size(); ++d) {
        const Mesh& mesh = *draws[d].mesh;
        const glm::dmat4 mvp = camera.projection * camera.view * draws[d].model;
        ClipSpaceGeometry& g = geometry[d];
        g.triangles = &mesh.triangles;
        g.cull = draws[d].state.cull;
        resize_vertices(g, mesh.positions.size());
        pool.parallel_for((mesh.positions.size() + kVertexBlock - 1) / kVertexBlock, [&](std::size_t b) {
            const std::size_t end = std::min((b + 1) * kVertexBlock, mesh.positions.size());
            // A few hundred vertices at a time: classified while the transform's output is in cache.
            for (std::size_t lo = b * kVertexBlock; lo < end; lo += kVertexRun) {
                const std::size_t hi = std::min(lo + kVertexRun, end);
                transform_vertices(&mesh.positions[lo], hi - lo, mvp, &g.positions[lo]);
                classify_and_project(g, lo, hi, volume, viewport);
            }
        });
    }
    stats.transform_ms = ms_since(t0);

    // Each draw's kernels (which also say whether deferred shading may run) and inputs.
    std::vector<TileKernel> kernels(draws.size()), prepass_kernels(draws.size());
    std::vector<OwnedShadingKernel> shading_kernels(draws.size());
    // Per draw, whether its tiles may be deferred: it has a deferred shading pass and no alpha test
    // (its samples keep the depth of what lies behind wherever its shade is discarded: the
    // pre-pass, which shades nothing, cannot know which triangle a sample ends up with). A tile
    // is deferred only when all its triangles' draws may be.
    const bool msaa = settings.samples > 1 && settings.anti_aliasing == AntiAliasing::msaa;
    std::vector<char> deferrable(draws.size());
    std::vector<DrawInputs> inputs(draws.size());
    std::vector<std::unique_ptr<TextureView>> textures(draws.size());  // pinned for the render
    for (std::size_t d = 0; d < draws.size(); ++d) {
        const ClipSpaceGeometry& g = geometry[d];
        const Interpolation interpolation =
            effective_interpolation(draws[d].state.interpolation, g.positions.data(), g.positions.size());
        const PipelineKey key = pipeline_key(draws[d], interpolation, camera, settings);
        kernels[d] = select_tile_kernel(key);
        PipelineKey prepass = key;
        prepass.shading = Shading::visibility;
        prepass_kernels[d] = select_tile_kernel(prepass);
        shading_kernels[d] = select_owned_shading_kernel(key);
        // (Not untextured draws under MSAA, whose one cheap shade per pixel leaves the pre-pass little
        // to save: their renders then skip the overlap estimate, as before MSAA was deferred.)
        deferrable[d] = settings.deferred_shading && shading_kernels[d] && !draws[d].state.alpha_cutoff &&
                        !(msaa && !draws[d].texture);
        const Mesh& mesh = *draws[d].mesh;
        inputs[d] = {mesh.triangles.data(), mesh.has_colors() ? mesh.colors.data() : nullptr, draws[d].color,
                     draws[d].state.depth_write, draws[d].state.alpha_cutoff};
        if (draws[d].texture) {
            textures[d] = std::make_unique<TextureView>(draws[d].texture);
            inputs[d].uvs = mesh.uvs.data();
            inputs[d].texture = textures[d].get();
            inputs[d].sampler = &draws[d].sampler;
            inputs[d].uv_interpolation = interpolation;
            inputs[d].derivatives = settings.derivatives;
            inputs[d].debug_view = settings.debug_view;
            inputs[d].batched_lookups = settings.batched_lookups;
            if (settings.anti_aliasing == AntiAliasing::ssaa && settings.samples > 1)
                inputs[d].footprint_scale = glm::dvec2(1.0 / result.pattern.columns, 1.0 / result.pattern.rows);
        }
    }

    // Whether some tile may be deferred, and whether every one may (else defer_tile looks).
    const bool deferred = std::find(deferrable.begin(), deferrable.end(), 1) != deferrable.end();
    const bool every_draw_deferrable = std::find(deferrable.begin(), deferrable.end(), 0) == deferrable.end();

    // Stage 2: clip, set up and bin (with the per-tile overlap estimate only where a tile may be
    // deferred; defer_tile asks no more of a tile with a textured draw than min_overdraw).
    t0 = Clock::now();
    const double min_overdraw = msaa ? kDeferredMinOverdrawMsaa : kDeferredMinOverdraw;
    const TileGrid grid = TileGrid::for_viewport(settings.width, settings.height);
    std::vector<double> enough_overdraw;
    if (deferred)
        for (const DrawInputs& input : inputs)
            enough_overdraw.push_back(input.texture ? min_overdraw : std::numeric_limits<double>::infinity());
    const std::vector<BinnedChunk> chunks =
        setup_and_bin(geometry, volume, viewport, grid, enough_overdraw, pool, stats);
    stats.setup_ms = ms_since(t0);

    // Stage 3: per tile, one task each: clear, rasterize (shade, depth test, blend) the tile's
    // triangles in submission order, and resolve. The samples live in a tile-local buffer that
    // stays in cache, and a whole-frame sample buffer exists only when the caller keeps the
    // samples; at one sample per pixel the resolve is a copy.
    t0 = Clock::now();
    const int S = settings.samples;
    const float clear_depth = camera.depth_convention == DepthConvention::opengl ? 1.0f : 0.0f;
    const glm::vec4 clear_depth4(clear_depth);
    // A wide resolve filter reads neighbouring pixels (across tiles): it needs every sample kept.
    const bool wide_resolve = settings.resolve_filter != ResolveFilter::box && S > 1;
    const bool whole_frame = settings.keep_samples || wide_resolve;
    // Where every draw tests and writes depth and replaces colour, a sample still at the clear
    // depth after drawing is one no draw wrote (a passing depth test is strict, so a written depth
    // is never the clear one), and only those need the clear colour (fill_undrawn): a tile drawn
    // whole no longer stores its colour twice (MSAA 4x: 64 bytes a pixel; the plane's and the
    // cube's frames −1–2 % at one thread, −5–6 % at two, where both cores' clears shared memory).
    const bool lazy_colour_clear =
        needs_depth && !whole_frame && std::all_of(draws.begin(), draws.end(), [](const Draw& d) {
            return d.state.depth_test && d.state.depth_write && d.state.blend == BlendMode::replace;
        });
    // With several samples a pixel, the undrawn samples' clear colour can go straight into the
    // resolve where nothing else reads the tile's colour samples (the error estimate does): the
    // background is then neither stored nor read back (MSAA 4x: 128 bytes a pixel). (At one
    // sample, where the resolve is a copy, the pass measured no faster than fill_undrawn + copy.)
    const bool resolve_over_clear = lazy_colour_clear && !settings.estimate_error && S > 1;
    Framebuffer kept;
    if (whole_frame)
        kept = make_framebuffer(settings.width, settings.height, S, settings.clear_color, needs_depth, clear_depth);
    // Unfilled: every tile writes each of its pixels (a clear, a resolve, or the listed-pixels
    // clear), so a zeroing pass over the whole image first would only add a serial write.
    result.color = Image::unfilled(settings.width, settings.height, 4);
    if (depth_output) result.depth = Image(settings.width, settings.height, 1);
    if (settings.estimate_error) result.error_map = Image(settings.width, settings.height, 1);
    const std::vector<std::vector<PixelSpan>> spans = pixel_spans(settings.pixels, grid);
    const bool listed = !settings.pixels.empty();
    // A tile no triangle reaches (block skipping's whole-tile case) needs no tile buffers: each of
    // its pixels is what the resolve makes of samples that all hold the clear values, worked out
    // once here by the same resolve on one pixel (at one sample the clear colour itself).
    const bool skip_empty_tiles = settings.block_skipping && !whole_frame && !listed && !settings.estimate_error;
    glm::vec4 clear_pixel(0.0f), clear_view_depth(0.0f);
    if (skip_empty_tiles) {
        std::vector<float> colour(4 * static_cast<std::size_t>(S)), depth(static_cast<std::size_t>(S), clear_depth);
        SampleWindow{colour.data(), 4, 0, 0, 1, S}.fill(0, 0, 1, 1, settings.clear_color);
        Image pixel(1, 1, 4);
        resolve_tile({colour.data(), 4, 0, 0, 1, S}, 0, 0, 1, 1, ResolveFilter::box, pixel);
        clear_pixel = glm::vec4(pixel.at(0, 0, 0), pixel.at(0, 0, 1), pixel.at(0, 0, 2), pixel.at(0, 0, 3));
        if (depth_output) {
            Image z(1, 1, 1);
            resolve_view_depth({depth.data(), 1, 0, 0, 1, S}, 0, 0, 1, 1, clear_depth, decoder, z);
            clear_view_depth = glm::vec4(z.at(0, 0, 0));
        }
    }
    std::vector<TileCounters> tile_counters(static_cast<std::size_t>(grid.count()));
    std::mutex progress_mutex;
    std::size_t tiles_done = 0;
    pool.parallel_for(static_cast<std::size_t>(grid.count()), [&](std::size_t tile) {
        TileTarget target = tile_target(grid, tile, result.pattern);
        target.block_skipping = settings.block_skipping;
        target.sample_rows = settings.sample_rows;
        // Counted here and stored once: the kernels count per sample, and neighbouring tiles'
        // counters share cache lines, which two threads would otherwise pass back and forth.
        TileCounters counters;
        const auto done = [&] {
            tile_counters[tile] = counters;
            if (settings.progress) {
                std::lock_guard<std::mutex> lock(progress_mutex);
                settings.progress(++tiles_done, static_cast<std::size_t>(grid.count()));
            }
        };
        // The tile's pixels written with one colour and one view depth, without drawing.
        const auto write_tile = [&](const glm::vec4& colour, const glm::vec4& view_depth) {
            write_pixels(colour, target.x0, target.y0, target.x1, target.y1, result.color);
            if (depth_output)
                SampleWindow{result.depth.pixels.data(), 1, 0, 0, settings.width, 1}.fill(
                    target.x0, target.y0, target.x1, target.y1, view_depth);
        };
        const bool masked = !settings.tile_mask.empty() && !settings.tile_mask[tile];
        if (masked || listed) {
            // Pixels not asked for: the clear colour, no samples drawn, no error.
            write_tile(settings.clear_color, glm::vec4(std::numeric_limits<float>::infinity()));
            if (masked || spans[tile].empty()) return done();
        }
        if (skip_empty_tiles && !tile_has_triangles(tile, chunks)) {
            write_tile(clear_pixel, clear_view_depth);
            ++counters.tiles_empty;
            return done();
        }
        // Tile-local storage, reused by each worker thread from tile to tile.
        thread_local std::vector<float> tile_color, tile_depth;
        if (whole_frame) {
            target.color = color_window(kept);
            target.depth = depth_window(kept);
        } else {
            tile_color.resize(std::size_t{4} * kTileSize * kTileSize * static_cast<std::size_t>(S));
            target.color = {tile_color.data(), 4, target.x0, target.y0, kTileSize, S};
            if (needs_depth) {
                tile_depth.resize(std::size_t{kTileSize} * kTileSize * static_cast<std::size_t>(S));
                target.depth = {tile_depth.data(), 1, target.x0, target.y0, kTileSize, S};
            }
        }
        // The whole tile, or each listed span of it (a span is a thin tile: the kernel clips every
        // triangle's bounding box to the target's rectangle). Each span repeats the edge setup of
        // every triangle in the tile, so a tile with at least kWholeTileShare of its pixels listed
        // is rasterized whole into its tile-local buffer and only the listed spans are resolved
        // (not with a kept framebuffer, where the samples are the output).
        const PixelSpan whole{target.y0, target.x0, target.x1};
        const PixelSpan* first = listed ? spans[tile].data() : &whole;
        const PixelSpan* last = listed ? first + spans[tile].size() : &whole + 1;
        int listed_pixels = 0;
        for (const PixelSpan* span = first; span != last; ++span) listed_pixels += span->x1 - span->x0;
        const int tile_pixels = (target.x1 - target.x0) * (target.y1 - target.y0);
        const bool rasterize_whole =
            !listed || (!whole_frame && listed_pixels >= kWholeTileShare * tile_pixels);
        if (rasterize_whole) {
            if (!whole_frame) {  // a kept framebuffer starts cleared
                if (!lazy_colour_clear)
                    target.color.fill(target.x0, target.y0, target.x1, target.y1, settings.clear_color);
                if (needs_depth) target.depth.fill(target.x0, target.y0, target.x1, target.y1, clear_depth4);
            }
            if (deferred && defer_tile(tile, chunks, inputs, deferrable, every_draw_deferrable, min_overdraw, target))
                rasterize_tile_deferred(tile, chunks, prepass_kernels, shading_kernels, inputs, target,
                                        msaa, counters);
            else
                rasterize_tile_chunks(tile, chunks, kernels, inputs, target, counters);
            if (lazy_colour_clear && !resolve_over_clear)
                fill_undrawn(target.color, target.depth, target.x0, target.y0, target.x1, target.y1, clear_depth,
                             settings.clear_color);
        }
        for (const PixelSpan* span = first; span != last; ++span) {
            TileTarget part = target;
            if (listed) part.x0 = span->x0, part.x1 = span->x1, part.y0 = span->y, part.y1 = span->y + 1;
            if (!rasterize_whole) {
                if (!whole_frame) {
                    part.color.fill(part.x0, part.y0, part.x1, part.y1, settings.clear_color);
                    if (needs_depth) part.depth.fill(part.x0, part.y0, part.x1, part.y1, clear_depth4);
                }
                rasterize_tile_chunks(tile, chunks, kernels, inputs, part, counters);
            }
            if (resolve_over_clear && rasterize_whole)
                resolve_undrawn(part.color, part.depth, part.x0, part.y0, part.x1, part.y1, clear_depth,
                                settings.clear_color, result.color);
            else if (!wide_resolve)  // (the box: at one sample every filter's resolve is this copy)
                resolve_tile(part.color, part.x0, part.y0, part.x1, part.y1, ResolveFilter::box, result.color);
            if (settings.estimate_error)
                estimate_tile_error(part.color, halves, part.x0, part.y0, part.x1, part.y1, result.error_map);
            if (depth_output)
                resolve_view_depth(part.depth, part.x0, part.y0, part.x1, part.y1, clear_depth, decoder, result.depth);
        }
        done();
    });
    if (wide_resolve) resolve_framebuffer(kept, result.pattern, settings.resolve_filter, pool, result.color);
    add_counters(tile_counters, stats);
    if (settings.keep_samples) result.framebuffer = std::move(kept);
    if (settings.estimate_error) result.error_estimate = summarize_error_map(result.error_map);
    stats.raster_ms = ms_since(t0);
    stats.total_ms = ms_since(start);
    return result;
}

Visibility rasterize(const std::vector<glm::dvec4>& clip_positions, const std::vector<glm::uvec3>& triangles,
                     const RasterizeSettings& settings) {
    const auto start = Clock::now();
    // Validate everything before allocating anything large.
    validate_framebuffer_size(settings.width, settings.height, settings.samples, true);
    Visibility out;
    out.pattern = make_sample_pattern(settings.pattern, settings.samples, settings.pattern_seed);
    for (std::size_t i = 0; i < clip_positions.size(); ++i)
        for (int c = 0; c < 4; ++c)
            if (!std::isfinite(clip_positions[i][c]))
                throw std::invalid_argument("clip_positions[" + std::to_string(i) + "][" + std::to_string(c) + "] is " +
                                            std::to_string(clip_positions[i][c]) + "; expected a finite number");
    if (triangles.size() >= (std::size_t{1} << 31))
        throw std::invalid_argument("triangles: at most 2^31 - 1 triangles (ids are int32)");
    validate_triangle_indices(triangles, clip_positions.size(), "triangles");
    const int threads = resolve_thread_count(settings.threads);
    // Per sample: triangle id, two barycentrics and depth (4 bytes each).
    const std::uint64_t samples = std::uint64_t(settings.width) * std::uint64_t(settings.height) * settings.samples;
    check_memory(samples * 16 + geometry_bytes(clip_positions.size(), triangles.size()),
                 "rasterizing " + render_description(settings.width, settings.height, settings.samples));
    const LeasedPool leased = lease_thread_pool(threads);
    ThreadPool& pool = *leased;
    RenderStats& stats = out.stats;
    stats.threads = threads;

    // Stage 1: outcodes and screen positions of the given clip-space vertices.
    auto t0 = Clock::now();
    const ClipVolume volume = make_clip_volume(settings.depth_convention, settings.width, settings.height);
    const Viewport viewport = sample_viewport(settings.width, settings.height, settings.depth_convention, out.pattern);
    std::vector<ClipSpaceGeometry> geometry(1);
    ClipSpaceGeometry& g = geometry[0];
    resize_vertices(g, clip_positions.size());
    std::copy(clip_positions.begin(), clip_positions.end(), g.positions.begin());
    g.triangles = &triangles;
    g.cull = settings.cull;
    pool.parallel_for((clip_positions.size() + kVertexBlock - 1) / kVertexBlock, [&](std::size_t b) {
        classify_and_project(g, b * kVertexBlock, std::min((b + 1) * kVertexBlock, clip_positions.size()), volume,
                             viewport);
    });
    stats.transform_ms = ms_since(t0);

    // Stage 2: clip, set up and bin.
    t0 = Clock::now();
    const TileGrid grid = TileGrid::for_viewport(settings.width, settings.height);
    const std::vector<BinnedChunk> chunks = setup_and_bin(geometry, volume, viewport, grid, {}, pool, stats);
    stats.setup_ms = ms_since(t0);

    // Stage 3: every tile records the nearest triangle of each sample.
    t0 = Clock::now();
    const int S = settings.samples;
    const std::size_t n = static_cast<std::size_t>(settings.width) * settings.height * S;
    const bool opengl = settings.depth_convention == DepthConvention::opengl;
    out.width = settings.width;
    out.height = settings.height;
    out.samples = S;
    out.triangle_id.assign(n, -1);
    out.barycentrics.assign(2 * n, 0.0f);
    out.depth.assign(n, opengl ? 1.0f : 0.0f);
    PipelineKey key;
    key.depth = opengl ? DepthFunc::less : DepthFunc::greater;
    key.shading = Shading::visibility;
    key.samples = S == 1 ? SampleMode::single : SampleMode::ssaa;
    const std::vector<TileKernel> kernels = {select_tile_kernel(key)};
    const std::vector<DrawInputs> inputs = {{triangles.data(), nullptr, glm::vec4(1.0f), true}};
    std::vector<TileCounters> tile_counters(static_cast<std::size_t>(grid.count()));
    pool.parallel_for(static_cast<std::size_t>(grid.count()), [&](std::size_t tile) {
        TileTarget target = tile_target(grid, tile, out.pattern);
        target.depth = {out.depth.data(), 1, 0, 0, settings.width, S};
        target.triangle_ids = out.triangle_id.data();
        target.barycentrics = {out.barycentrics.data(), 2, 0, 0, settings.width, S};
        TileCounters counters;  // (stored once, as in render)
        rasterize_tile_chunks(tile, chunks, kernels, inputs, target, counters);
        tile_counters[tile] = counters;
    });
    add_counters(tile_counters, stats);
    stats.raster_ms = ms_since(t0);
    stats.total_ms = ms_since(start);
    return out;
}

std::string RasterizeSettings::to_string() const {
    return "RasterizeSettings(" + std::to_string(width) + "x" + std::to_string(height) + ", samples=" +
           std::to_string(samples) + ", pattern=" + mipraster::to_string(pattern) + ", depth=" +
           mipraster::to_string(depth_convention) + ", cull=" + mipraster::to_string(cull) + ", threads=" +
           std::to_string(threads) + ")";
}

std::string RenderSettings::to_string() const {
    return "RenderSettings(" + std::to_string(width) + "x" + std::to_string(height) + ", samples=" +
           std::to_string(samples) + ", pattern=" + mipraster::to_string(pattern) + ", aa=" +
           mipraster::to_string(anti_aliasing) + ", threads=" + std::to_string(threads) + ", resolve=" +
           mipraster::to_string(resolve_filter) + ", derivatives=" + mipraster::to_string(derivatives) +
           ", debug_view=" + mipraster::to_string(debug_view) +
           (estimate_error ? ", estimate_error" : "") + (block_skipping ? "" : ", no block skipping") +
           (sample_rows ? "" : ", no sample rows") +
           (deferred_shading ? "" : ", no deferred shading") + (batched_lookups ? "" : ", no batched lookups") +
           (tile_mask.empty() ? "" : ", tile_mask=" + std::to_string(tile_mask.size()) + " tiles") +
           (pixels.empty() ? "" : ", pixels=" + std::to_string(pixels.size())) + ")";
}

std::string RenderStats::to_json() const {
    auto field = [](const char* name, auto value, bool last = false) {
        std::string v;
        if constexpr (std::is_floating_point_v<decltype(value)>) {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%.3f", value);
            v = buf;
        } else {
            v = std::to_string(value);
        }
        return std::string("\"") + name + "\": " + v + (last ? "" : ", ");
    };
    return "{" + field("triangles_in", triangles_in) + field("triangles_clipped", triangles_clipped) +
           field("triangles_outside", triangles_outside) +
           field("triangles_between_samples", triangles_between_samples) +
           field("triangles_backface", triangles_backface) +
           field("triangles_degenerate", triangles_degenerate) + field("triangles_nonfinite", triangles_nonfinite) +
           field("triangles_rasterized", triangles_rasterized) + field("samples_covered", samples_covered) +
           field("samples_passed", samples_passed) + field("shader_invocations", shader_invocations) +
           field("depth_blocks_rejected", depth_blocks_rejected) + field("tiles_deferred", tiles_deferred) + field("tiles_empty", tiles_empty) + field("threads", threads) + field("transform_ms", transform_ms) + field("setup_ms", setup_ms) +
           field("raster_ms", raster_ms) + field("total_ms", total_ms, true) + "}";
}

std::string RenderStats::to_string() const {
    auto ms = [](double v) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.3f", v);
        return std::string(buf);
    };
    return "RenderStats(triangles_in=" + std::to_string(triangles_in) + ", clipped=" + std::to_string(triangles_clipped) +
           ", outside=" + std::to_string(triangles_outside) +
           ", between_samples=" + std::to_string(triangles_between_samples) +
           ", backface=" + std::to_string(triangles_backface) +
           ", degenerate=" + std::to_string(triangles_degenerate) + ", nonfinite=" + std::to_string(triangles_nonfinite) +
           ", rasterized=" + std::to_string(triangles_rasterized) + ", samples_covered=" + std::to_string(samples_covered) +
           ", samples_passed=" + std::to_string(samples_passed) + ", shader_invocations=" +
           std::to_string(shader_invocations) + ", depth_blocks_rejected=" + std::to_string(depth_blocks_rejected) +
           ", tiles_deferred=" + std::to_string(tiles_deferred) + ", tiles_empty=" + std::to_string(tiles_empty) +
           ", threads=" + std::to_string(threads) + ", transform_ms=" +
           ms(transform_ms) + ", setup_ms=" + ms(setup_ms) + ", raster_ms=" + ms(raster_ms) +
           ", total_ms=" + ms(total_ms) + ")";
}

}  // namespace mipraster
