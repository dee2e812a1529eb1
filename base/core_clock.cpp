#include "base/core_clock.h"

#include <x86intrin.h>

#include <algorithm>

namespace sfx {

namespace {

// The ruler is always a chain of dependent scalar adds (one a cycle on every x86-64 core).
// For a vector back end, each group of 8 adds runs beside one vpaddd of a chain in a vector
// register of the back end's width and one vmulps of another (both chains of at most 4 cycles
// a link, so neither is ever the critical path): the core runs at the clock it gives code that
// uses those registers (Intel's frequency licences), while the count stays the scalar chain's.
// A chain of the vector adds alone would be no ruler: their latency is 1 cycle on Haswell to
// Zen 4 but 2 on Zen 5, where such a chain reads half the clock.
uint64_t chain_ticks(uint32_t lanes, uint64_t adds, uint64_t seed) {
    uint64_t x = seed;
    static const float k_one = 1.0f;
    uint64_t start = 0;
    if (lanes == 16) {
        asm volatile("vpxord %%zmm1, %%zmm1, %%zmm1\n\tvbroadcastss %0, %%zmm2\n\t"
                     "vbroadcastss %0, %%zmm3" ::"m"(k_one)
                     : "xmm1", "xmm2", "xmm3");
        start = __rdtsc();
        for (uint64_t i = 0; i < adds / 8; ++i)
            asm volatile(
                "add $1, %0\n\tvpaddd %%zmm1, %%zmm0, %%zmm0\n\tadd $1, %0\n\t"
                "vmulps %%zmm3, %%zmm2, %%zmm2\n\tadd $1, %0\n\tadd $1, %0\n\t"
                "add $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\tadd $1, %0"
                : "+r"(x)::"xmm0", "xmm2");
    } else if (lanes == 8) {
        asm volatile("vpxor %%ymm1, %%ymm1, %%ymm1\n\tvbroadcastss %0, %%ymm2\n\t"
                     "vbroadcastss %0, %%ymm3" ::"m"(k_one)
                     : "xmm1", "xmm2", "xmm3");
        start = __rdtsc();
        for (uint64_t i = 0; i < adds / 8; ++i)
            asm volatile(
                "add $1, %0\n\tvpaddd %%ymm1, %%ymm0, %%ymm0\n\tadd $1, %0\n\t"
                "vmulps %%ymm3, %%ymm2, %%ymm2\n\tadd $1, %0\n\tadd $1, %0\n\t"
                "add $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\tadd $1, %0"
                : "+r"(x)::"xmm0", "xmm2");
    } else {
        start = __rdtsc();
        for (uint64_t i = 0; i < adds / 4; ++i)
            asm volatile("add $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\tadd $1, %0" : "+r"(x));
    }
    const uint64_t ticks = __rdtsc() - start;
    // The upper halves of the vector registers are dirty after a wide chain: clean them, so
    // that SSE code after it pays no transition.
    if (lanes == 8 || lanes == 16) asm volatile("vzeroupper" ::: "xmm0", "xmm1", "xmm2", "xmm3");
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
    return lanes == 16 ? "add beside vpaddd/vmulps zmm"
                       : lanes == 8 ? "add beside vpaddd/vmulps ymm" : "add";
}

}  // namespace sfx
