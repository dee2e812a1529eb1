#pragma once
// The core's own clock against the time-stamp counter. The TSC ticks at a constant rate while
// the core's clock moves with load and temperature (boost), and on a shared machine it moves
// between one measurement and the next; a cycle count that compares a microbenchmark with a
// frame must be in core cycles. A chain of dependent scalar adds of a register retires one add
// per core cycle on every x86-64 core (an add of an immediate need not: recent Intel cores fold
// such chains at rename), so timing it with the TSC gives TSC ticks per core cycle. On
// Intel cores the clock under AVX2 and AVX-512 code is lower than under scalar code (frequency
// licences), so the clock of a back end is measured with that back end's vector instructions
// running beside the chain: `lanes` 8 runs vpaddd and vmulps on ymm registers, 16 on zmm (the
// caller makes sure the CPU has them), anything else the scalar chain alone. The vector ops
// are not the ruler: their latency is not one cycle everywhere (vpaddd takes 2 on Zen 5).

#include <cstdint>

namespace sfx {

// TSC ticks per core cycle now: the fastest of `runs` timings of a chain of 16 384 dependent
// adds (about 10 us each) of the back end with `lanes` lanes.
double tsc_ticks_per_core_cycle(int runs = 5, uint32_t lanes = 1);

// What the chain runs: "add reg", "add reg beside vpaddd/vmulps ymm" or "... zmm".
const char* clock_chain_name(uint32_t lanes);

}  // namespace sfx
