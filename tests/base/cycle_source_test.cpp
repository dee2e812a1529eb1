// The cycle source: counted where perf_event_open gives a working counter, else the estimate,
// taken cleanly when the counter is refused (the refusal injected, so this runs on any host);
// the estimate's clock chain on every back end this CPU runs.

#include "base/cycle_source.h"

#include <linux/perf_event.h>
#include <unistd.h>
#include <x86intrin.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cerrno>

#include "base/core_clock.h"
#include "hw_model/host_description.h"
#include "kernels/simd/isa.h"

using namespace sfx;

namespace {

// Work the region measures: `n` dependent adds of a register (adds of an immediate may be
// folded at rename, several a cycle).
uint64_t busy(uint64_t n) {
    uint64_t x = 1;
    const uint64_t step = 3;
    for (uint64_t i = 0; i < n; ++i) asm volatile("add %1, %0" : "+r"(x) : "r"(step));
    return x;
}

// TSC ticks a link of a chain of 64-bit multiplies (3 cycles a link on every x86-64 core since
// Nehalem and Zen), the fastest of `runs`: a second ruler no renamer can fold.
double tsc_ticks_per_multiply(int runs) {
    constexpr uint64_t k_links = 16384;
    uint64_t best = ~0ull;
    for (int r = 0; r < runs; ++r) {
        uint64_t x = uint64_t(r) + 1;
        const uint64_t factor = 3;
        const uint64_t start = __rdtsc();
        for (uint64_t i = 0; i < k_links / 4; ++i)
            asm volatile("imul %1, %0\n\timul %1, %0\n\timul %1, %0\n\timul %1, %0"
                         : "+r"(x)
                         : "r"(factor));
        best = std::min<uint64_t>(best, __rdtsc() - start);
    }
    return double(best) / double(k_links);
}

}  // namespace

TEST_CASE("Cycle source: a refused counter falls back to the estimate", "[cycles]") {
    const double tsc_mhz = measure_tsc_mhz(0.05);
    for (const int refusal : {ENOENT, EOPNOTSUPP, EACCES}) {
        for (const Isa isa : supported_isas()) {
            bool asked = false;
            CycleSource source(isa_width(isa), tsc_mhz, [&](perf_event_attr& attr) {
                asked = true;
                // What is asked for: the thread's user-mode core cycles.
                CHECK(attr.type == PERF_TYPE_HARDWARE);
                CHECK(attr.config == PERF_COUNT_HW_CPU_CYCLES);
                CHECK(attr.exclude_kernel == 1);
                errno = refusal;
                return -1;
            });
            INFO("back end " << isa_name(isa) << ", errno " << refusal);
            CHECK(asked);
            CHECK_FALSE(source.counted());
            CHECK(source.description().find("estimated") == 0);
            CHECK(source.description().find(clock_chain_name(isa_width(isa))) != std::string::npos);
            CHECK(source.refusal().find(refusal == ENOENT       ? "ENOENT"
                                        : refusal == EOPNOTSUPP ? "EOPNOTSUPP"
                                                                : "EACCES") != std::string::npos);
            source.start();
            CHECK(busy(2000000) > 0);
            const CycleReading r = source.stop();
            CHECK(r.cpu_seconds > 0);
            CHECK(r.cycles > 0);
            // Both clocks measured, each a plausible core clock (0.3 to 8 GHz).
            CHECK(r.clock_mhz_before > 300);
            CHECK(r.clock_mhz_before < 8000);
            CHECK(r.clock_mhz_after > 300);
            CHECK(r.clock_mhz_after < 8000);
            CHECK(r.cycles ==
                  Approx(r.cpu_seconds * 0.5 * (r.clock_mhz_before + r.clock_mhz_after) * 1e6));
        }
    }
}

TEST_CASE("Cycle source: a counter that opens but counts nothing is refused too", "[cycles]") {
    // A descriptor that reads as zero cycles: a pipe with nothing in it would block, so a
    // regular file of zeros stands in.
    char path[] = "/tmp/sfx-cycles-XXXXXX";
    const int fd = mkstemp(path);
    REQUIRE(fd >= 0);
    const uint64_t zeros[3] = {0, 0, 0};
    REQUIRE(write(fd, zeros, sizeof zeros) == ssize_t(sizeof zeros));
    lseek(fd, 0, SEEK_SET);
    unlink(path);
    const CycleSource source(1, measure_tsc_mhz(0.05), [&](perf_event_attr&) { return fd; });
    CHECK_FALSE(source.counted());
    CHECK(source.refusal().find("counted nothing") != std::string::npos);
}

TEST_CASE("Cycle source: this host's own, counted or estimated, measures a region", "[cycles]") {
    CycleSource source(1, measure_tsc_mhz(0.05));
    INFO(source.description());
    CHECK((source.counted() ? source.refusal().empty() : !source.refusal().empty()));
    source.start();
    CHECK(busy(2000000) > 0);
    const CycleReading r = source.stop();
    CHECK(r.cycles > 0);
    // 2e6 dependent adds take at least 2e6 cycles, and (loaded machine) far less than 100x.
    CHECK(r.cycles > 1e6);
    CHECK(r.cycles < 2e8);
}

TEST_CASE("Core clock: every back end's chain gives a plausible clock", "[cycles]") {
    const double tsc_mhz = measure_tsc_mhz(0.05);
    const double scalar_mhz = tsc_mhz / tsc_ticks_per_core_cycle(5, 1);
    for (const Isa isa : supported_isas()) {
        const double mhz = tsc_mhz / tsc_ticks_per_core_cycle(5, isa_width(isa));
        INFO(isa_name(isa) << ": " << mhz << " MHz, scalar " << scalar_mhz << " MHz");
        CHECK(mhz > 300);
        CHECK(mhz < 8000);
        // A frequency licence lowers the vector clock by a third at most; a ruler whose links
        // took two cycles (a chain of vpaddd on Zen 5) would read half.
        CHECK(mhz > 0.6 * scalar_mhz);
    }
}

TEST_CASE("Core clock: the add chain reads the clock a multiply chain reads", "[cycles]") {
    // The ruler's links take one cycle: a renamer that folded them (as Intel's fold adds of an
    // immediate) would read a clock several times too fast. Interleaved, fastest of each.
    double add_ticks = 1e9, multiply_ticks = 1e9;
    for (int round = 0; round < 5; ++round) {
        add_ticks = std::min(add_ticks, tsc_ticks_per_core_cycle(5, 1));
        multiply_ticks = std::min(multiply_ticks, tsc_ticks_per_multiply(5) / 3.0);
    }
    INFO("ticks a cycle: add chain " << add_ticks << ", multiply chain " << multiply_ticks);
    CHECK(add_ticks == Approx(multiply_ticks).epsilon(0.15));
}

TEST_CASE("Cycle source: how far the estimate's clock moved over a region", "[cycles]") {
    CycleReading r;
    CHECK(clock_moved(r) == 0.0);  // no clock
    r.clock_mhz_before = r.clock_mhz_after = 4000.0;
    CHECK(clock_moved(r) == 0.0);  // steady (and every counted reading)
    r.clock_mhz_before = 3584.0;
    r.clock_mhz_after = 4081.0;  // a frequency step seen on an Intel VM: 13.9 % of the lower
    CHECK(clock_moved(r) == Approx(497.0 / 3584.0));
    std::swap(r.clock_mhz_before, r.clock_mhz_after);
    CHECK(clock_moved(r) == Approx(497.0 / 3584.0));
}
