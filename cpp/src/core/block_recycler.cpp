#include "mipraster/core/block_recycler.hpp"

#include <mutex>
#include <new>

#include "mipraster/core/constants.hpp"

namespace mipraster {

namespace {

struct Kept {
    void* block = nullptr;
    std::size_t bytes = 0;
};

std::mutex kept_mutex;
Kept kept[kRecycledBlocks];

}  // namespace

void* take_recycled_block(std::size_t bytes) noexcept {
    if (bytes < kMinRecycledBytes || bytes > kMaxRecycledBytes) return nullptr;
    std::lock_guard<std::mutex> lock(kept_mutex);
    for (Kept& k : kept)
        if (k.block && k.bytes == bytes) {
            void* block = k.block;
            k = Kept{};
            return block;
        }
    return nullptr;
}

bool recycle_block(void* block, std::size_t bytes) noexcept {
    if (!block || bytes < kMinRecycledBytes || bytes > kMaxRecycledBytes) return false;
    std::lock_guard<std::mutex> lock(kept_mutex);
    for (Kept& k : kept)
        if (!k.block) {
            k = Kept{block, bytes};
            return true;
        }
    return false;
}

void release_recycled_blocks() noexcept {
    std::lock_guard<std::mutex> lock(kept_mutex);
    for (Kept& k : kept) {
        if (k.block) ::operator delete(k.block, std::align_val_t{kBlockAlignment});
        k = Kept{};
    }
}

}  // namespace mipraster
