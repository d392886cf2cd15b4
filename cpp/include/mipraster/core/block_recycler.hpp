#pragma once
// Large per-render buffers kept for the next buffer of the same size: a render allocates its
// colour image, its clip-space vertices and its set-up triangles anew each frame, and on a
// virtual machine that hands freed memory back to its host, touching them again costs page
// faults and zeroing in the kernel (a new 33 MB image: ~70 ms a frame; a million triangles'
// set-up buffers: 1,570 faults and 5–24 ms a frame), against nothing when the pages stay. Up to
// kRecycledBlocks blocks of kMinRecycledBytes to kMaxRecycledBytes are kept, at most
// kMaxRecycledTotalBytes in all, the oldest freed first (constants.hpp); thread-safe.
#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace mipraster {

/// The alignment of the blocks kept (and of every buffer that may become one): a cache line.
inline constexpr std::size_t kBlockAlignment = 64;

/// A kept block of exactly `bytes` bytes (its old contents left as they were), or null.
void* take_recycled_block(std::size_t bytes) noexcept;

/// Keeps `block` (from operator new with kBlockAlignment, `bytes` long) for a later
/// take_recycled_block, freeing the oldest kept blocks where the count or the total would be
/// exceeded; false when its size is outside the kept sizes: the caller frees it.
bool recycle_block(void* block, std::size_t bytes) noexcept;

/// Frees every kept block.
void release_recycled_blocks() noexcept;

/// The bytes kept now.
std::size_t recycled_bytes() noexcept;

/// A std::allocator whose large blocks come from, and go back to, the kept blocks; every block
/// starts on a cache line.
template <typename T>
struct RecyclingAllocator {
    using value_type = T;
    RecyclingAllocator() = default;
    template <typename U>
    RecyclingAllocator(const RecyclingAllocator<U>&) noexcept {}
    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
        if (void* kept = take_recycled_block(n * sizeof(T))) return static_cast<T*>(kept);
        return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{kBlockAlignment}));
    }
    void deallocate(T* p, std::size_t n) noexcept {
        if (!recycle_block(p, n * sizeof(T))) ::operator delete(p, std::align_val_t{kBlockAlignment});
    }
    /// resize() and emplace_back() without arguments default-initialize: a type without a
    /// constructor is left as it is, not zeroed (every user writes what it sizes, and zeroing a
    /// buffer larger than the cache first reads each of its lines from memory).
    template <typename U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value) {
        ::new (static_cast<void*>(p)) U;
    }
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
    template <typename U>
    bool operator==(const RecyclingAllocator<U>&) const noexcept {
        return true;
    }
    template <typename U>
    bool operator!=(const RecyclingAllocator<U>&) const noexcept {
        return false;
    }
};

/// A per-render buffer whose large blocks are kept for the next render.
template <typename T>
using RecycledVector = std::vector<T, RecyclingAllocator<T>>;

}  // namespace mipraster
