#include "base/cache_eviction.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <vector>

#include "base/huge_pages.h"

namespace sfx {

uint64_t eviction_bytes(uint64_t largest_cache_bytes) {
    return std::max(k_min_eviction_bytes, 3 * largest_cache_bytes);
}

uint64_t largest_cache_bytes(const std::string& cache_dir) {
    uint64_t largest = 0;
    for (int i = 0; i < 16; ++i) {
        std::ifstream in(cache_dir + "/index" + std::to_string(i) + "/size");
        uint64_t n = 0;
        char unit = 0;
        if (!(in >> n)) continue;
        in >> unit;
        const uint64_t scale = unit == 'K' ? 1u << 10 : unit == 'M' ? 1u << 20 : 1u;
        largest = std::max(largest, n * scale);
    }
    return largest;
}

void evict_caches() {
    static const uint64_t bytes = eviction_bytes(largest_cache_bytes());
    static std::vector<uint64_t, HugePageAllocator<uint64_t>> other(bytes / sizeof(uint64_t), 1);
    uint64_t sum = 0;
    for (size_t i = 0; i < other.size(); i += 8) sum += other[i];  // one read a line
    if (sum == 0) std::fprintf(stderr, " ");                       // keeps the reads
}

}  // namespace sfx
