#pragma once
// Large buffers on transparent huge pages: a buffer written once per render is otherwise faulted in
// 4 KiB at a time (a million set-up triangles: ~110 MB, tens of thousands of page faults, ~100 ms),
// and a large texture level read all over costs a TLB miss per 4 KiB page.
#include <cstddef>
#include <vector>

namespace mipraster {

/// Asks the kernel to back the 2 MiB-aligned part of [data, data + bytes) with transparent huge
/// pages (madvise MADV_HUGEPAGE). A hint: without effect where the system does not offer them,
/// and for buffers smaller than 4 MiB.
void advise_huge_pages(const void* data, std::size_t bytes);

/// v.reserve(n), advised before anything touches the new memory.
template <typename T, typename Allocator>
void reserve_on_huge_pages(std::vector<T, Allocator>& v, std::size_t n) {
    if (n <= v.capacity()) return;
    v.reserve(n);
    advise_huge_pages(v.data(), n * sizeof(T));
}

}  // namespace mipraster
