// The other CPUs' load, read from /proc/stat.

#include "base/cpu_load.h"

#include <catch2/catch.hpp>
#include <thread>

using namespace sfx;

TEST_CASE("CPU times: one reading per CPU, busy within total, never going back", "[cycles]") {
    const std::vector<CpuTimes> a = read_cpu_times();
    REQUIRE(a.size() == size_t(std::thread::hardware_concurrency()));
    uint64_t x = 0;
    const uint64_t step = 1;
    for (int i = 0; i < 20000000; ++i) asm volatile("add %1, %0" : "+r"(x) : "r"(step));
    const std::vector<CpuTimes> b = read_cpu_times();
    REQUIRE(b.size() == a.size());
    for (size_t c = 0; c < a.size(); ++c) {
        CHECK(a[c].busy <= a[c].total);
        CHECK(b[c].busy >= a[c].busy);
        CHECK(b[c].total >= a[c].total);
    }
}
