#pragma once
// The core's own clock against the time-stamp counter. The TSC ticks at a constant rate while
// the core's clock moves with load and temperature (boost), and on a shared machine it moves
// between one measurement and the next; a cycle count that compares a microbenchmark with a
// frame must be in core cycles. A chain of dependent integer adds retires one add per core
// cycle on every x86-64 core, so timing it with the TSC gives TSC ticks per core cycle.

#include <cstdint>

namespace sfx {

// TSC ticks per core cycle now: the fastest of `runs` timings of a chain of 16 384 dependent
// adds (about 10 us each).
double tsc_ticks_per_core_cycle(int runs = 5);

}  // namespace sfx
