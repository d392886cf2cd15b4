#pragma once
// Textured samples waiting for their texture lookup (private to the pipeline): each shade queues
// its untextured colour and its lookup's inputs; every kLookupBatch of them go through one
// BatchSampler call, then blend in the order they were queued, which is the order the forward
// path blends them in. Blends read the target when they run, so a sample queued twice (by two
// triangles) still sees the first result under the second.
#include <cstdint>

#include <glm/vec4.hpp>

#include "mipraster/pipeline/blend.hpp"
#include "mipraster/pipeline/rasterize_tile.hpp"
#include "mipraster/pipeline/shade_texture.hpp"
#include "mipraster/texture/sample_batch.hpp"

namespace mipraster {
namespace kernels {

template <BlendMode kBlend>
class LookupQueue {
public:
    explicit LookupQueue(const DrawInputs& draw) : sampler_(*draw.texture, *draw.sampler) {}
    LookupQueue(const LookupQueue&) = delete;
    LookupQueue& operator=(const LookupQueue&) = delete;

    /// Queues the shade of samples `samples` (a bit mask) at 4-float colour slots of `target`: colour × the
    /// texture at `lookup`.
    void push(float* target, std::uint64_t samples, const glm::vec4& colour, const UvSample& lookup) {
        lookups_.set(count_, glm::vec2(lookup.uv), glm::vec2(lookup.dx), glm::vec2(lookup.dy));
        pending_[count_] = {target, samples, colour};
        if (++count_ == kLookupBatch) flush();
    }

    /// Looks up and blends what is queued (also before the kernel returns).
    void flush() {
        if (count_ == 0) return;
        lookups_.count = count_;
        glm::vec4 texture[kLookupBatch];
        sampler_.sample(lookups_, texture);
        for (int i = 0; i < count_; ++i) {
            const Pending& p = pending_[i];
            glm::vec4 c = p.colour;
            c *= texture[i];  // as shade() multiplies
            for (std::uint64_t m = p.samples; m; m &= m - 1) blend_into<kBlend>(p.target + 4 * __builtin_ctzll(m), c);
        }
        count_ = 0;
    }

private:
    struct Pending {
        float* target;
        std::uint64_t samples;
        glm::vec4 colour;
    };
    BatchSampler sampler_;
    LookupBatch lookups_;
    Pending pending_[kLookupBatch];
    int count_ = 0;
};

}  // namespace kernels
}  // namespace mipraster
