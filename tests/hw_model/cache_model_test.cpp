// Scene-data caches: hits, misses, pseudo-LRU eviction and latencies on crafted address streams.

#include <catch2/catch.hpp>

#include "hw_model/cache_model.h"

using namespace sfx;

TEST_CASE("A cache hits on a line it holds and misses on a new one", "[hw_model][cache]") {
    SetAssociativeCache c({"l1", 1, 64, 2, 4});  // 16 lines, 8 sets of 2 ways
    CHECK_FALSE(c.access(0));
    CHECK(c.access(0));
    CHECK(c.access(63));       // same line
    CHECK_FALSE(c.access(64));  // next line
    CHECK(c.hits() == 2);
    CHECK(c.misses() == 2);
}

TEST_CASE("Pseudo-LRU evicts the line not recently used", "[hw_model][cache]") {
    SetAssociativeCache c({"l1", 1, 64, 4, 4});  // 16 lines: 4 sets of 4 ways
    const uint64_t set_stride = 4 * 64;         // addresses mapping to set 0
    for (uint64_t i = 0; i < 4; ++i) c.access(i * set_stride);  // fill ways 0..3
    CHECK(c.access(0));                  // way 0 recently used
    CHECK(c.access(1 * set_stride));     // way 1 recently used
    CHECK_FALSE(c.access(4 * set_stride));  // evicts from ways 2/3, not 0 or 1
    CHECK(c.access(0));
    CHECK(c.access(1 * set_stride));
    // Cyclic access over more lines than ways always misses.
    SetAssociativeCache d({"l1", 1, 64, 4, 4});
    uint64_t misses_before = 0;
    for (int round = 0; round < 3; ++round)
        for (uint64_t i = 0; i < 5; ++i) d.access(i * set_stride);
    misses_before = d.misses();
    CHECK(misses_before > 5);
}

TEST_CASE("The hierarchy charges the nearest level's latency and DRAM transfer",
          "[hw_model][cache]") {
    SceneMemoryConfig config;  // l1 4, l2 11, l3 39 cycles, DRAM 107
    config.dram_bandwidth_gbps = 32.0;  // at 500 MHz: 64 bytes per cycle, one cycle per line
    SceneMemoryModel memory(config, 500.0);
    CHECK(memory.read(4096, 32) == 107 + 1);  // cold: DRAM
    CHECK(memory.read(4096, 32) == 4);        // now in L1
    CHECK(memory.read(4096 + 60, 8) == 107 + 1);  // straddles into a cold line: the slower one
    CHECK(memory.dram_reads() == 2);
    CHECK(memory.levels()[0].hits() == 2);  // the warm line, twice
    // Evict from L1 only (32 KiB, 8-way: 64 sets): 9 lines in one L1 set, then re-read.
    const uint64_t l1_set_stride = 64 * 64;
    for (uint64_t i = 1; i <= 9; ++i) memory.read(4096 + i * l1_set_stride, 4);
    CHECK(memory.read(4096, 4) == 11);  // from L2
}
