#pragma once
// Textured samples waiting for their shade (private to the pipeline): each shade queues its
// sample's screen weights; every kLookupBatch of them are interpolated (interpolate_batch when
// they all belong to one triangle it covers, else sample by sample), go through one BatchSampler
// call, then blend in the order they were queued, which is the order the forward path blends
// them in. Blends read the target when they run, so a sample queued twice (by two triangles)
// still sees the first result under the second.
#include <algorithm>
#include <cstdint>
#include <limits>

#include <glm/vec4.hpp>

#include "mipraster/pipeline/blend.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/texture/sample.hpp"
#include "mipraster/texture/sample_batch.hpp"
#include "interpolate_batch.hpp"
#include "sample_shading.hpp"

namespace mipraster {
namespace kernels {

template <BlendMode kBlend, Shading kShading, Texturing kTexturing>
class LookupQueue {
public:
    explicit LookupQueue(const DrawInputs& draw) : draw_(draw), sampler_(*draw.texture, *draw.sampler) {}
    LookupQueue(const LookupQueue&) = delete;
    LookupQueue& operator=(const LookupQueue&) = delete;

    /// The triangle whose samples the next pushes are, with its vertex colours and uvs (copied:
    /// the caller's copies change with the next triangle).
    void begin_triangle(const SetupTriangle& t, const VertexValues& colors, const TriangleUvs& uvs,
                        const ClipWeights* clip_weights) {
        if (current_queued_) ++current_;  // keep the triangle of the samples already queued
        current_queued_ = false;
        triangles_[current_] = {&t, clip_weights, colors, uvs,
                                interpolates_in_batches(draw_, kShading, kTexturing, t),
                                batch_shading(kShading, colors)};
    }

    /// Asks for the texels triangle t reads in the tile [tile_x0, tile_x1) × [tile_y0, tile_y1) to
    /// be brought into the cache before its samples there are queued (see BatchSampler::prefetch).
    /// The area is bounded by the uvs at the four corner pixels of its bounds in the tile (the
    /// planes extended beyond the triangle, as for quad derivatives) and by its vertices' uvs; its
    /// λ is the finest of the corners'. False, asking for nothing, where its bounds hold fewer than
    /// kPrefetchArea pixels of the tile: a smaller part reads few texels, and the prefetch would
    /// cost more than the misses it saves.
    static constexpr int kPrefetchArea = 256;
    bool prefetch_area(const SetupTriangle& t, const TriangleUvs& uvs, int tile_x0, int tile_y0, int tile_x1,
                       int tile_y1) {
        const int x0 = std::max(t.min_x, tile_x0), x1 = std::min(t.max_x + 1, tile_x1);
        const int y0 = std::max(t.min_y, tile_y0), y1 = std::min(t.max_y + 1, tile_y1);
        if (x1 - x0 < 1 || y1 - y0 < 1 || (x1 - x0) * (y1 - y0) < kPrefetchArea) return false;
        glm::dvec2 lo = glm::min(glm::min(uvs.v[0], uvs.v[1]), uvs.v[2]);
        glm::dvec2 hi = glm::max(glm::max(uvs.v[0], uvs.v[1]), uvs.v[2]);
        glm::dvec2 corners_lo(std::numeric_limits<double>::infinity()), corners_hi = -corners_lo;
        double lambda = std::numeric_limits<double>::infinity();
        for (const int py : {y0, y1 - 1})
            for (const int px : {x0, x1 - 1}) {
                const std::int64_t X = std::int64_t{px} * kSubpixelOne + kSubpixelOne / 2;
                const std::int64_t Y = std::int64_t{py} * kSubpixelOne + kSubpixelOne / 2;
                std::int64_t e[3];
                for (int i = 0; i < 3; ++i) e[i] = t.edge_a[i] * X + t.edge_b[i] * Y + t.edge_c[i];
                const glm::dvec3 l = screen_weights(t, e[0], e[1], e[2]);
                // Beyond the triangle's horizon (1/w ≤ 0 there) the extended planes mean nothing.
                if (draw_.uv_interpolation == Interpolation::perspective &&
                    !(l.x * t.inv_w[0] + l.y * t.inv_w[1] + l.z * t.inv_w[2] > 0.0))
                    return true;
                const UvSample s = texture_lookup<kTexturing>(draw_, t, uvs, l, px, py);
                corners_lo = glm::min(corners_lo, s.uv), corners_hi = glm::max(corners_hi, s.uv);
                double corner_lambda = 0.0;  // (a sampler without derivatives reads level 0)
                if constexpr (kTexturing == Texturing::lod)
                    corner_lambda = texture_lod(*draw_.texture, *draw_.sampler, glm::vec2(s.dx), glm::vec2(s.dy));
                lambda = std::min(lambda, corner_lambda);
            }
        sampler_.prefetch(glm::max(lo, corners_lo), glm::min(hi, corners_hi), lambda);
        return true;
    }

    /// Queues the shade of samples `samples` (a bit mask) at 4-float colour slots of `target`:
    /// the current triangle at screen weights l of pixel (px, py).
    void push(float* target, std::uint64_t samples, const glm::dvec3& l, int px, int py) {
        enqueue(target, samples, l.x, l.y, l.z, px, py);
    }

    /// push for the pixels of a row, in order: bit j of `pixels` is pixel (x0 + j, y), its colour
    /// slots at row_target + stride·j (floats): one, or (MSAA) samples[j] of them; its screen
    /// weights l0[j], l1[j], l2[j].
    void push_row(float* row_target, int stride, std::uint32_t pixels, const double* l0, const double* l1,
                  const double* l2, int x0, int y, const std::uint64_t* samples = nullptr) {
        while (pixels) {
            // Up to a batch at a time with the count in a register (as a member, each pixel's
            // stores into the queue could change it, so it went through memory pixel by pixel).
            int n = count_;
            const int j = __builtin_ctz(pixels);
            const std::uint64_t from_j = std::uint64_t{pixels} >> j;
            if ((from_j & (from_j + 1)) == 0) {
                // The row's pixels left are one run (a triangle's span where every pixel passed):
                // field by field, in loops that vectorize (pixel by pixel it was 27 instructions each).
                const int take = std::min(__builtin_popcountll(from_j), kLookupBatch - n);
                for (int k = 0; k < take; ++k) {
                    weights_.l0[n + k] = l0[j + k], weights_.l1[n + k] = l1[j + k], weights_.l2[n + k] = l2[j + k];
                    pending_.target[n + k] = row_target + stride * (j + k);
                    pending_.samples[n + k] = samples ? samples[j + k] : 1;
                    pending_.triangle[n + k] = current_;
                    pending_.px[n + k] = x0 + j + k;
                    pending_.py[n + k] = y;
                }
                n += take;
                pixels &= ~static_cast<std::uint32_t>(((std::uint64_t{1} << take) - 1) << j);
            } else {
                for (; pixels && n < kLookupBatch; pixels &= pixels - 1, ++n) {
                    const int i = __builtin_ctz(pixels);
                    put(n, row_target + stride * i, samples ? samples[i] : 1, l0[i], l1[i], l2[i], x0 + i, y);
                }
            }
            count_ = n;
            current_queued_ = true;
            if (n == kLookupBatch) flush();
        }
    }

    /// Shades and blends what is queued (also before the kernel returns).
    void flush() {
        if (count_ == 0) return;
        glm::vec4 colour[kLookupBatch];
        const Triangle& first = triangles_[pending_.triangle[0]];
        if (first.batched && pending_.triangle[count_ - 1] == pending_.triangle[0]) {  // (triangles only advance)
            weights_.count = count_;
            interpolate_batch(draw_, first.shading, kTexturing, *first.t, first.colors, first.uvs, weights_, colour,
                              lookups_);
        } else {
            for (int i = 0; i < count_; ++i) {
                const Triangle& tri = triangles_[pending_.triangle[i]];
                const glm::dvec3 l(weights_.l0[i], weights_.l1[i], weights_.l2[i]);
                colour[i] = untextured_colour<kShading>(draw_, tri.colors, *tri.t, l, tri.clip_weights);
                const UvSample s =
                    texture_lookup<kTexturing>(draw_, *tri.t, tri.uvs, l, pending_.px[i], pending_.py[i]);
                lookups_.set(i, glm::vec2(s.uv), glm::vec2(s.dx), glm::vec2(s.dy));
            }
            lookups_.count = count_;
        }
        glm::vec4 texture[kLookupBatch];
        sampler_.sample(lookups_, texture);
        for (int i = 0; i < count_; ++i) {
            glm::vec4 c = colour[i];
            c *= texture[i];  // as shade() multiplies
            float* const target = pending_.target[i];
            if (pending_.samples[i] == 1) {  // (one sample per pixel, or SSAA: the slot itself)
                blend_into<kBlend>(target, c);
                continue;
            }
            blend_into_samples<kBlend>(target, pending_.samples[i], c);
        }
        count_ = 0;
        // The current triangle stays, with nothing queued. (Its record is a few hundred bytes: a
        // copy onto itself, as for nearly every batch of a large triangle, cost 2 % of a frame.)
        if (current_ != 0) triangles_[0] = triangles_[current_];
        current_ = 0;
        current_queued_ = false;
    }

private:
    // Entry n of the queue: the current triangle's samples at `target`, screen weights l0, l1, l2.
    void put(int n, float* target, std::uint64_t samples, double l0, double l1, double l2, int px, int py) {
        weights_.l0[n] = l0, weights_.l1[n] = l1, weights_.l2[n] = l2;
        pending_.target[n] = target, pending_.samples[n] = samples, pending_.triangle[n] = current_;
        pending_.px[n] = px, pending_.py[n] = py;
    }
    void enqueue(float* target, std::uint64_t samples, double l0, double l1, double l2, int px, int py) {
        put(count_, target, samples, l0, l1, l2, px, py);
        current_queued_ = true;
        if (++count_ == kLookupBatch) flush();
    }

    struct Triangle {
        const SetupTriangle* t;
        const ClipWeights* clip_weights;
        VertexValues colors;
        TriangleUvs uvs;
        bool batched;     // interpolates_in_batches
        Shading shading;  // batch_shading
    };
    // The queued samples' colour slots, sample masks, triangles (indices into triangles_) and
    // pixels, field by field.
    struct PendingLanes {
        float* target[kLookupBatch];
        std::uint64_t samples[kLookupBatch];
        int triangle[kLookupBatch];
        int px[kLookupBatch], py[kLookupBatch];
    };
    const DrawInputs& draw_;
    BatchSampler sampler_;
    // The triangles of the queued samples, in order, then the current one: at most one per
    // queued sample plus one.
    Triangle triangles_[kLookupBatch + 1];
    int current_ = 0;
    bool current_queued_ = false;  // some queued sample belongs to triangles_[current_]
    BatchWeights weights_;
    LookupBatch lookups_;
    PendingLanes pending_;
    int count_ = 0;
};

}  // namespace kernels
}  // namespace mipraster
