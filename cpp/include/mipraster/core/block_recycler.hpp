#pragma once
// Large image buffers kept for the next image of the same size. A render allocates its colour
// image anew each frame; on a virtual machine that hands freed memory back to its host, touching
// a new 33 MB image (1080p RGBA float) was measured at ~70 ms of kernel time a frame, against
// 0–8 ms when the pages stay. At most kRecycledBlocks blocks of kMinRecycledBytes to
// kMaxRecycledBytes are kept (constants.hpp); thread-safe.
#include <cstddef>

namespace mipraster {

/// The alignment of the blocks kept (and of every image buffer): a cache line.
inline constexpr std::size_t kBlockAlignment = 64;

/// A kept block of exactly `bytes` bytes (its old contents left as they were), or null.
void* take_recycled_block(std::size_t bytes) noexcept;

/// Keeps `block` (from operator new with kBlockAlignment, `bytes` long) for a later
/// take_recycled_block; false when it is not kept (wrong size, or the keep is full): the caller
/// frees it.
bool recycle_block(void* block, std::size_t bytes) noexcept;

/// Frees every kept block.
void release_recycled_blocks() noexcept;

}  // namespace mipraster
