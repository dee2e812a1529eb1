#pragma once
// HugePageAllocator: storage for large arrays read at random (the BVH's nodes and leaf
// primitives, 19 MiB on conference; the scene's vertices and triangles, 6 MiB). An allocation
// of 2 MiB or more is 2 MiB-aligned and advised for transparent huge pages (madvise
// MADV_HUGEPAGE; Debian's default THP mode, "madvise", gives them only where asked), so
// scattered reads need one TLB entry per 2 MiB instead of one per 4 KiB page: conference's
// 19 MiB of tree span 4800 small pages, beyond a second-level TLB of 1.5-3k entries. Where the
// kernel gives no huge pages, it is a plain aligned allocation. The bytes are the same, so are
// the results.

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <new>

namespace sfx {

constexpr std::size_t k_huge_page_bytes = std::size_t(2) << 20;

template <class T>
struct HugePageAllocator {
    using value_type = T;

    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) {}

    T* allocate(std::size_t n) {
        const std::size_t bytes = n * sizeof(T);
        if (bytes < k_huge_page_bytes)
            return static_cast<T*>(::operator new(bytes, std::align_val_t(alignof(T))));
        const std::size_t rounded =
            (bytes + k_huge_page_bytes - 1) / k_huge_page_bytes * k_huge_page_bytes;
        void* p = std::aligned_alloc(k_huge_page_bytes, rounded);
        if (p == nullptr) throw std::bad_alloc();
        madvise(p, rounded, MADV_HUGEPAGE);  // advice: if refused, the pages stay 4 KiB
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) {
        if (n * sizeof(T) < k_huge_page_bytes)
            ::operator delete(p, std::align_val_t(alignof(T)));
        else
            std::free(p);
    }
    friend bool operator==(const HugePageAllocator&, const HugePageAllocator&) { return true; }
    friend bool operator!=(const HugePageAllocator&, const HugePageAllocator&) { return false; }
};

// KiB of this process's anonymous memory in transparent huge pages now (AnonHugePages of
// /proc/self/smaps_rollup, else the sum over /proc/self/smaps); -1 if neither can be read. What
// `sfx calibrate --check` records per workload: whether the kernel granted the huge pages the
// allocator above asked for is a placement effect that holds for a whole allocation.
inline int64_t anon_huge_page_kib() {
    for (const char* path : {"/proc/self/smaps_rollup", "/proc/self/smaps"}) {
        std::ifstream in(path);
        if (!in) continue;
        int64_t total = 0;
        std::string key;
        while (in >> key) {
            if (key == "AnonHugePages:") {
                int64_t kib = 0;
                in >> kib;
                total += kib;
            }
            in.ignore(1 << 20, '\n');
        }
        return total;
    }
    return -1;
}

}  // namespace sfx
