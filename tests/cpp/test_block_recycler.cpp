// Large per-render buffers are kept for the next buffer of the same size (block_recycler.hpp): the
// next such image reuses the block, a kept block never shows through a render (every pixel is
// written, so a render into a recycled block gives the bits of one into fresh memory; likewise
// for the set-up buffers), and what is kept is bounded in size, count and total, newest kept.
#include <gtest/gtest.h>

#include <cstring>
#include <new>
#include <vector>

#include "helpers.hpp"
#include "mipraster/core/block_recycler.hpp"
#include "mipraster/core/constants.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

TEST(BlockRecycler, AFreedLargeImageServesTheNextImageOfItsSizeOnly) {
    mr::release_recycled_blocks();
    const float* first;
    {
        const mr::Image a = mr::Image::unfilled(1024, 1024, 4);  // 16 MiB
        first = a.pixels.data();
    }
    {
        const mr::Image other = mr::Image::unfilled(1024, 1000, 4);  // another size: fresh memory
        EXPECT_NE(other.pixels.data(), first);
        const mr::Image b = mr::Image::unfilled(1024, 1024, 4);
        EXPECT_EQ(b.pixels.data(), first);
        const mr::Image zeros(1024, 1024, 4);  // (a new block: b holds the kept one)
        for (float v : zeros.pixels) ASSERT_EQ(v, 0.0f);
    }
    mr::release_recycled_blocks();
}

void* block(std::size_t bytes) { return ::operator new(bytes, std::align_val_t{mr::kBlockAlignment}); }

TEST(BlockRecycler, KeepsOnlyItsSizesAndTheNewestBlocksWithinItsCountAndTotal) {
    mr::release_recycled_blocks();
    EXPECT_EQ(mr::recycled_bytes(), 0u);
    const std::size_t size = mr::kMinRecycledBytes;
    EXPECT_FALSE(mr::recycle_block(nullptr, size));
    void* small = block(size - 1);
    EXPECT_FALSE(mr::recycle_block(small, size - 1));  // not kept: the caller frees it
    ::operator delete(small, std::align_val_t{mr::kBlockAlignment});
    EXPECT_EQ(mr::take_recycled_block(size - 1), nullptr);
    EXPECT_EQ(mr::take_recycled_block(mr::kMaxRecycledBytes + 1), nullptr);

    // One more block than the count: the oldest is freed to make room.
    std::vector<void*> blocks;
    for (int i = 0; i <= mr::kRecycledBlocks; ++i) {
        blocks.push_back(block(size));
        EXPECT_TRUE(mr::recycle_block(blocks.back(), size));
    }
    EXPECT_EQ(mr::recycled_bytes(), mr::kRecycledBlocks * size);
    for (int i = mr::kRecycledBlocks; i >= 1; --i) {  // the newest first
        void* taken = mr::take_recycled_block(size);
        EXPECT_EQ(taken, blocks[i]);
        ::operator delete(taken, std::align_val_t{mr::kBlockAlignment});
    }
    EXPECT_EQ(mr::take_recycled_block(size), nullptr);  // blocks[0] was freed, the rest taken
    EXPECT_EQ(mr::recycled_bytes(), 0u);

    // Blocks of the largest size, one more than the total holds: the oldest goes. (Never
    // touched: only address space.)
    const std::size_t large = mr::kMaxRecycledBytes;
    const int fit = static_cast<int>(mr::kMaxRecycledTotalBytes / large);
    std::vector<void*> larges;
    for (int i = 0; i <= fit; ++i) {
        larges.push_back(block(large));
        EXPECT_TRUE(mr::recycle_block(larges.back(), large));
        EXPECT_LE(mr::recycled_bytes(), mr::kMaxRecycledTotalBytes);
    }
    EXPECT_EQ(mr::recycled_bytes(), fit * large);
    for (int i = fit; i >= 1; --i) {
        void* taken = mr::take_recycled_block(large);
        EXPECT_EQ(taken, larges[i]);
        ::operator delete(taken, std::align_val_t{mr::kBlockAlignment});
    }
    EXPECT_EQ(mr::take_recycled_block(large), nullptr);
    mr::release_recycled_blocks();
}

// The set-up buffers of a large mesh (clip-space vertices, set-up triangles) are kept too: a
// render into the blocks another mesh's render left gives the bits of one into fresh memory, and
// rendering the same scene again keeps the same bytes (it takes the blocks and gives them back).
TEST(BlockRecycler, SetUpBuffersAreKeptAndARenderIntoThemGivesTheBitsOfOneIntoFreshMemory) {
    const int W = 96, H = 64;  // a small image (not kept): what is kept is the set-up
    const std::size_t n = 200000;  // ~24 MB of set-up triangles
    const mr::Mesh a = random_triangles(n, 0.4, 11, {-2.0, -1.5, -2.0}, {4.0, 3.0, 8.0});
    const mr::Mesh b = random_triangles(n, 0.4, 12, {-2.0, -1.5, -2.0}, {4.0, 3.0, 8.0});
    const mr::Camera cam = mr::Camera::look_at_perspective({0.3, 1.0, 4.0}, {0, 0, 0}, {0, 1, 0}, 1.0, double(W) / H, 0.05);
    auto s = settings(W, H, 1);
    s.threads = 1;
    const auto render = [&](const mr::Mesh& mesh) {
        const std::vector<mr::Draw> draws = {make_draw(mesh, glm::dmat4(1.0), mr::DrawState{})};
        return mr::render(draws, cam, s);
    };
    mr::release_recycled_blocks();
    const mr::RenderResult fresh = render(b);
    const std::size_t kept = mr::recycled_bytes();
    EXPECT_GE(kept, n * sizeof(mr::SetupTriangle));  // (the vertices come on top)
    mr::release_recycled_blocks();
    render(a);  // leaves its data in the kept blocks
    EXPECT_EQ(mr::recycled_bytes(), kept);
    const mr::RenderResult reused = render(b);
    EXPECT_EQ(mr::recycled_bytes(), kept);
    EXPECT_TRUE(same_bits(reused.color.pixels, fresh.color.pixels));
    EXPECT_EQ(reused.stats.samples_passed, fresh.stats.samples_passed);
    mr::release_recycled_blocks();
}

TEST(BlockRecycler, ARenderIntoAKeptBlockGivesTheBitsOfOneIntoFreshMemory) {
    const int W = 1024, H = 1024;  // a 16 MiB colour image: kept when freed
    const mr::Mesh mesh = random_triangles(300, 1.2, 5, {-2.0, -1.5, -2.0}, {4.0, 3.0, 8.0});
    const mr::Camera cam = mr::Camera::look_at_perspective({0.3, 1.0, 4.0}, {0, 0, 0}, {0, 1, 0}, 1.0, double(W) / H, 0.05);
    const std::vector<mr::Draw> draws = {make_draw(mesh, glm::dmat4(1.0), mr::DrawState{})};
    for (int samples : {1, 4}) {
        SCOPED_TRACE(std::to_string(samples) + " samples");
        auto s = settings(W, H, samples);
        s.keep_samples = false;
        s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
        mr::release_recycled_blocks();
        const mr::RenderResult fresh = mr::render(draws, cam, s);
        {
            mr::Image garbage = mr::Image::unfilled(W, H, 4);  // a block full of a poison, then kept
            std::memset(garbage.pixels.data(), 0xbe, garbage.pixels.size() * sizeof(float));
        }
        const mr::RenderResult recycled = mr::render(draws, cam, s);
        EXPECT_TRUE(same_bits(recycled.color.pixels, fresh.color.pixels));
    }
    mr::release_recycled_blocks();
}

}  // namespace
