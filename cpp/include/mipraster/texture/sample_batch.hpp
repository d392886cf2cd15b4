#pragma once
// Texture lookups sixteen at a time: the footprint, λ and texel positions of all of them in float
// vectors, then one trilinear blend per lookup (or one line of anisotropic probes per level).
// The fast path for the common samplers (bilinear, trilinear and anisotropic, repeat or clamp);
// sample_texture (sample.hpp, double positions) stays the reference it is tested against.
#include <cstdint>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture.hpp"

namespace mipraster {

inline constexpr int kLookupBatch = 16;

/// Up to kLookupBatch lookups, one per lane: what sample_texture takes, as arrays.
/// Lanes past `count` are read but not used (zero-initialized, so they hold defined values).
struct LookupBatch {
    float u[kLookupBatch] = {}, v[kLookupBatch] = {};
    float dudx[kLookupBatch] = {}, dvdx[kLookupBatch] = {}, dudy[kLookupBatch] = {}, dvdy[kLookupBatch] = {};
    int count = 0;

    void set(int lane, glm::vec2 uv, glm::vec2 duv_dx, glm::vec2 duv_dy) {
        u[lane] = uv.x, v[lane] = uv.y;
        dudx[lane] = duv_dx.x, dvdx[lane] = duv_dx.y, dudy[lane] = duv_dy.x, dvdy[lane] = duv_dy.y;
    }
};

/// How far a batched lookup may be from sample_texture, per channel, in units of the largest
/// |texel value| of level 0: λ in float moves the blend between two levels by ≤ 4·10⁻⁶, and a
/// texel position u·w in float is off by ≤ w·2⁻²⁴ texels (exact for a power-of-two width).
inline double batch_sampling_tolerance(int width, int height) {
    const int longest = width > height ? width : height;
    return 4e-6 + longest * 0x1p-22;
}

/// The texels of a w×h level that bilinear lookups at uv in [lo, hi] (component-wise) can read,
/// with a texel to spare on each side: rows y_from[i] … y_to[i] for i < rows and, in each, columns
/// x_from[i] … x_to[i] for i < columns (two ranges where a repeated area crosses the texture's
/// edge). Empty (rows = columns = 0) for a non-finite or inverted box, or one beyond ±2²⁰.
struct TexelArea {
    int columns = 0, rows = 0;
    int x_from[2] = {}, x_to[2] = {}, y_from[2] = {}, y_to[2] = {};
};
TexelArea texel_area(int w, int h, glm::dvec2 lo, glm::dvec2 hi, WrapMode wrap_u, WrapMode wrap_v);

/// Samples one texture with one sampler a batch at a time. Lookups the float path handles (see
/// covers()) go through it. An anisotropic footprint that needs several probes takes the
/// reference's probe count and line of probes (in double), on the level(s) of the float λ.
/// Every other lane (a non-finite uv or derivative, a sampler outside covers()) calls
/// sample_texture, so its value is the reference's exactly. The result depends on neither the
/// CPU nor the batch's other lanes (element-wise vector arithmetic, no fused multiply-add).
class BatchSampler {
public:
    /// `texture` must outlive the sampler (the levels it reads are pinned by the view).
    /// `vector_width`: lanes per vector of the float path, 4 (SSE2), 8 (AVX2, where the CPU has
    /// it) or 0 for widest_vector(); every width gives the same bits (std::invalid_argument for
    /// another width, or 8 without AVX2).
    BatchSampler(const TextureView& texture, const Sampler& sampler, int vector_width = 0);

    /// 8 where the CPU has AVX2, else 4.
    static int widest_vector();

    /// True when the sampler is one the float path takes: linear magnification and
    /// minification, mip filter none or linear, an isotropic or anisotropic footprint, repeat
    /// or clamp on both axes. False: every lane is a sample_texture call.
    static bool covers(const Sampler& sampler);

    /// Asks for the texels that lookups at uv in [lo, hi] read on the level(s) of λ = `lambda`
    /// to be brought into the second-level cache (a hint: no result depends on it). Nothing for a
    /// sampler outside covers(), a level not built yet (none is built for it), or an area of
    /// more than kMaxPrefetchLines cache lines.
    void prefetch(glm::dvec2 lo, glm::dvec2 hi, double lambda);
    static constexpr long kMaxPrefetchLines = 2048;  // 128 KiB

    /// out[i] for i < batch.count (std::invalid_argument for a count outside 0 … kLookupBatch).
    void sample(const LookupBatch& batch, glm::vec4* out);

private:
    const TextureView& texture_;
    Sampler sampler_;
    bool covered_;
    int vector_width_;
    // The levels read so far (null: not asked for yet; asking may build it), and their texels'
    // floats, RGBA by RGBA.
    const TextureLevel* level_records_[32] = {};
    const TextureLevel* level_record(int k) { return level_records_[k] ? level_records_[k] : first_record_use(k); }
    const TextureLevel* first_record_use(int k);
    const float* level_floats(int k) { return &level_record(k)->texels.data()->x; }
};

}  // namespace mipraster
