// Large image buffers are kept for the next image of the same size (block_recycler.hpp): the next
// such image reuses the block, a kept block never shows through a render (every pixel is written,
// so a render into a recycled block gives the bits of one into fresh memory), and what is kept is
// bounded in size and count.
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

TEST(BlockRecycler, KeepsAtMostItsCountOfBlocksWithinItsSizes) {
    mr::release_recycled_blocks();
    const std::size_t size = mr::kMinRecycledBytes;
    EXPECT_FALSE(mr::recycle_block(nullptr, size));
    std::vector<void*> blocks;
    for (int i = 0; i <= mr::kRecycledBlocks; ++i) blocks.push_back(::operator new(size, std::align_val_t{64}));
    for (int i = 0; i < mr::kRecycledBlocks; ++i) EXPECT_TRUE(mr::recycle_block(blocks[i], size));
    EXPECT_FALSE(mr::recycle_block(blocks.back(), size));  // full
    ::operator delete(blocks.back(), std::align_val_t{64});
    void* small = ::operator new(size - 1, std::align_val_t{64});
    EXPECT_FALSE(mr::recycle_block(small, size - 1));
    ::operator delete(small, std::align_val_t{64});
    EXPECT_EQ(mr::take_recycled_block(size - 1), nullptr);
    EXPECT_EQ(mr::take_recycled_block(mr::kMaxRecycledBytes + 1), nullptr);
    for (int i = 0; i < mr::kRecycledBlocks; ++i) {
        void* taken = mr::take_recycled_block(size);
        EXPECT_TRUE(taken == blocks[0] || taken == blocks[1]);
        ::operator delete(taken, std::align_val_t{64});
    }
    EXPECT_EQ(mr::take_recycled_block(size), nullptr);  // all taken
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
