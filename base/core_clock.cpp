#include "base/core_clock.h"

#include <x86intrin.h>

#include <algorithm>

namespace sfx {

double tsc_ticks_per_core_cycle(int runs) {
    constexpr uint64_t k_adds = 16384;  // 4 per iteration
    uint64_t best = ~0ull;
    for (int r = 0; r < runs; ++r) {
        uint64_t x = uint64_t(r);
        const uint64_t start = __rdtsc();
        for (uint64_t i = 0; i < k_adds / 4; ++i)
            asm volatile("add $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\tadd $1, %0" : "+r"(x));
        best = std::min<uint64_t>(best, __rdtsc() - start);
    }
    return double(best) / double(k_adds);
}

}  // namespace sfx
