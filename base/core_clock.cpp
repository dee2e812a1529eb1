#include "base/core_clock.h"

#include <x86intrin.h>

#include <algorithm>

namespace sfx {

namespace {

// The ruler is always a chain of dependent scalar adds of a register (one a cycle on every
// x86-64 core). Not adds of an immediate: recent Intel renamers fold a chain of those (on this
// project's Intel Xeon VM, family 6 model 0xA7 with AMX, `add $1` chains ran 4 links a cycle,
// reading a 16.8 GHz clock, while `add reg, reg` and a 3-cycle imul chain both read 4.19 GHz).
// For a vector back end, each group of 8 adds runs beside one vpaddd of a chain in a vector
// register of the back end's width and one vmulps of another (both chains of at most 4 cycles
// a link, so neither is ever the critical path): the core runs at the clock it gives code that
// uses those registers (Intel's frequency licences), while the count stays the scalar chain's.
// A chain of the vector adds alone would be no ruler: their latency is 1 cycle on Haswell to
// Zen 4 but 2 on Zen 5, where such a chain reads half the clock.
// Eight adds of the ruler beside one link of each vector chain, in the registers R (ymm, zmm);
// registers 2 and 3 hold 1.0f (so vmulps never meets a denormal), register 1 anything; `step`
// is the ruler's addend.
// clang-format off
#define SFX_VECTOR_CLOCK_LOOP(R)                                                                \
    asm volatile("vbroadcastss %0, %%" R "2\n\tvbroadcastss %0, %%" R "3" ::"m"(k_one)          \
                 : "xmm2", "xmm3");                                                             \
    start = __rdtsc();                                                                          \
    for (uint64_t i = 0; i < adds / 8; ++i)                                                     \
        asm volatile("add %1, %0\n\tvpaddd %%" R "1, %%" R "0, %%" R "0\n\tadd %1, %0\n\t"        \
                     "vmulps %%" R "3, %%" R "2, %%" R "2\n\tadd %1, %0\n\tadd %1, %0\n\t"       \
                     "add %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\tadd %1, %0"                      \
                     : "+r"(x)                                                                  \
                     : "r"(step)                                                                \
                     : "xmm0", "xmm2")
// clang-format on

uint64_t chain_ticks(uint32_t lanes, uint64_t adds, uint64_t seed) {
    uint64_t x = seed;
    const uint64_t step = seed | 1;
    static const float k_one = 1.0f;
    uint64_t start = 0;
    if (lanes == 16) {
        SFX_VECTOR_CLOCK_LOOP("zmm");
    } else if (lanes == 8) {
        SFX_VECTOR_CLOCK_LOOP("ymm");
    } else {
        start = __rdtsc();
        for (uint64_t i = 0; i < adds / 4; ++i)
            asm volatile("add %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\tadd %1, %0"
                         : "+r"(x)
                         : "r"(step));
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
    return lanes == 16 ? "add reg beside vpaddd/vmulps zmm"
                       : lanes == 8 ? "add reg beside vpaddd/vmulps ymm" : "add reg";
}

}  // namespace sfx
