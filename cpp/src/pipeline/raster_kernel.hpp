#pragma once
// The tile kernel template (private to the pipeline): edge functions stepped over the samples of a
// tile, depth test, shading and blending, specialized at compile time on a PipelineKey. Each kind
// of texturing is instantiated in its own source file so they compile in parallel.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include "mipraster/core/constants.hpp"
#include "mipraster/pipeline/alpha_test.hpp"
#include "mipraster/pipeline/blend.hpp"
#include "mipraster/pipeline/interpolate.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/texture/sample.hpp"
#include "interpolate_batch.hpp"
#include "lookup_queue.hpp"
#include "pixel_samples.hpp"
#include "sample_row.hpp"
#include "sample_shading.hpp"
#include "tile_blocks.hpp"

namespace mipraster {
namespace kernels {

template <DepthFunc kDepth>
inline bool depth_passes(float z, float stored) {
    if constexpr (kDepth == DepthFunc::greater) return z > stored;
    else if constexpr (kDepth == DepthFunc::less) return z < stored;
    else return true;
}

// Shades samples `samples` of one pixel (colour slots at `target`) with one colour: through the
// lookup queue when there is one (textured draws), else at once.
template <BlendMode kBlend, Shading kShading, Texturing kTexturing>
inline void shade_into(LookupQueue<kBlend, kShading, kTexturing>* queue, float* target, std::uint64_t samples,
                       const DrawInputs& draw, const VertexValues& colors, const TriangleUvs& uvs, const SetupTriangle& t,
                       const glm::dvec3& screen, const ClipWeights* clip_weights, int px, int py) {
    if constexpr (kTexturing != Texturing::none) {
        if (queue) {
            queue->push(target, samples, screen, px, py);
            return;
        }
    }
    const glm::vec4 c = shade<kShading, kTexturing>(draw, colors, uvs, t, screen, clip_weights, px, py);
    blend_into_samples<kBlend>(target, samples, c);
}

// Untextured screen or perspective shading: deferred shading's runs of pixels are coloured a batch
// at a time (interpolate_colours), and a triangle of one colour takes it without the sums. (Constant
// and flat colours cost nothing to shade.)
template <Shading kShading, Texturing kTexturing>
inline constexpr bool kInterpolatedColours =
    kTexturing == Texturing::none && (kShading == Shading::screen || kShading == Shading::perspective);

// Shades and blends pixels `passed` of a row of unclipped triangle t (bit j: screen weights l0[j],
// l1[j], l2[j], the colour slot at target + stride·j, floats), kLookupBatch at a time: the bits
// shade_into gives them one by one. `shading`: batch_shading of the triangle's colours.
template <BlendMode kBlend>
void shade_row_colours(float* target, int stride, std::uint32_t passed, const double* l0, const double* l1,
                       const double* l2, const DrawInputs& draw, Shading shading, const VertexValues& colors,
                       const SetupTriangle& t) {
    BatchWeights w;
    glm::vec4 colour[kLookupBatch];
    int pixel[kLookupBatch];
    while (passed) {
        int n = 0;
        for (; passed && n < kLookupBatch; passed &= passed - 1, ++n) {
            const int j = __builtin_ctz(passed);
            pixel[n] = j;
            w.l0[n] = l0[j], w.l1[n] = l1[j], w.l2[n] = l2[j];
        }
        w.count = n;
        interpolate_colours(draw, shading, t, colors, w, colour);
        for (int i = 0; i < n; ++i) blend_into<kBlend>(target + stride * pixel[i], colour[i]);
    }
}

// True when a draw's texture lookups go through the BatchSampler (debug views never do): the lookup
// queue's, or for an alpha-tested draw alpha_tested_triangle's (the queue shades after the depth
// writes).
template <Texturing kTexturing>
inline bool batches_lookups(const DrawInputs& draw) {
    return kTexturing != Texturing::none && draw.batched_lookups && draw.debug_view == DebugView::none;
}
template <Texturing kTexturing>
inline bool queues_lookups(const DrawInputs& draw) {
    return batches_lookups<kTexturing>(draw) && !draw.alpha_cutoff;
}

// Triangle t of an alpha-tested draw (DrawInputs::alpha_cutoff) over pixels [x0, x1) × [y0, y1) of
// the tile: each covered sample depth-tested, shaded (MSAA once per pixel, at its centre when that
// is inside the triangle, else at its first sample that passed; else each sample), alpha-tested,
// and only then its depth and colour written. Every other path writes depth as it tests it; a
// branch for alpha testing inside their loops cost the other draws 3–5 % of the kernel's
// instructions (many_small MSAA 4x), so alpha-tested triangles take this one. Blocks are skipped
// as `cls` (the triangle's TileBlocks classes) says; long depth-tested rows are tested a vector at
// a time without writing depth (test_sample_row, test_pixel_row_avx2: the per-sample path's
// bits), the others sample by sample.
// With `sampler` (a textured draw with batched lookups), shades go kLookupBatch at a time through
// interpolate_batch and the BatchSampler, as the lookup queue sends them: the bits of the same draw
// without a cutoff; they wait within the triangle only, whose samples are all distinct.
template <DepthFunc kDepth, BlendMode kBlend, Shading kShading, SampleMode kMode, Texturing kTexturing>
[[gnu::noinline]] void alpha_tested_triangle(const TileTarget& target, const DrawInputs& draw, const SetupTriangle& t,
                                             const ClipWeights* clip_weights, int x0, int y0, int x1, int y1,
                                             const BlockClasses& cls, BatchSampler* sampler, TileBlocks& blocks,
                                             TileCounters& counters) {
    const SamplePattern& pattern = *target.pattern;
    const int S = kMode == SampleMode::single ? 1 : pattern.count();
    constexpr std::int64_t kStep = kSubpixelOne;
    const glm::uvec3 tri = draw.triangles[t.triangle];
    VertexValues colors{};
    if constexpr (kShading == Shading::flat || kShading == Shading::screen || kShading == Shading::perspective)
        colors = VertexValues(draw.vertex_colors[tri[0]], draw.vertex_colors[tri[1]], draw.vertex_colors[tri[2]]);
    TriangleUvs uvs;
    if constexpr (kTexturing != Texturing::none) uvs = TriangleUvs(t, tri, draw.uvs, clip_weights);
    std::int64_t off[3][kMaxSamples];  // edge offsets of each sample from its pixel's corner
    double offsets[3][kMaxSamples];    // (the same, as test_pixel_row_avx2 takes them)
    for (int s = 0; s < S; ++s)
        for (int i = 0; i < 3; ++i) {
            off[i][s] = std::int64_t{t.edge_a[i]} * pattern.x[s] + std::int64_t{t.edge_b[i]} * pattern.y[s];
            offsets[i][s] = static_cast<double>(off[i][s]);
        }
    // Edge values at the top-left corner of pixel (px, py), exact in int64.
    const auto corner = [&](int px, int py, std::int64_t (&p)[3]) {
        const std::int64_t X = std::int64_t{px} * kStep, Y = std::int64_t{py} * kStep;
        for (int i = 0; i < 3; ++i) p[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
    };
    const auto weights_at = [&](const std::int64_t (&p)[3], int s) {
        return screen_weights(t, p[0] + off[0][s], p[1] + off[1][s], p[2] + off[2][s]);
    };

    // Samples `samples` of pixel (px, py), shaded at screen weights l with colour c: discarded, or
    // counted as passed, their colour written and (depth_write) the depths their tests computed:
    // from l where it is the sample's own (one sample shaded), else (MSAA, depth-tested) as the
    // tests kept them, sample s's at depths[s].
    const auto test_and_write = [&](int px, int py, std::uint64_t samples, const glm::dvec3& l, glm::vec4 c,
                                    const float* depths) {
        if (!alpha_test(c, *draw.alpha_cutoff)) return;
        if constexpr (kDepth != DepthFunc::none) blocks.written(px, py);
        if constexpr (kMode != SampleMode::msaa) {
            const int s = __builtin_ctzll(samples);  // (the only one)
            ++counters.samples_passed;
            if (kDepth != DepthFunc::none && draw.depth_write) *target.depth.at(px, py, s) = sample_depth(t, l);
            return blend_into<kBlend>(target.color.at(px, py, s), c);
        }
        counters.samples_passed += static_cast<std::uint64_t>(count_bits(samples));  // (as GL counts them)
        if (kDepth != DepthFunc::none && draw.depth_write) {
            float* const depth_px = target.depth.at(px, py, 0);
            for (std::uint64_t m = samples; m; m &= m - 1) depth_px[__builtin_ctzll(m)] = depths[__builtin_ctzll(m)];
        }
        float* const color_px = target.color.at(px, py, 0);
        blend_into_samples<kBlend>(color_px, samples, c);
    };
    // The shades waiting for a batch (with `sampler`): pixel and samples (screen weights in `weights`;
    // MSAA with a depth test: the samples' tested depths in waiting_depths).
    struct Waiting {
        int px, py;
        std::uint64_t samples;
    };
    constexpr bool kKeepsDepths = kMode == SampleMode::msaa && kDepth != DepthFunc::none;
    BatchWeights weights;
    Waiting waiting[kLookupBatch];
    float waiting_depths[kKeepsDepths ? kLookupBatch : 1][kMaxSamples];
    LookupBatch lookups;
    const bool batched = sampler && interpolates_in_batches(draw, kShading, kTexturing, t);
    const Shading shading = batch_shading(kShading, colors);
    const auto shade_waiting = [&] {
        const int n = weights.count;
        if (!n) return;
        glm::vec4 colour[kLookupBatch], texel[kLookupBatch];
        if (batched) {
            interpolate_batch(draw, shading, kTexturing, t, colors, uvs, weights, colour, lookups);
        } else {  // (as the lookup queue: interpolated one by one, looked up at once)
            for (int i = 0; i < n; ++i) {
                const glm::dvec3 l(weights.l0[i], weights.l1[i], weights.l2[i]);
                colour[i] = untextured_colour<kShading>(draw, colors, t, l, clip_weights);
                const UvSample u = texture_lookup<kTexturing>(draw, t, uvs, l, waiting[i].px, waiting[i].py);
                lookups.set(i, glm::vec2(u.uv), glm::vec2(u.dx), glm::vec2(u.dy));
            }
            lookups.count = n;
        }
        sampler->sample(lookups, texel);
        for (int i = 0; i < n; ++i)
            test_and_write(waiting[i].px, waiting[i].py, waiting[i].samples,
                           glm::dvec3(weights.l0[i], weights.l1[i], weights.l2[i]), colour[i] * texel[i],
                           kKeepsDepths ? waiting_depths[i] : nullptr);
        weights.count = 0;
    };
    // Shades samples `samples` of pixel (px, py) at screen weights l (MSAA, depth-tested: their
    // tested depths at depths[s]).
    const auto shade_samples = [&](int px, int py, std::uint64_t samples, const glm::dvec3& l,
                                   const float* depths = nullptr) {
        ++counters.shader_invocations;
        if (!sampler) {
            const glm::vec4 c = shade<kShading, kTexturing>(draw, colors, uvs, t, l, clip_weights, px, py);
            test_and_write(px, py, samples, l, c, depths);
            return;
        }
        const int i = weights.count++;
        weights.l0[i] = l.x, weights.l1[i] = l.y, weights.l2[i] = l.z;
        waiting[i] = {px, py, samples};
        if constexpr (kKeepsDepths) std::memcpy(waiting_depths[i], depths, sizeof(float) * S);
        if (weights.count == kLookupBatch) shade_waiting();
    };
    // MSAA shades samples `passed` of pixel (px, py), whose corner has edge values p, once (with a
    // depth test: their tested depths at depths[s]).
    const auto shade_pixel = [&](int px, int py, std::uint64_t passed, const std::int64_t (&p)[3],
                                 const float* depths) {
        const std::int64_t c0 = p[0] + (std::int64_t{t.edge_a[0]} + t.edge_b[0]) * (kStep / 2);
        const std::int64_t c1 = p[1] + (std::int64_t{t.edge_a[1]} + t.edge_b[1]) * (kStep / 2);
        const std::int64_t c2 = p[2] + (std::int64_t{t.edge_a[2]} + t.edge_b[2]) * (kStep / 2);
        shade_samples(px, py, passed,
                      (c0 | c1 | c2) >= 0 ? screen_weights(t, c0, c1, c2) : weights_at(p, __builtin_ctzll(passed)),
                      depths);
    };

    // A long depth-tested row of pixels [rx0, rx0 + n), tested a vector at a time: false (nothing
    // done) where the vectors' sums could round, or under MSAA where a block is classified.
    const std::uint32_t classified = cls.skipped | cls.hidden;
    const auto vector_row = [&](int rx0, int py, int n) {
        if constexpr (kDepth == DepthFunc::none) {
            return false;
        } else {
            if (!target.sample_rows || n < kSampleRowMinPixels) return false;
            std::int64_t row[3];
            corner(rx0, py, row);
            if (kMode != SampleMode::single && !sample_rows_exact(t, row, n)) return false;
            if constexpr (kMode == SampleMode::msaa) {
                if (S % 4 != 0 || BatchSampler::widest_vector() != 8 || blocks.row_pixels(classified, py, rx0, n))
                    return false;
                std::uint64_t samples[kTileSize];
                float depths[kTileSize * kMaxSamples];  // (the write takes them, not computes them again)
                const double* const by_sample[3] = {offsets[0], offsets[1], offsets[2]};
                counters.samples_covered += test_pixel_row_avx2(t, row, n, by_sample, S, kDepth, false,
                                                                target.depth.at(rx0, py, 0), samples, depths)
                                                .covered;
                for (int j = 0; j < n; ++j) {
                    if (!samples[j]) continue;
                    std::int64_t p[3];
                    for (int i = 0; i < 3; ++i) p[i] = row[i] + j * std::int64_t{t.edge_a[i]} * kStep;
                    shade_pixel(rx0 + j, py, samples[j], p, depths + j * S);
                }
            } else {
                const std::uint32_t skipped = blocks.row_pixels(cls.skipped, py, rx0, n);
                const std::uint32_t untested = skipped | blocks.row_pixels(cls.hidden, py, rx0, n);
                for (int s = 0; s < S; ++s) {
                    const std::int64_t e[3] = {row[0] + off[0][s], row[1] + off[1][s], row[2] + off[2][s]};
                    SampleRow r;
                    if (!test_sample_row(t, e, n, ~untested, kDepth, false, target.depth.at(rx0, py, s), S, r))
                        return false;  // (one sample: nothing done yet)
                    counters.samples_covered += static_cast<std::uint64_t>(count_bits(r.covered & ~skipped));
                    for (std::uint32_t m = r.passed; m; m &= m - 1) {
                        const int j = __builtin_ctz(m);
                        shade_samples(rx0 + j, py, std::uint64_t{1} << s, glm::dvec3(r.l0[j], r.l1[j], r.l2[j]));
                    }
                }
            }
            return true;
        }
    };

    for (int py = y0; py < y1; ++py) {
        int rx0 = x0, rx1 = x1;  // the row without skipped blocks at its ends
        blocks.trim(cls.skipped, py, rx0, rx1);
        if (rx0 >= rx1 || vector_row(rx0, py, rx1 - rx0)) continue;
        for (int px = rx0; px < rx1; ++px) {
            std::int64_t p[3];
            corner(px, py, p);
            std::uint64_t covered = 0;
            for (int s = 0; s < S; ++s) {
                const std::int64_t signs = (p[0] + off[0][s]) | (p[1] + off[1][s]) | (p[2] + off[2][s]);
                covered |= static_cast<std::uint64_t>(signs >= 0) << s;
            }
            if (!covered) continue;
            if (classified && (classified >> blocks.bit(px, py) & 1)) {  // counted, not tested
                if (cls.hidden >> blocks.bit(px, py) & 1)
                    counters.samples_covered += static_cast<std::uint64_t>(count_bits(covered));
                continue;
            }
            counters.samples_covered += static_cast<std::uint64_t>(count_bits(covered));
            std::uint64_t passed = covered;
            float tested[kMaxSamples];  // (MSAA writes the passing ones after the alpha test)
            if constexpr (kDepth != DepthFunc::none) {
                const float* const stored = target.depth.at(px, py, 0);
                for (std::uint64_t m = covered; m; m &= m - 1) {
                    const int s = __builtin_ctzll(m);
                    tested[s] = sample_depth(t, weights_at(p, s));
                    if (!depth_passes<kDepth>(tested[s], stored[s])) passed &= ~(std::uint64_t{1} << s);
                }
            }
            if (!passed) continue;
            if constexpr (kMode == SampleMode::msaa) {
                shade_pixel(px, py, passed, p, kDepth != DepthFunc::none ? tested : nullptr);
            } else {
                for (std::uint64_t m = passed; m; m &= m - 1) {
                    const int s = __builtin_ctzll(m);
                    shade_samples(px, py, std::uint64_t{1} << s, weights_at(p, s));
                }
            }
        }
    }
    shade_waiting();
}

template <DepthFunc kDepth, BlendMode kBlend, Shading kShading, SampleMode kMode, Texturing kTexturing>
void raster_tile(const TileTarget& target, const DrawInputs& draw, const TriangleBatch& batch,
                 TileCounters& counters) {
    const SampleWindow color_out = target.color;  // (copies: fields no store through a float* can change)
    const SampleWindow depth_out = target.depth;
    const SamplePattern& pattern = *target.pattern;
    const int S = kMode == SampleMode::single ? 1 : pattern.count();
    constexpr std::int64_t kStep = kSubpixelOne;  // one pixel in fixed point
    const std::int64_t sample_x = pattern.x[0], sample_y = pattern.y[0];  // (sample 0's offsets)
    TileBlocks blocks(target, S);
    // Coverage masks four samples per vector (pixel_coverage_avx2; also MSAA's depth tests,
    // pixel_vectors below).
    const bool vector_masks = target.sample_rows && S % 4 == 0 && BatchSampler::widest_vector() == 8;
    // Small triangles' pixels at one sample a pixel, and with several samples where the vector
    // masks are, found a box at a time (box_coverage_avx2, box_sample_masks_avx2).
    const bool box_rows = target.sample_rows && BatchSampler::widest_vector() == 8 &&
                          (kMode == SampleMode::single || vector_masks);
    std::optional<LookupQueue<kBlend, kShading, kTexturing>> queue;
    if (queues_lookups<kTexturing>(draw)) queue.emplace(draw);
    // An alpha-tested draw's batched lookups (alpha_tested_triangle), where a draw without a cutoff
    // would queue them.
    std::optional<BatchSampler> alpha_sampler;
    if (batches_lookups<kTexturing>(draw) && draw.alpha_cutoff) alpha_sampler.emplace(*draw.texture, *draw.sampler);

    for (std::size_t k = 0; k < batch.count; ++k) {
        const SetupTriangle& t = batch.tris[batch.indices[k]];
        // The set-up record (two cache lines) of the triangle four ahead: a small triangle takes
        // less time than its record takes to come from memory.
        if (k + 4 < batch.count) {
            const char* ahead = reinterpret_cast<const char*>(&batch.tris[batch.indices[k + 4]]);
            __builtin_prefetch(ahead);
            __builtin_prefetch(ahead + 64);
        }
        const int x0 = std::max(t.min_x, target.x0), x1 = std::min(t.max_x + 1, target.x1);
        const int y0 = std::max(t.min_y, target.y0), y1 = std::min(t.max_y + 1, target.y1);
        if (x0 >= x1 || y0 >= y1) continue;
        // Blocks with nothing to do, and blocks whose depth tests would all fail (tile_blocks.hpp).
        BlockClasses cls;
        if (target.block_skipping) {
            cls = blocks.classify<kDepth>(t, x0, y0, x1, y1, S);
            counters.samples_covered += cls.skipped_samples;
            counters.depth_blocks_rejected += static_cast<std::uint64_t>(cls.depth_rejected);
            if (cls.skipped && cls.skipped == blocks.blocks_in(x0, y0, x1, y1)) continue;  // every row would trim to nothing
        }
        if constexpr (kShading != Shading::visibility) {  // (deferred shading never takes alpha-tested draws)
            if (draw.alpha_cutoff) {
                alpha_tested_triangle<kDepth, kBlend, kShading, kMode, kTexturing>(
                    target, draw, t, batch.clip_weights, x0, y0, x1, y1, cls,
                    alpha_sampler ? &*alpha_sampler : nullptr, blocks, counters);
                continue;
            }
        }
        // Most small triangles classify no block: they skip the per-pixel block test.
        const std::uint32_t classified = cls.skipped | cls.hidden;

        // The vertex colours of the original triangle, once per triangle and tile (constant shading:
        // unused, zeros).
        constexpr bool kVertexColours =
            kShading == Shading::flat || kShading == Shading::screen || kShading == Shading::perspective;
        const VertexValues colors = [&] {
            if constexpr (kVertexColours) {
                const glm::uvec3 tri = draw.triangles[t.triangle];
                return VertexValues(draw.vertex_colors[tri[0]], draw.vertex_colors[tri[1]], draw.vertex_colors[tri[2]]);
            }
            return VertexValues{};
        }();
        // Untextured screen or perspective shading of three equal vertex colours (VertexValues::one):
        // every sample's colour is flat's, the same bits, without its weights and sums.
        std::optional<glm::vec4> one_colour;
        if constexpr (kInterpolatedColours<kShading, kTexturing>)
            if (t.clip_index < 0 && colors.one)
                one_colour = untextured_colour<Shading::flat>(draw, colors, t, glm::dvec3(0.0), batch.clip_weights);
        TriangleUvs uvs;
        if constexpr (kTexturing != Texturing::none) {
            uvs = TriangleUvs(t, draw.triangles[t.triangle], draw.uvs, batch.clip_weights);
            if (queue) {
                queue->begin_triangle(t, colors, uvs, batch.clip_weights);
                // Its texels in this tile, asked for as it starts; not for a triangle behind what is
                // drawn in some of its blocks, which reads few (overdraw MSAA 4x: 8 % of the frame
                // went to such prefetches).
                if (!cls.hidden) queue->prefetch_area(t, uvs, target.x0, target.y0, target.x1, target.y1);
            }
        }
        // Deferred shading's pre-pass: the samples this triangle wins name it by this index.
        std::int32_t owner = -1;
        if constexpr (kShading == Shading::visibility) {
            if (target.owners) {
                owner = static_cast<std::int32_t>(target.owner_refs->size());
                target.owner_refs->push_back({&t, batch.clip_weights});
            }
        }

        // Edge offsets of each sample from its pixel's corner: a·ox + b·oy. (At one sample a pixel,
        // after the box path below, which needs none: many_small 1x spent 27 instructions of a
        // small triangle's 560 in a tile on them.)
        std::int64_t off0[kMaxSamples], off1[kMaxSamples], off2[kMaxSamples];
        const auto sample_offsets = [&] {
            if (vector_masks) {
                sample_offsets_avx2(t, pattern.x.data(), pattern.y.data(), S, {off0, off1, off2});
                return;
            }
            for (int s = 0; s < S; ++s) {
                off0[s] = std::int64_t{t.edge_a[0]} * pattern.x[s] + std::int64_t{t.edge_b[0]} * pattern.y[s];
                off1[s] = std::int64_t{t.edge_a[1]} * pattern.x[s] + std::int64_t{t.edge_b[1]} * pattern.y[s];
                off2[s] = std::int64_t{t.edge_a[2]} * pattern.x[s] + std::int64_t{t.edge_b[2]} * pattern.y[s];
            }
        };
        if constexpr (kMode != SampleMode::single) sample_offsets();
        const std::int64_t step0 = t.edge_a[0] * kStep, step1 = t.edge_a[1] * kStep, step2 = t.edge_a[2] * kStep;
        // Edge offsets of a pixel's centre from its corner (MSAA shades there when it is inside).
        const std::int64_t to_centre0 = (std::int64_t{t.edge_a[0]} + t.edge_b[0]) * (kStep / 2);
        const std::int64_t to_centre1 = (std::int64_t{t.edge_a[1]} + t.edge_b[1]) * (kStep / 2);
        const std::int64_t to_centre2 = (std::int64_t{t.edge_a[2]} + t.edge_b[2]) * (kStep / 2);
        // MSAA with a depth test: the samples of a pixel the triangle covers whole tested four per
        // vector (pixel_samples.hpp). Pixels on its edges, with a few samples covered, and the
        // pixels of small triangles take less time one sample at a time (many_small MSAA 4x was
        // 12 % slower when every pixel took the vectors).
        const std::uint64_t all_samples = S == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << S) - 1;
        double offset0[kMaxSamples], offset1[kMaxSamples], offset2[kMaxSamples];
        const bool pixel_vectors = kMode == SampleMode::msaa && kDepth != DepthFunc::none && vector_masks;
        if (pixel_vectors)
            for (int s = 0; s < S; ++s)
                offset0[s] = static_cast<double>(off0[s]), offset1[s] = static_cast<double>(off1[s]),
                offset2[s] = static_cast<double>(off2[s]);

        // A sample s of pixel (px, py) at screen weights l that passed the depth test (stored; the
        // caller tells `blocks`). color_px: the pixel's colour slots (colour_slots).
        const auto colour_slots = [&](int px, int py) {
            return kShading == Shading::visibility ? nullptr : color_out.at(px, py, 0);
        };
        const auto passed_sample = [&](float* color_px, int px, int py, int s, const glm::dvec3& l) {
            ++counters.samples_passed;
            if constexpr (kShading == Shading::visibility) {
                if (target.owners) {
                    target.owners[target.owner_index(px, py, s, S)] = owner;
                    return;
                }
                const glm::dvec3 w = original_weights(t, perspective_weights(t, l), batch.clip_weights);
                const std::size_t i = target.barycentrics.index(px, py, s);
                target.triangle_ids[i] = static_cast<std::int32_t>(t.triangle);
                target.barycentrics.data[2 * i] = static_cast<float>(w.y);
                target.barycentrics.data[2 * i + 1] = static_cast<float>(w.z);
            } else {
                ++counters.shader_invocations;
                if (one_colour) return blend_into<kBlend>(color_px + 4 * s, *one_colour);
                shade_into<kBlend, kShading, kTexturing>(queue ? &*queue : nullptr, color_px + 4 * s, std::uint64_t{1},
                                                         draw, colors, uvs, t, l, batch.clip_weights, px, py);
            }
        };

        // The samples `covered` of pixel (px, py), whose corner has edge values p0, p1, p2, one by
        // one: each that passes the depth test is shaded. depth_px, color_px: the pixel's slots.
        // (This and msaa_pixel are always inlined: called from two places, GCC made them functions
        // reading their captures through memory, +11 % instructions in many_small MSAA 4x.)
        const auto shade_samples = [&](int px, int py, std::int64_t p0, std::int64_t p1, std::int64_t p2,
                                       std::uint64_t covered, float* depth_px,
                                       float* color_px) __attribute__((always_inline)) {
            bool written = false;
            for (; covered; covered &= covered - 1) {
                const int s = __builtin_ctzll(covered);
                ++counters.samples_covered;
                const std::int64_t e0 = p0 + off0[s], e1 = p1 + off1[s], e2 = p2 + off2[s];
                glm::dvec3 l(0.0);
                if constexpr (kDepth != DepthFunc::none || kShading == Shading::screen ||
                              kShading == Shading::perspective || kShading == Shading::visibility ||
                              kTexturing != Texturing::none)
                    l = screen_weights(t, e0, e1, e2);
                if constexpr (kDepth != DepthFunc::none) {
                    const float z = sample_depth(t, l);
                    if (!depth_passes<kDepth>(z, depth_px[s])) continue;
                    if (draw.depth_write) depth_px[s] = z;
                    written = true;
                }
                passed_sample(color_px, px, py, s, l);
            }
            if (written) blocks.written(px, py);
        };

        // The passed pixels of a row's sample s (bit j: pixel rx0 + j) at once, as passed_sample takes
        // them one by one: for queued lookups and the deferred pre-pass's owners (false: neither).
        const auto passed_row = [&](int rx0, int py, int s, const SampleRow& row) {
            if constexpr (kShading == Shading::visibility) {
                if (!target.owners) return false;
            } else if (!queue) {
                return false;
            }
            if constexpr (kDepth != DepthFunc::none) blocks.written_row(py, rx0, row.passed);
            const auto passed = static_cast<std::uint64_t>(count_bits(row.passed));
            counters.samples_passed += passed;
            if constexpr (kShading == Shading::visibility) {
                std::int32_t* const owners = target.owners + target.owner_index(rx0, py, s, S);
                for (std::uint32_t m = row.passed; m; m &= m - 1) owners[__builtin_ctz(m) * S] = owner;
            } else {
                counters.shader_invocations += passed;
                queue->push_row(color_out.at(rx0, py, s), 4 * S, row.passed, row.l0, row.l1, row.l2, rx0, py);
            }
            return true;
        };

        // Deferred shading's MSAA pre-pass: samples `passed` of pixel (px, py) name this triangle
        // their owner, with where it would shade the pixel (shade_owned shades there).
        const auto record_owner = [&](int px, int py, std::uint64_t passed, bool at_centre) {
            const std::size_t first = target.owner_index(px, py, 0, S);
            const auto at = static_cast<std::uint8_t>(at_centre ? kShadeAtCentre : __builtin_ctzll(passed));
            if (passed == 0xF) {  // (MSAA 4x, a pixel won whole, as most are: a store each, not a loop)
                const std::int32_t owners[4] = {owner, owner, owner, owner};
                const std::uint32_t places = at * 0x01010101u;
                std::memcpy(target.owners + first, owners, sizeof owners);
                std::memcpy(target.owner_shade_at + first, &places, sizeof places);
                return;
            }
            for (std::uint64_t m = passed; m; m &= m - 1) {
                target.owners[first + __builtin_ctzll(m)] = owner;
                target.owner_shade_at[first + __builtin_ctzll(m)] = at;
            }
        };

        // Under MSAA, the samples `covered` of pixel (px, py), whose corner has edge values p0, p1,
        // p2: depth per sample, colour once per pixel, at the pixel centre when it is inside the
        // triangle, else at the first covered sample that passed (never extrapolated).
        const auto msaa_pixel = [&](int px, int py, std::int64_t p0, std::int64_t p1, std::int64_t p2,
                                    std::uint64_t covered, float* depth_px) __attribute__((always_inline)) {
            float* const color_px = kShading == Shading::visibility ? nullptr : color_out.at(px, py, 0);
            std::uint64_t passed = 0;
            if (pixel_vectors && covered == all_samples &&
                test_pixel_samples_avx2(t, {p1, p2, offset1, offset2, S}, covered, kDepth, draw.depth_write,
                                        depth_px, passed)) {
                counters.samples_covered += static_cast<std::uint64_t>(count_bits(covered));
                covered = 0;  // (all tested)
            }
            for (std::uint64_t m = covered; m; m &= m - 1) {
                const int s = __builtin_ctzll(m);
                ++counters.samples_covered;
                if constexpr (kDepth != DepthFunc::none) {
                    const float z = sample_depth(t, screen_weights(t, p0 + off0[s], p1 + off1[s], p2 + off2[s]));
                    if (!depth_passes<kDepth>(z, depth_px[s])) continue;
                    if (draw.depth_write) depth_px[s] = z;
                }
                passed |= std::uint64_t{1} << s;
            }
            if (!passed) return;
            if constexpr (kDepth != DepthFunc::none) blocks.written(px, py);
            counters.samples_passed += static_cast<std::uint64_t>(count_bits(passed));
            const bool at_centre = ((p0 + to_centre0) | (p1 + to_centre1) | (p2 + to_centre2)) >= 0;
            if constexpr (kShading == Shading::visibility) {
                record_owner(px, py, passed, at_centre);  // (the shade below, deferred)
            } else {
                ++counters.shader_invocations;
                if (one_colour) return blend_into_samples<kBlend>(color_px, passed, *one_colour);
                glm::dvec3 l(0.0);  // (unused by constant and flat untextured shading)
                if constexpr (!((kShading == Shading::constant || kShading == Shading::flat) &&
                                kTexturing == Texturing::none)) {
                    std::int64_t c0 = p0 + to_centre0, c1 = p1 + to_centre1, c2 = p2 + to_centre2;
                    if (!at_centre) {
                        const int s = __builtin_ctzll(passed);
                        c0 = p0 + off0[s];
                        c1 = p1 + off1[s];
                        c2 = p2 + off2[s];
                    }
                    l = screen_weights(t, c0, c1, c2);
                }
                shade_into<kBlend, kShading, kTexturing>(queue ? &*queue : nullptr, color_px, passed, draw,
                                                         colors, uvs, t, l, batch.clip_weights, px, py);
            }
        };

        // A long MSAA row of pixels rx0 … rx0 + n − 1 whose first pixel's corner has edge values
        // `corner`, where sample_rows_exact holds and no block is skipped or hidden. Each pixel is
        // shaded once (or, in the pre-pass, its owner recorded), at its centre when that is inside
        // the triangle, else at its first sample that passed.
        const auto msaa_row = [&](int rx0, int py, int n, const std::int64_t (&corner)[3]) {
            std::uint64_t samples[kTileSize];  // per pixel, the samples that passed
            std::uint32_t pixels = 0;
            std::uint64_t found_passed = 0;  // how many samples passed
            if constexpr (kDepth == DepthFunc::none) {  // (every covered sample passes)
                pixel_coverage_avx2(corner, {off0, off1, off2}, {step0, step1, step2}, n, S, samples);
                std::uint64_t covered = 0;
                for (int j = 0; j < n; ++j) {
                    covered += static_cast<std::uint64_t>(count_bits(samples[j]));
                    pixels |= static_cast<std::uint32_t>(samples[j] != 0) << j;
                }
                counters.samples_covered += covered;
                counters.samples_passed += covered;
                found_passed = covered;
                if (!pixels) return;
            } else {
                const double* const offsets[3] = {offset0, offset1, offset2};
                const PixelRowTest found = test_pixel_row_avx2(t, corner, n, offsets, S, kDepth, draw.depth_write,
                                                               depth_out.at(rx0, py, 0), samples);
                counters.samples_covered += found.covered;
                counters.samples_passed += found.passed;
                found_passed = found.passed;
                pixels = found.pixels;
                if (!pixels) return;
                blocks.written_row(py, rx0, pixels);
            }
            const std::int64_t centre[3] = {corner[0] + to_centre0, corner[1] + to_centre1, corner[2] + to_centre2};
            const std::uint32_t centres = row_coverage_avx2(centre, {step0, step1, step2}, n);  // bit j: inside
            if constexpr (kShading == Shading::visibility) {
                // A row won whole, every pixel at its centre (most rows of a large triangle): its
                // owners and places are one run each (pixel by pixel, 28 instructions a pixel).
                const std::uint32_t row = ~std::uint32_t{0} >> (32 - n);
                if (centres == row && found_passed == static_cast<std::uint64_t>(n) * S) {
                    const std::size_t first = target.owner_index(rx0, py, 0, S);
                    const auto count = static_cast<std::size_t>(S) * static_cast<std::size_t>(n);
                    std::fill_n(target.owners + first, count, owner);
                    std::memset(target.owner_shade_at + first, kShadeAtCentre, count);
                    return;
                }
                for (std::uint32_t m = pixels; m; m &= m - 1) {
                    const int j = __builtin_ctz(m);
                    record_owner(rx0 + j, py, samples[j], centres >> j & 1);
                }
                return;
            }
            counters.shader_invocations += static_cast<std::uint64_t>(count_bits(pixels));
            double l0[kTileSize], l1[kTileSize], l2[kTileSize];
            sample_row_weights(t, centre, n, l0, l1, l2);  // (exact: the centres lie within the row's pixels)
            for (std::uint32_t m = pixels & ~centres; m; m &= m - 1) {  // the others shade at a passed sample
                const int j = __builtin_ctz(m);
                const int s = __builtin_ctzll(samples[j]);
                const glm::dvec3 l = screen_weights(t, corner[0] + j * step0 + off0[s], corner[1] + j * step1 + off1[s],
                                                    corner[2] + j * step2 + off2[s]);
                l0[j] = l.x, l1[j] = l.y, l2[j] = l.z;
            }
            queue->push_row(color_out.at(rx0, py, 0), 4 * S, pixels, l0, l1, l2, rx0, py, samples);
        };

        // A triangle narrower than a sample row with no block classified (most of many_small's):
        // the coverage of its whole box at once, then its covered pixels in the order of the rows
        // below, without their rows' set-up or the tests of the pixels it misses (box_coverage_avx2
        // at one sample: many_small 1x, a third of the kernel's instructions; box_sample_masks_avx2
        // with four samples a vector: many_small SSAA 4x −8 %, MSAA 4x −9 %).
        if (box_rows && !classified && x1 - x0 < kSampleRowMinPixels) {
            // Edge values at the corner of pixel (x0, y0) (at one sample a pixel, at its sample: the
            // corner's plus the sample's offset, the same integers), and the pixel's slots: the
            // per-sample path's integers, and addresses from the windows' fields read once.
            const bool at_sample = kMode == SampleMode::single;
            const std::int64_t X = std::int64_t{x0} * kStep + (at_sample ? sample_x : 0);
            const std::int64_t Y = std::int64_t{y0} * kStep + (at_sample ? sample_y : 0);
            std::int64_t e[3] = {t.edge_a[0] * X + t.edge_b[0] * Y + t.edge_c[0],
                                 t.edge_a[1] * X + t.edge_b[1] * Y + t.edge_c[1],
                                 t.edge_a[2] * X + t.edge_b[2] * Y + t.edge_c[2]};
            const std::int64_t down[3] = {t.edge_b[0] * kStep, t.edge_b[1] * kStep, t.edge_b[2] * kStep};
            float* depth_row = kDepth != DepthFunc::none ? depth_out.at(x0, y0, 0) : nullptr;
            float* color_row = colour_slots(x0, y0);
            const std::ptrdiff_t depth_pixel = kDepth != DepthFunc::none ? depth_out.samples * depth_out.channels : 0;
            const std::ptrdiff_t depth_line = depth_pixel * depth_out.pitch;
            const std::ptrdiff_t color_pixel = color_out.samples * color_out.channels;
            const std::ptrdiff_t color_line = color_pixel * color_out.pitch;
            if constexpr (kMode != SampleMode::single) {
                static_assert(kSampleRowMinPixels <= kBoxPixels, "a box's row of masks");
                std::uint64_t masks[kTileSize][kBoxPixels];
                std::uint8_t pixels[kTileSize];
                if (!box_sample_masks_avx2(e, {off0, off1, off2}, {step0, step1, step2}, down, x1 - x0, y1 - y0, S,
                                           masks, pixels))
                    continue;
                for (int py = y0; py < y1; ++py) {
                    for (std::uint32_t m = pixels[py - y0]; m; m &= m - 1) {
                        const int j = __builtin_ctz(m);
                        const std::int64_t p0 = e[0] + j * step0, p1 = e[1] + j * step1, p2 = e[2] + j * step2;
                        if constexpr (kMode == SampleMode::msaa)
                            msaa_pixel(x0 + j, py, p0, p1, p2, masks[py - y0][j], depth_row + j * depth_pixel);
                        else
                            shade_samples(x0 + j, py, p0, p1, p2, masks[py - y0][j], depth_row + j * depth_pixel,
                                          kShading == Shading::visibility ? nullptr : color_row + j * color_pixel);
                    }
                    for (int k = 0; k < 3; ++k) e[k] += down[k];
                    depth_row += depth_line;
                    if constexpr (kShading != Shading::visibility) color_row += color_line;
                }
                continue;
            }
            std::uint8_t cover[kTileSize];
            if (!box_coverage_avx2(e, {step0, step1, step2}, down, x1 - x0, y1 - y0, cover)) continue;
            for (int py = y0; py < y1; ++py) {
                // The per-sample path's steps for sample 0 of each covered pixel.
                for (std::uint32_t m = cover[py - y0]; m; m &= m - 1) {
                    const int j = __builtin_ctz(m);
                    ++counters.samples_covered;
                    glm::dvec3 l(0.0);
                    if constexpr (kDepth != DepthFunc::none || kShading == Shading::screen ||
                                  kShading == Shading::perspective || kShading == Shading::visibility ||
                                  kTexturing != Texturing::none)
                        l = screen_weights(t, e[0] + j * step0, e[1] + j * step1, e[2] + j * step2);
                    if constexpr (kDepth != DepthFunc::none) {
                        float* const depth = depth_row + j * depth_pixel;
                        const float z = sample_depth(t, l);
                        if (!depth_passes<kDepth>(z, *depth)) continue;
                        if (draw.depth_write) *depth = z;
                    }
                    passed_sample(kShading == Shading::visibility ? nullptr : color_row + j * color_pixel, x0 + j, py,
                                  0, l);
                    if constexpr (kDepth != DepthFunc::none) blocks.written(x0 + j, py);
                }
                for (int k = 0; k < 3; ++k) e[k] += down[k];
                depth_row += depth_line;
                if constexpr (kShading != Shading::visibility) color_row += color_line;
            }
            continue;
        }

        if constexpr (kMode == SampleMode::single) sample_offsets();
        for (int py = y0; py < y1; ++py) {
            int rx0 = x0, rx1 = x1;  // the row without skipped blocks at its ends
            blocks.trim(cls.skipped, py, rx0, rx1);
            if (rx0 >= rx1) continue;
            // Edge values at the top-left corner of pixel (rx0, py), exact in int64.
            const std::int64_t X = std::int64_t{rx0} * kStep, Y = std::int64_t{py} * kStep;
            const std::int64_t row0 = t.edge_a[0] * X + t.edge_b[0] * Y + t.edge_c[0];
            const std::int64_t row1 = t.edge_a[1] * X + t.edge_b[1] * Y + t.edge_c[1];
            const std::int64_t row2 = t.edge_a[2] * X + t.edge_b[2] * Y + t.edge_c[2];
            const int n = rx1 - rx0;

            // Textured (or the deferred pre-pass), every sample shaded (one per pixel, or SSAA):
            // the row four pixels at a time, sample by sample (sample_row.hpp), depth tested or not.
            // With several samples, only where none of their rows can be refused; one sample's
            // refused row takes the per-sample path. (Textured without a depth test: plane 1x −9 %,
            // SSAA 4x −17 %. Untextured, the per-pixel path is faster: a depth-tested 1080p grid of
            // 20,000 vertex-coloured triangles took 33 ms by rows, 23 without.)
            if constexpr (kMode != SampleMode::msaa &&
                          (kTexturing != Texturing::none || kShading == Shading::visibility)) {
                bool rows = target.sample_rows && n >= kSampleRowMinPixels &&
                            (kMode == SampleMode::single || sample_rows_exact(t, {row0, row1, row2}, n));
                if (rows) {
                    const std::uint32_t skipped = blocks.row_pixels(cls.skipped, py, rx0, n);
                    const std::uint32_t untested = skipped | blocks.row_pixels(cls.hidden, py, rx0, n);
                    // A multiple of four samples with AVX2: four rows at once, their depths four
                    // pixels a vector. (No row is refused past sample 0: sample_rows_exact holds.)
                    SampleRow four[4];
                    const bool fours = kMode == SampleMode::ssaa && vector_masks && kDepth != DepthFunc::none;
                    float* const depth_row = kDepth != DepthFunc::none ? depth_out.at(rx0, py, 0) : nullptr;
                    for (int s = 0; rows && s < S; ++s) {
                        SampleRow single_row;
                        if (fours && s % 4 == 0) {
                            std::int64_t e[4][3];
                            for (int k = 0; k < 4; ++k) {
                                e[k][0] = row0 + off0[s + k], e[k][1] = row1 + off1[s + k];
                                e[k][2] = row2 + off2[s + k];
                            }
                            if (!test_four_sample_rows_avx2(t, e, n, ~untested, kDepth, draw.depth_write,
                                                            depth_row + s, S, four)) {
                                rows = false;
                                break;
                            }
                        }
                        if (!fours) {
                            const std::int64_t e[3] = {row0 + off0[s], row1 + off1[s], row2 + off2[s]};
                            if (!test_sample_row(t, e, n, ~untested, kDepth, draw.depth_write,
                                                 depth_row ? depth_row + s : nullptr, S, single_row)) {
                                rows = false;  // (one sample, nothing done yet)
                                break;
                            }
                        }
                        const SampleRow& row = fours ? four[s % 4] : single_row;
                        counters.samples_covered += static_cast<std::uint64_t>(count_bits(row.covered & ~skipped));
                        if (passed_row(rx0, py, s, row)) continue;
                        blocks.written_row(py, rx0, row.passed);
                        for (std::uint32_t m = row.passed; m; m &= m - 1) {
                            const int j = __builtin_ctz(m);
                            passed_sample(colour_slots(rx0 + j, py), rx0 + j, py, s,
                                          glm::dvec3(row.l0[j], row.l1[j], row.l2[j]));
                        }
                    }
                    if (rows) continue;
                }
            }

            // MSAA, textured (or the pre-pass of textured draws): a long row's pixels tested one
            // after the other, four samples per vector, then shaded into the lookup queue at once
            // (their centres' weights a row at a time), or their owners recorded: the per-pixel
            // path's values and order (plane MSAA 4x −8 %; without a depth test −30 %). Not where a
            // block is hidden: its pixels skip their tests one by one at less cost (overdraw MSAA 4x
            // was 7 % slower).
            if constexpr (kMode == SampleMode::msaa &&
                          (kTexturing != Texturing::none || kShading == Shading::visibility)) {
                const bool takes_rows = kShading == Shading::visibility ? target.owners != nullptr : queue.has_value();
                if (takes_rows && vector_masks && n >= kSampleRowMinPixels &&
                    !blocks.row_pixels(classified, py, rx0, n) && sample_rows_exact(t, {row0, row1, row2}, n)) {
                    msaa_row(rx0, py, n, {row0, row1, row2});
                    continue;
                }
            }

            // Coverage of the row's samples: sample s of pixel j is inside iff all three edge values
            // are ≥ 0, i.e. the sign bit of their OR is clear. MSAA rows, SSAA rows of
            // kSampleRowMinPixels or more (here only without a depth test or past sample_rows_exact)
            // and, with the vector masks (four samples a vector), every SSAA row get their masks in a
            // pass of their own: plain integer adds, which vectorize with 64-bit compares (x86-64-v3;
            // scalar on the baseline). The first sample stores each mask, the others add their bit:
            // no clearing pass first, whose string stores the next loads would wait for. The other
            // rows (all of them at one sample a pixel) test each pixel's samples in the pixel loop:
            // faster for small triangles (many_small 1x raster 86.5 -> 68.7 ms, SSAA 4x -5 % before
            // the vector masks, which take another 12 % off), slower for long MSAA rows (plane MSAA
            // 4x +5 %).
            const bool masks = kMode == SampleMode::msaa ||
                               (kMode == SampleMode::ssaa && (n >= kSampleRowMinPixels || vector_masks));
            std::uint64_t mask[kTileSize];
            const auto row_samples = [&](int s, auto&& store) {  // store(j, 1 if sample s of pixel j is inside)
                std::int64_t e0 = row0 + off0[s], e1 = row1 + off1[s], e2 = row2 + off2[s];
                for (int j = 0; j < n; ++j) {
                    store(j, static_cast<std::uint64_t>((e0 | e1 | e2) >= 0));
                    e0 += step0;
                    e1 += step1;
                    e2 += step2;
                }
            };
            if (masks && vector_masks) {
                pixel_coverage_avx2({row0, row1, row2}, {off0, off1, off2}, {step0, step1, step2}, n, S, mask);
            } else if (masks) {
                row_samples(0, [&](int j, std::uint64_t inside) { mask[j] = inside; });
                for (int s = 1; s < S; ++s) row_samples(s, [&](int j, std::uint64_t inside) { mask[j] |= inside << s; });
            }

            for (int j = 0; j < n; ++j) {
                const std::int64_t p0 = row0 + j * step0, p1 = row1 + j * step1, p2 = row2 + j * step2;
                std::uint64_t covered = 0;
                if (masks) {
                    covered = mask[j];
                } else {
                    for (int s = 0; s < S; ++s)
                        covered |= static_cast<std::uint64_t>(((p0 + off0[s]) | (p1 + off1[s]) | (p2 + off2[s])) >= 0) << s;
                }
                if (!covered) continue;
                const int px = rx0 + j;
                if (classified && (classified >> blocks.bit(px, py) & 1)) {  // counted, not tested
                    if (cls.hidden >> blocks.bit(px, py) & 1)
                        counters.samples_covered += static_cast<std::uint64_t>(count_bits(covered));
                    continue;
                }
                float* const depth_px = kDepth != DepthFunc::none ? depth_out.at(px, py, 0) : nullptr;

                if constexpr (kMode == SampleMode::msaa) {
                    msaa_pixel(px, py, p0, p1, p2, covered, depth_px);
                } else {
                    shade_samples(px, py, p0, p1, p2, covered, depth_px, colour_slots(px, py));
                }
            }
        }
    }
    if (queue) queue->flush();
}

// Deferred shading's second pass (OwnedShadingKernel): each sample owned by a triangle of this
// draw gets the colour the forward kernel gives it when that triangle draws it (replace blending:
// the last write is all that remains). The edge values are the forward kernel's, exactly: the
// same integer sums in another order.
template <Shading kShading, Texturing kTexturing>
void shade_owned(const TileTarget& target, const DrawInputs& draw, std::uint32_t draw_index, TileCounters& counters) {
    const SamplePattern& pattern = *target.pattern;
    const int S = target.color.samples;
    const std::vector<OwnerRef>& refs = *target.owner_refs;
    // The owner of this draw whose triangle and per-triangle values are below (−1: none yet).
    std::int32_t cached = -1;
    OwnerRef ref{};
    VertexValues colors{};
    TriangleUvs uvs{};
    Shading run_shading = kShading;  // batch_shading of colors, for untextured runs (kInterpolatedColours)
    std::optional<LookupQueue<BlendMode::replace, kShading, kTexturing>> queue;
    if (queues_lookups<kTexturing>(draw)) queue.emplace(draw);
    // The texels of an owner's part of the tile, prefetched the first time it becomes current
    // (runs of two owners can alternate along every row).
    std::int32_t prefetched[8];
    int prefetched_count = 0;
    const auto prefetch_once = [&](std::int32_t owner) {
        if (prefetched_count == 8 ||
            std::find(prefetched, prefetched + prefetched_count, owner) != prefetched + prefetched_count)
            return;
        if (queue->prefetch_area(*ref.triangle, uvs, target.x0, target.y0, target.x1, target.y1))
            prefetched[prefetched_count++] = owner;
    };
    // Makes `owner` the current triangle if it is one of this draw's (false: another draw's).
    const auto take = [&](std::int32_t owner) {
        if (owner == cached) return true;
        const OwnerRef& next = refs[static_cast<std::size_t>(owner)];
        if (next.triangle->draw != draw_index) return false;
        cached = owner;
        ref = next;
        const glm::uvec3 tri = draw.triangles[ref.triangle->triangle];
        if constexpr (kShading == Shading::flat || kShading == Shading::screen || kShading == Shading::perspective)
            colors = VertexValues(draw.vertex_colors[tri[0]], draw.vertex_colors[tri[1]], draw.vertex_colors[tri[2]]);
        if constexpr (kInterpolatedColours<kShading, kTexturing>) run_shading = batch_shading(kShading, colors);
        if constexpr (kTexturing != Texturing::none) {
            uvs = TriangleUvs(*ref.triangle, tri, draw.uvs, ref.clip_weights);
            if (queue) {
                queue->begin_triangle(*ref.triangle, colors, uvs, ref.clip_weights);
                prefetch_once(owner);
            }
        }
        return true;
    };
    // The current triangle's edge values at sample s of pixel (px, py).
    const auto edges_within = [&](int px, int py, std::int64_t ox, std::int64_t oy, std::int64_t (&e)[3]) {
        const SetupTriangle& t = *ref.triangle;  // (at (ox, oy), in 1/256 px, from the pixel's corner)
        const std::int64_t X = std::int64_t{px} * kSubpixelOne + ox, Y = std::int64_t{py} * kSubpixelOne + oy;
        for (int i = 0; i < 3; ++i) e[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
    };
    const auto edges_at = [&](int px, int py, int s, std::int64_t (&e)[3]) {
        edges_within(px, py, pattern.x[s], pattern.y[s], e);
    };
    const auto shade_sample = [&](int px, int py, int s, const glm::dvec3& l) __attribute__((always_inline)) {
        ++counters.shader_invocations;
        shade_into<BlendMode::replace, kShading, kTexturing>(queue ? &*queue : nullptr, target.color.at(px, py, s),
                                                             std::uint64_t{1}, draw, colors, uvs, *ref.triangle, l,
                                                             ref.clip_weights, px, py);
    };
    const auto shade_exactly = [&](int px, int py, int s) {
        std::int64_t e[3];
        edges_at(px, py, s, e);
        shade_sample(px, py, s, screen_weights(*ref.triangle, e[0], e[1], e[2]));
    };
    if (!target.owner_shade_at) {
        // One sample or SSAA, every sample shaded on its own: along each row, runs of pixels whose
        // sample s has one owner, their weights a row at a time (sample_row.hpp). (Replace blending
        // writes each sample once, so the order of the samples does not matter.)
        double l0[kTileSize], l1[kTileSize], l2[kTileSize];
        for (int py = target.y0; py < target.y1; ++py)
            for (int s = 0; s < S; ++s) {
                const std::int32_t* const row = &target.owners[target.owner_index(target.x0, py, s, S)];
                const auto owner_of = [&](int px) { return row[static_cast<std::size_t>(px - target.x0) * S]; };
                for (int px = target.x0, end; px < target.x1; px = end) {
                    const std::int32_t owner = owner_of(px);
                    for (end = px + 1; end < target.x1 && owner_of(end) == owner;) ++end;
                    if (owner < 0 || !take(owner)) continue;
                    std::int64_t e[3];
                    edges_at(px, py, s, e);
                    const int n = end - px;
                    if (n < kSampleRowMinPixels || !sample_row_weights(*ref.triangle, e, n, l0, l1, l2)) {
                        for (int x = px; x < end; ++x) shade_exactly(x, py, s);
                        continue;
                    }
                    const std::uint32_t run = ~std::uint32_t{0} >> (32 - n);
                    float* const first = target.color.at(px, py, s);
                    if (queue) {  // the run as one mask
                        counters.shader_invocations += static_cast<std::uint64_t>(n);
                        queue->push_row(first, 4 * S, run, l0, l1, l2, px, py);
                    } else if (kInterpolatedColours<kShading, kTexturing> && ref.triangle->clip_index < 0) {
                        counters.shader_invocations += static_cast<std::uint64_t>(n);
                        shade_row_colours<BlendMode::replace>(first, 4 * S, run, l0, l1, l2, draw, run_shading, colors,
                                                              *ref.triangle);
                    } else {
                        for (int j = 0; j < n; ++j) shade_sample(px + j, py, s, glm::dvec3(l0[j], l1[j], l2[j]));
                    }
                }
            }
    } else {
        // MSAA: the samples of a pixel with one owner, shaded once where the owner's draw shaded the
        // pixel (its centre, or a sample) and stored to all of them, as that draw did.
        const std::uint64_t all = S == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << S) - 1;
        const auto centre_edges = [&](int px, int py, std::int64_t (&e)[3]) {
            edges_within(px, py, kSubpixelOne / 2, kSubpixelOne / 2, e);
        };
        const auto shade_pixel = [&](int px, int py) {
            const std::size_t first = target.owner_index(px, py, 0, S);
            for (std::uint64_t left = all; left;) {
                const int s = __builtin_ctzll(left);
                const std::int32_t owner = target.owners[first + s];
                const std::uint8_t at = target.owner_shade_at[first + s];  // (one per owner: it drew the pixel once)
                std::uint64_t samples = 0;  // the pixel's samples with this owner
                for (std::uint64_t m = left; m; m &= m - 1)
                    if (target.owners[first + __builtin_ctzll(m)] == owner) samples |= m & -m;
                left &= ~samples;
                if (owner < 0 || !take(owner)) continue;
                std::int64_t e[3];
                if (at == kShadeAtCentre) centre_edges(px, py, e);
                else edges_at(px, py, at, e);
                ++counters.shader_invocations;
                shade_into<BlendMode::replace, kShading, kTexturing>(
                    queue ? &*queue : nullptr, target.color.at(px, py, 0), samples, draw, colors, uvs, *ref.triangle,
                    screen_weights(*ref.triangle, e[0], e[1], e[2]), ref.clip_weights, px, py);
            }
        };
        // Runs of pixels whose samples all have one owner that shades them at their centres go to
        // the lookup queue a row at a time, their weights as the forward kernel's long rows take them.
        // Such a run from pixel px on ends where a sample's owner or place differs: a scan of the
        // row's samples, 32 at a time, then four (a sample at a time, this scan was two thirds of
        // the pass; four at a time, 19 instructions a pixel).
        const auto centre_run_end = [&](int px, int py, std::int32_t owner) {
            const std::size_t first = target.owner_index(px, py, 0, S);
            const std::size_t count = static_cast<std::size_t>(target.x1 - px) * static_cast<std::size_t>(S);
            const std::int32_t* const owners = target.owners + first;
            const std::uint8_t* const places = target.owner_shade_at + first;
            static_assert(kShadeAtCentre == 0xff, "four places at the centre are an all-ones word");
            std::size_t k = 0;
            for (; k + 32 <= count; k += 32) {  // (branch-free within: the compiler vectorizes it)
                std::uint32_t differ = 0;
                for (std::size_t q = k; q < k + 32; ++q)
                    differ |= static_cast<std::uint32_t>(owners[q] ^ owner) | static_cast<std::uint8_t>(places[q] + 1);
                if (differ) break;
            }
            for (; k + 4 <= count; k += 4) {
                std::uint32_t four_places;
                std::memcpy(&four_places, places + k, sizeof four_places);
                if ((four_places + 1) | (owners[k] ^ owner) | (owners[k + 1] ^ owner) | (owners[k + 2] ^ owner) |
                    (owners[k + 3] ^ owner))
                    break;
            }
            while (k < count && owners[k] == owner && places[k] == kShadeAtCentre) ++k;
            return px + static_cast<int>(k / static_cast<std::size_t>(S));
        };
        std::uint64_t all_samples[kTileSize];
        std::fill(all_samples, all_samples + kTileSize, all);
        double l0[kTileSize], l1[kTileSize], l2[kTileSize];
        for (int py = target.y0; py < target.y1; ++py)
            for (int px = target.x0; px < target.x1;) {
                const std::int32_t owner = target.owners[target.owner_index(px, py, 0, S)];
                const int end = queue && owner >= 0 ? centre_run_end(px, py, owner) : px;
                if (end - px < kSampleRowMinPixels) {
                    shade_pixel(px++, py);
                    continue;
                }
                if (take(owner)) {  // (else another draw's pixels)
                    std::int64_t centre[3];
                    centre_edges(px, py, centre);
                    const int n = end - px;
                    if (sample_row_weights(*ref.triangle, centre, n, l0, l1, l2)) {
                        counters.shader_invocations += static_cast<std::uint64_t>(n);
                        queue->push_row(target.color.at(px, py, 0), 4 * S, ~std::uint32_t{0} >> (32 - n), l0, l1, l2,
                                        px, py, all_samples);
                    } else {
                        for (int x = px; x < end; ++x) shade_pixel(x, py);
                    }
                }
                px = end;
            }
    }
    if (queue) queue->flush();
}

template <Texturing T>
OwnedShadingKernel pick_owned_shading(const PipelineKey& k) {
    if (k.blend != BlendMode::replace) return nullptr;
    switch (k.shading) {
        case Shading::constant: return &shade_owned<Shading::constant, T>;
        case Shading::flat: return &shade_owned<Shading::flat, T>;
        case Shading::screen: return &shade_owned<Shading::screen, T>;
        case Shading::perspective: return &shade_owned<Shading::perspective, T>;
        case Shading::visibility: break;
    }
    return nullptr;
}

// Compile-time table of the instances with one kind of texturing, indexed by the key's enumerators.
template <Texturing T, DepthFunc D, BlendMode B, Shading Sh>
TileKernel pick_mode(SampleMode m) {
    switch (m) {
        case SampleMode::single: return &raster_tile<D, B, Sh, SampleMode::single, T>;
        case SampleMode::ssaa: return &raster_tile<D, B, Sh, SampleMode::ssaa, T>;
        case SampleMode::msaa: return &raster_tile<D, B, Sh, SampleMode::msaa, T>;
    }
    return nullptr;
}

template <Texturing T, DepthFunc D, BlendMode B>
TileKernel pick_shading(const PipelineKey& k) {
    switch (k.shading) {
        case Shading::constant: return pick_mode<T, D, B, Shading::constant>(k.samples);
        case Shading::flat: return pick_mode<T, D, B, Shading::flat>(k.samples);
        case Shading::screen: return pick_mode<T, D, B, Shading::screen>(k.samples);
        case Shading::perspective: return pick_mode<T, D, B, Shading::perspective>(k.samples);
        case Shading::visibility: break;  // see select_tile_kernel
    }
    return nullptr;
}

template <Texturing T, DepthFunc D>
TileKernel pick_blend(const PipelineKey& k) {
    switch (k.blend) {
        case BlendMode::replace: return pick_shading<T, D, BlendMode::replace>(k);
        case BlendMode::add: return pick_shading<T, D, BlendMode::add>(k);
        case BlendMode::over: return pick_shading<T, D, BlendMode::over>(k);
    }
    return nullptr;
}

template <Texturing T>
TileKernel pick_depth(const PipelineKey& k) {
    switch (k.depth) {
        case DepthFunc::none: return pick_blend<T, DepthFunc::none>(k);
        case DepthFunc::greater: return pick_blend<T, DepthFunc::greater>(k);
        case DepthFunc::less: return pick_blend<T, DepthFunc::less>(k);
    }
    return nullptr;
}

// Visibility records every covered sample that passes the depth test: no blending; MSAA only as
// deferred shading's pre-pass (with owners).
template <DepthFunc D>
TileKernel pick_visibility(SampleMode m) {
    constexpr BlendMode kReplace = BlendMode::replace;
    constexpr Shading kVisibility = Shading::visibility;
    switch (m) {
        case SampleMode::single: return &raster_tile<D, kReplace, kVisibility, SampleMode::single, Texturing::none>;
        case SampleMode::ssaa: return &raster_tile<D, kReplace, kVisibility, SampleMode::ssaa, Texturing::none>;
        case SampleMode::msaa: return &raster_tile<D, kReplace, kVisibility, SampleMode::msaa, Texturing::none>;
    }
    return nullptr;
}

/// The instances of one kind of texturing (defined in raster_kernels_*.cpp).
TileKernel select_untextured(const PipelineKey& key);
TileKernel select_textured_fixed(const PipelineKey& key);
TileKernel select_textured_lod(const PipelineKey& key);
OwnedShadingKernel select_owned_untextured(const PipelineKey& key);
OwnedShadingKernel select_owned_textured_fixed(const PipelineKey& key);
OwnedShadingKernel select_owned_textured_lod(const PipelineKey& key);

}  // namespace kernels
}  // namespace mipraster
