#include "base/core_clock.h"

#include <x86intrin.h>

#include <algorithm>

namespace sfx {

namespace {

// 4 dependent adds per iteration; the loop's own increment and branch run beside the chain.
uint64_t chain_ticks(uint32_t lanes, uint64_t adds, uint64_t seed) {
    uint64_t x = seed;
    const uint64_t start = __rdtsc();
    if (lanes == 16) {
        for (uint64_t i = 0; i < adds / 4; ++i)
            asm volatile(
                "vpaddd %%zmm1, %%zmm0, %%zmm0\n\tvpaddd %%zmm1, %%zmm0, %%zmm0\n\t"
                "vpaddd %%zmm1, %%zmm0, %%zmm0\n\tvpaddd %%zmm1, %%zmm0, %%zmm0" ::
                    : "xmm0");
    } else if (lanes == 8) {
        for (uint64_t i = 0; i < adds / 4; ++i)
            asm volatile(
                "vpaddd %%ymm1, %%ymm0, %%ymm0\n\tvpaddd %%ymm1, %%ymm0, %%ymm0\n\t"
                "vpaddd %%ymm1, %%ymm0, %%ymm0\n\tvpaddd %%ymm1, %%ymm0, %%ymm0" ::
                    : "xmm0");
    } else {
        for (uint64_t i = 0; i < adds / 4; ++i)
            asm volatile("add $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\tadd $1, %0" : "+r"(x));
    }
    const uint64_t ticks = __rdtsc() - start;
    // The upper halves of the vector registers are dirty after a wide chain: clean them, so
    // that SSE code after it pays no transition.
    if (lanes == 8 || lanes == 16) asm volatile("vzeroupper" ::: "xmm0", "xmm1");
    return ticks;
}

}  // namespace

double tsc_ticks_per_core_cycle(int runs, uint32_t lanes) {
    constexpr uint64_t k_adds = 16384;
    uint64_t best = ~0ull;
    for (int r = 0; r < runs; ++r) best = std::min(best, chain_ticks(lanes, k_adds, uint64_t(r)));
    return double(best) / double(k_adds);
}

const char* clock_chain_name(uint32_t lanes) {
    return lanes == 16 ? "vpaddd zmm" : lanes == 8 ? "vpaddd ymm" : "add";
}

}  // namespace sfx
