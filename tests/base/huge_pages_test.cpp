// HugePageAllocator: large arrays start on a 2 MiB boundary (what the kernel needs to back them
// by huge pages), small ones keep the type's alignment, and both hold what is written.

#include "base/huge_pages.h"

#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

using namespace sfx;

namespace {
struct alignas(32) Record {
    uint64_t value[4];
};
}  // namespace

TEST_CASE("HugePageAllocator: 2 MiB arrays are 2 MiB aligned, small ones keep their alignment",
          "[base]") {
    std::vector<Record, HugePageAllocator<Record>> large(k_huge_page_bytes / sizeof(Record) + 3);
    CHECK(reinterpret_cast<uintptr_t>(large.data()) % k_huge_page_bytes == 0);
    std::vector<Record, HugePageAllocator<Record>> small(5);
    CHECK(reinterpret_cast<uintptr_t>(small.data()) % alignof(Record) == 0);
    for (size_t i = 0; i < large.size(); ++i) large[i].value[3] = i;
    for (size_t i = 0; i < small.size(); ++i) small[i].value[0] = 7 * i;
    large.push_back(Record{{0, 0, 0, 99}});  // regrows into a new large allocation
    CHECK(reinterpret_cast<uintptr_t>(large.data()) % k_huge_page_bytes == 0);
    uint64_t wrong = 0;
    for (size_t i = 0; i + 1 < large.size(); ++i) wrong += large[i].value[3] != i;
    for (size_t i = 0; i < small.size(); ++i) wrong += small[i].value[0] != 7 * i;
    CHECK(wrong == 0);
    CHECK(large.back().value[3] == 99u);
}
