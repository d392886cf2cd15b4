#include "mipraster/core/block_recycler.hpp"

#include <cstdint>
#include <mutex>
#include <new>

#include "mipraster/core/constants.hpp"

namespace mipraster {

namespace {

struct Kept {
    void* block = nullptr;
    std::size_t bytes = 0;
    std::uint64_t when = 0;  // when it was kept (larger: later)
};

std::mutex kept_mutex;
Kept kept[kRecycledBlocks];
std::size_t kept_bytes = 0;
std::uint64_t keep_order = 0;  // counts the blocks kept so far

void free_block(Kept& k) {
    ::operator delete(k.block, std::align_val_t{kBlockAlignment});
    kept_bytes -= k.bytes;
    k = Kept{};
}

}  // namespace

void* take_recycled_block(std::size_t bytes) noexcept {
    if (bytes < kMinRecycledBytes || bytes > kMaxRecycledBytes) return nullptr;
    std::lock_guard<std::mutex> lock(kept_mutex);
    Kept* newest = nullptr;  // of this size
    for (Kept& k : kept)
        if (k.block && k.bytes == bytes && (!newest || k.when > newest->when)) newest = &k;
    if (!newest) return nullptr;
    void* block = newest->block;
    kept_bytes -= newest->bytes;
    *newest = Kept{};
    return block;
}

bool recycle_block(void* block, std::size_t bytes) noexcept {
    if (!block || bytes < kMinRecycledBytes || bytes > kMaxRecycledBytes) return false;
    std::lock_guard<std::mutex> lock(kept_mutex);
    for (;;) {  // make room: the oldest go first
        Kept* free_slot = nullptr;
        Kept* oldest = nullptr;
        for (Kept& k : kept) {
            if (!k.block) free_slot = &k;
            else if (!oldest || k.when < oldest->when) oldest = &k;
        }
        if (free_slot && kept_bytes + bytes <= kMaxRecycledTotalBytes) {
            *free_slot = Kept{block, bytes, ++keep_order};
            kept_bytes += bytes;
            return true;
        }
        free_block(*oldest);  // (full or over the total: some block is kept)
    }
}

void release_recycled_blocks() noexcept {
    std::lock_guard<std::mutex> lock(kept_mutex);
    for (Kept& k : kept)
        if (k.block) free_block(k);
}

std::size_t recycled_bytes() noexcept {
    std::lock_guard<std::mutex> lock(kept_mutex);
    return kept_bytes;
}

}  // namespace mipraster
