// Scene-data caches: hits, misses, pseudo-LRU eviction and latencies on crafted address streams.

#include "hw_model/cache_model.h"

#include <catch2/catch.hpp>

#include "hw_model/op_costs.h"

using namespace sfx;

TEST_CASE("A cache hits on a line it holds and misses on a new one", "[hw_model][cache]") {
    SetAssociativeCache c({"l1", 1, 64, 2, 4});  // 16 lines, 8 sets of 2 ways
    CHECK_FALSE(c.access(0));
    CHECK(c.access(0));
    CHECK(c.access(63));        // same line
    CHECK_FALSE(c.access(64));  // next line
    CHECK(c.hits() == 2);
    CHECK(c.misses() == 2);
}

TEST_CASE("A measured size becomes a cache's in whole sets, whatever its ways",
          "[hw_model][cache]") {
    // 20 ways of 64-byte lines: sets of 1280 bytes, whole KiB every 5 KiB.
    CHECK(whole_sets_kib(35330, 20, 64) == 35330);
    CHECK(whole_sets_kib(35332, 20, 64) == 35330);
    CHECK(whole_sets_kib(35333, 20, 64) == 35335);
    CHECK(whole_sets_kib(1, 20, 64) == 5);
    CHECK(whole_sets_kib(34567, 16, 64) == 34567);  // 16 ways: every KiB
    CHECK(whole_sets_kib(34567, 12, 64) == 34566);  // 768-byte sets: every 3 KiB
    SetAssociativeCache c({"l3", whole_sets_kib(34567, 20, 64), 64, 20, 40});
    CHECK_FALSE(c.access(0));
    CHECK(c.access(0));
    CHECK_THROWS_WITH(SetAssociativeCache({"l3", 34567, 64, 20, 40}),
                      "cache l3: 34567 KiB is not a whole number of sets of 20 ways of 64-byte "
                      "lines");
}

TEST_CASE("Pseudo-LRU evicts the line not recently used", "[hw_model][cache]") {
    SetAssociativeCache c({"l1", 1, 64, 4, 4});                 // 16 lines: 4 sets of 4 ways
    const uint64_t set_stride = 4 * 64;                         // addresses mapping to set 0
    for (uint64_t i = 0; i < 4; ++i) c.access(i * set_stride);  // fill ways 0..3
    CHECK(c.access(0));                                         // way 0 recently used
    CHECK(c.access(1 * set_stride));                            // way 1 recently used
    CHECK_FALSE(c.access(4 * set_stride));                      // evicts from ways 2/3, not 0 or 1
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

TEST_CASE("Others' fills into a shared level evict a line left untouched long enough",
          "[hw_model][cache]") {
    // 64 lines of 4 ways: 16 sets; at 1000 MHz others fill 1 line a microsecond, so a set gets
    // one in 16000 cycles and all 4 of its ways in 64000.
    CacheLevelConfig level{"l3", 4, 64, 4, 10, true};
    level.foreign_fill_per_us = 1.0;
    SetAssociativeCache c(level, 1000.0);
    CHECK_FALSE(c.access(0, 0));
    CHECK(c.access(0, 16000));                // one of theirs since: the line, just touched, stays
    CHECK(c.access(0, 48000));                // two more since its last touch
    CHECK_FALSE(c.access(0, 48000 + 64000));  // four: the whole set is theirs
    // Touched often enough, it stays however long the run.
    for (uint64_t t = 48000 + 64000; t < 1'000'000; t += 32000) CHECK(c.access(0, t));
    // Without others' fills, nothing is lost by waiting.
    level.foreign_fill_per_us = 0.0;
    SetAssociativeCache own(level, 1000.0);
    own.access(0, 0);
    CHECK(own.access(0, 1'000'000'000));
}

TEST_CASE("DRAM's latency is the one at the scene's span on a page's first use",
          "[hw_model][cache]") {
    SceneMemoryConfig config;
    config.dram_latency_ns = 300.0;
    CHECK(dram_latency_ns_at(config, 8u << 20) == 300.0);  // no table: the one latency
    config.dram_latency_by_span = {{4, 100.0}, {16, 200.0}, {64, 250.0}};
    CHECK(dram_latency_ns_at(config, 0) == 300.0);                  // span unknown
    CHECK(dram_latency_ns_at(config, 1u << 20) == 100.0);           // below the first span
    CHECK(dram_latency_ns_at(config, 4u << 20) == Approx(100.0));   // at a span
    CHECK(dram_latency_ns_at(config, 8u << 20) == Approx(141.42));  // log-log: sqrt(100 x 200)
    CHECK(dram_latency_ns_at(config, 1ull << 30) == 250.0);         // beyond the last
    // The model reads DRAM at that latency: no caches, 1000 MHz (a cycle a ns), one line.
    config.caches.clear();
    config.dram_bandwidth_gbps = 64.0;  // a line a cycle
    SceneMemoryModel small(config, 1000.0, 1, nullptr, 4u << 20);
    SceneMemoryModel large(config, 1000.0, 1, nullptr, 64u << 20);
    CHECK(small.read(0, 64) == 100 + 1);
    CHECK(large.read(0, 64) == 250 + 1);
    // The span is the scene data's: nodes, primitive records, mesh records and vertices.
    SceneDataMap map;
    map.nodes = 10;
    map.triangles = 4;
    map.spheres = 1;
    map.vertices = 6;
    CHECK(map.span_bytes() == 10 * 32 + 4 * (36 + 16) + 6 * 12 + 16);
    map.vertices = 0;  // unknown: three a triangle
    CHECK(map.span_bytes() == 10 * 32 + 4 * (36 + 16) + 12 * 12 + 16);
}

TEST_CASE("Page recency counts the distinct pages used since a page's last use",
          "[hw_model][cache]") {
    const uint64_t page = PageRecency::k_page_bytes;
    PageRecency pages;
    CHECK(pages.use(0) == PageRecency::k_never);
    CHECK(pages.use(64) == 0);  // the same page
    CHECK(pages.use(1 * page) == PageRecency::k_never);
    CHECK(pages.use(2 * page) == PageRecency::k_never);
    CHECK(pages.use(1 * page + 8) == 1);  // page 2 since
    CHECK(pages.use(0) == 2);             // pages 2 and 1, once each however often used
    // Thousands of uses (the tree renumbers its times as it fills): still exact.
    for (uint64_t i = 0; i < 5000; ++i) pages.use((10 + i % 2500) * page);
    CHECK(pages.use(0) == 2500);
    CHECK(pages.use((10 + 2499) * page) == 1);  // page 0 since
    CHECK(pages.use(2 * page) == 2502);         // all but itself: 0, 1 and the 2500
    // Pages far above a scene's (a mesh's arrays, the ray buffers) count alike.
    const uint64_t far = uint64_t(1) << 44;
    CHECK(pages.use(far) == PageRecency::k_never);
    for (uint64_t i = 0; i < 3000; ++i) pages.use(far + (1 + i % 1500) * page);
    CHECK(pages.use(far + 8) == 1500);
    CHECK(pages.use(2 * page) == 1501);  // the far ones since, and far itself
}

TEST_CASE("A DRAM read's latency follows the pages used since its page's last use",
          "[hw_model][cache]") {
    SceneMemoryConfig config;
    config.caches.clear();              // every read from DRAM
    config.dram_bandwidth_gbps = 64.0;  // at 1000 MHz: a line a cycle
    config.dram_latency_ns = 300.0;
    config.dram_latency_by_span = {{4, 100.0}, {16, 200.0}, {64, 250.0}};
    const uint64_t page = PageRecency::k_page_bytes;
    SceneMemoryModel memory(config, 1000.0, 1, nullptr, 64u << 20);
    uint64_t now = 0;
    auto latency = [&](uint64_t address) {
        now += 10000;  // the channel idle
        return memory.read(0, address, 4, now) - now;
    };
    CHECK(latency(0) == 250 + 1);   // a first use: the span's
    CHECK(latency(64) == 100 + 1);  // its page just used: a chase of 8 KiB, the first point
    for (uint64_t p = 1; p <= 1023; ++p) latency(p * page);
    // 1023 pages since: a chase over 2 x 1024 pages (8 MiB), sqrt(100 x 200) = 141.4 ns.
    CHECK(latency(128) == 142 + 1);
    for (uint64_t p = 1; p <= 8191; ++p) latency(p * page);
    CHECK(latency(192) == 250 + 1);  // 8191 since: 64 MiB
    // Not beyond the span: a chase over more than the scene's data is the span's.
    SceneMemoryModel small(config, 1000.0, 1, nullptr, 4u << 20);
    now = 0;
    now += 10000;
    CHECK(small.read(0, 0, 4, now) - now == 100 + 1);
    for (uint64_t p = 1; p <= 8191; ++p) small.read(0, p * page, 4, now += 10000);
    now += 10000;
    CHECK(small.read(0, 64, 4, now) - now == 100 + 1);
    // Without a table, one latency for every read however recent its page.
    config.dram_latency_by_span.clear();
    SceneMemoryModel flat(config, 1000.0, 1, nullptr, 64u << 20);
    now = 0;
    now += 10000;
    CHECK(flat.read(0, 0, 4, now) - now == 300 + 1);
    now += 10000;
    CHECK(flat.read(0, 64, 4, now) - now == 300 + 1);
}

TEST_CASE("The hierarchy charges the nearest level's latency and DRAM transfer",
          "[hw_model][cache]") {
    SceneMemoryConfig config;       // at 500 MHz (2 ns): l1 1.4 ns -> 1, l2 3.8 -> 2, l3 13.3 -> 7
    config.dram_latency_ns = 36.5;  // -> 19 cycles
    config.dram_bandwidth_gbps = 32.0;  // at 500 MHz: 64 bytes per cycle, one cycle per line
    SceneMemoryModel memory(config, 500.0);
    CHECK(memory.read(0, 4096, 32, 0) == 19 + 1);     // cold: DRAM
    CHECK(memory.read(0, 4096, 32, 100) == 100 + 1);  // now in L1
    // Straddles into a cold line: the slower one.
    CHECK(memory.read(0, 4096 + 60, 8, 100) == 100 + 19 + 1);
    CHECK(memory.dram_reads() == 2);
    CHECK(memory.hits(0) == 2);  // the warm line, twice
    // Evict from L1 only (32 KiB, 8-way: 64 sets): 9 lines in one L1 set, then re-read.
    const uint64_t l1_set_stride = 64 * 64;
    for (uint64_t i = 1; i <= 9; ++i) memory.read(0, 4096 + i * l1_set_stride, 4, 200);
    CHECK(memory.read(0, 4096, 4, 1000) == 1000 + 2);  // from L2
}

TEST_CASE("A read of a line whose fill is in flight waits for that fill", "[hw_model][cache]") {
    SceneMemoryConfig config;  // at 500 MHz: l1 1 cycle, l3 7, DRAM 19 + 1 for the transfer
    config.dram_latency_ns = 36.5;
    config.dram_bandwidth_gbps = 32.0;
    SceneMemoryModel memory(config, 500.0, 2);
    CHECK(memory.read(0, 8192, 4, 100) == 120);  // cold: DRAM
    // The caches hold the line from the read on; the data is not there before the fill.
    uint64_t unloaded = 0;
    CHECK(memory.read(0, 8192 + 32, 4, 105, &unloaded) == 120);
    CHECK(unloaded == 1);  // the level's own latency: no other read's wait
    CHECK(memory.hits(0) == 1);
    CHECK(memory.read(1, 8192 + 8, 4, 110) == 120);  // another core, through the shared L3
    CHECK(memory.read(0, 8192, 4, 130) == 131);      // arrived: an L1 hit
    // A read timed before the fill's own (reads are not always made in time order) would
    // have missed itself: it waits no longer than the fill's latency.
    CHECK(memory.read(0, 8192 + 16, 4, 90) == 110);
    CHECK(memory.dram_reads() == 1);
}

TEST_CASE("DRAM bandwidth is shared: lines queue for the channel", "[hw_model][cache]") {
    SceneMemoryConfig config;
    config.caches.clear();
    config.dram_latency_ns = 20.0;     // 10 cycles at 500 MHz
    config.dram_bandwidth_gbps = 8.0;  // 16 bytes per cycle: a 64-byte line takes 4 cycles
    SceneMemoryModel memory(config, 500.0, 2);
    CHECK(memory.read(0, 0, 64, 100) == 100 + 10 + 4);
    CHECK(memory.read(1, 4096, 64, 100) == 100 + 10 + 8);  // the other core's line waits
    CHECK(ns_to_cycles(2.0, 500.0) == 1);
    CHECK(ns_to_cycles(2.1, 500.0) == 2);
}

TEST_CASE("Private levels are per core, shared levels see every core", "[hw_model][cache]") {
    SceneMemoryConfig config;  // l1, l2 private; l3 shared
    SceneMemoryModel memory(config, 500.0, 2);
    const uint64_t cold = memory.read(0, 8192, 4, 0);
    CHECK(memory.read(0, 8192, 4, 1000) == 1000 + 1);  // core 0's L1
    CHECK(memory.read(1, 8192, 4, 2000) == 2000 + 7);  // core 1 finds it in the shared L3
    CHECK(cold > 7);
}

TEST_CASE("Shared cache lookups time every reader as its own caches would", "[hw_model][cache]") {
    // Two machines with the same lookups (same_cache_lookups: one core, equal geometry and
    // prefetch) but other latencies, each reading the same addresses; one reads ahead of the
    // other, as one configuration of a group runs ahead of another.
    HwConfig a, b;
    b.scene_memory.caches[1].hit_latency_ns = 9.0;
    b.scene_memory.dram_latency_ns = 80.0;
    REQUIRE(same_cache_lookups(a, b));
    HwConfig other = a;
    other.scene_memory.caches[0].ways = 4;
    CHECK_FALSE(same_cache_lookups(a, other));
    other = a;
    other.scene_memory.caches.back().pair_fill = true;  // fills lines a read never asked for
    CHECK_FALSE(same_cache_lookups(a, other));
    other = a;
    other.cores.count = 2;  // passes go to cores as their timing decides
    CHECK_FALSE(same_cache_lookups(a, other));
    other = a;
    other.scene_memory.hit_reads = "mesh";  // the lanes' hit primitives read elsewhere
    CHECK_FALSE(same_cache_lookups(a, other));
    other = a;
    other.ray_buffer.storage = "l1d";  // a CPU core reads its ray lines through the caches
    CHECK_FALSE(same_cache_lookups(a, other));
    HwConfig l1d = other;
    CHECK(same_cache_lookups(l1d, other));
    other.ray_buffer.slot_bytes = 330;  // at other addresses
    CHECK_FALSE(same_cache_lookups(l1d, other));

    auto shared = std::make_shared<SharedCacheLookups>(a.scene_memory.caches);
    SceneMemoryModel own_a(a.scene_memory, 500.0), own_b(b.scene_memory, 500.0);
    SceneMemoryModel shared_a(a.scene_memory, 500.0, 1, shared);
    SceneMemoryModel shared_b(b.scene_memory, 500.0, 1, shared);
    std::vector<uint64_t> addresses;
    uint64_t x = 12345;
    for (int i = 0; i < 20000; ++i) {  // enough to forget what both have read
        x = x * 6364136223846793005ull + 1442695040888963407ull;
        addresses.push_back((x >> 33) % (4u << 20));
    }
    for (size_t i = 0; i < addresses.size(); ++i) {
        CHECK(shared_a.read(0, addresses[i], 36, i) == own_a.read(0, addresses[i], 36, i));
        if (i % 7 == 0) {  // other data between the reads: looked up alike, counted nowhere
            shared_a.touch_other(0, (uint64_t(1) << 44) + addresses[i], 330, i);
            own_a.touch_other(0, (uint64_t(1) << 44) + addresses[i], 330, i);
        }
        if (i >= 5000) {  // b trails a by 5000 reads
            const size_t j = i - 5000;
            CHECK(shared_b.read(0, addresses[j], 36, j) == own_b.read(0, addresses[j], 36, j));
            if (j % 7 == 0) {
                shared_b.touch_other(0, (uint64_t(1) << 44) + addresses[j], 330, j);
                own_b.touch_other(0, (uint64_t(1) << 44) + addresses[j], 330, j);
            }
        }
    }
    for (uint32_t level = 0; level < own_a.level_count(); ++level) {
        CHECK(shared_a.hits(level) == own_a.hits(level));
        CHECK(shared_a.misses(level) == own_a.misses(level));
        CHECK(shared_b.hits(level) == own_b.hits(level));
    }
    CHECK(shared_a.dram_reads() == own_a.dram_reads());
    // A reader that looks up another line than the one simulated is a logic error.
    CHECK_THROWS_AS(shared_b.read(0, addresses[0] + 4096 * 64, 4, 0), std::logic_error);
}

TEST_CASE("Other data read through the caches evicts scene lines and is not counted",
          "[hw_model][cache]") {
    // One level of 1 KiB (16 lines: 8 sets of 2 ways) before DRAM.
    SceneMemoryConfig memory;
    memory.caches = {{"l1", 1, 64, 2, 2.0}};
    memory.dram_latency_ns = 50.0;
    SceneMemoryModel model(memory, 1000.0);
    model.read(0, 0, 4, 0);
    CHECK(model.read(0, 0, 4, 100) == 100 + 2);          // a hit
    model.touch_other(0, uint64_t(1) << 44, 2048, 200);  // 32 lines of other data: 2 KiB
    CHECK(model.hits(0) == 1);
    CHECK(model.misses(0) == 1);
    CHECK(model.requests() == 2);
    CHECK(model.read(0, 0, 4, 300) > 300 + 2);  // evicted: from DRAM again
    CHECK(model.dram_reads() == 2);
    model.touch_other(0, 0, 0, 400);  // nothing
    CHECK(model.read(0, 0, 4, 500) == 500 + 2);
}

TEST_CASE("A read from DRAM fills its 128-byte pair's other line into a last level that pairs",
          "[hw_model][cache]") {
    for (const bool pairs : {false, true}) {
        SceneMemoryConfig config;  // l1, l2, l3 (the last) at 500 MHz: 1, 2 and 7 cycles
        config.dram_latency_ns = 36.5;
        config.dram_bandwidth_gbps = 32.0;
        config.caches.back().pair_fill = pairs;
        SceneMemoryModel memory(config, 500.0);
        memory.read(0, 4096, 8, 0);  // from DRAM: line 64, whose pair's other line is 65
        // The other line of the pair: in the last level only (not the first two), where it pairs.
        CHECK(memory.read(0, 4096 + 64, 8, 100) == (pairs ? 100 + 7 : 100 + 19 + 1));
        CHECK(memory.dram_reads() == (pairs ? 1 : 2));
        CHECK(memory.hits(2) == (pairs ? 1 : 0));
        // Line 66's pair (67) too; a line read again from the first level brings nothing new.
        memory.read(0, 4096 + 128, 8, 200);
        CHECK(memory.read(0, 4096 + 192, 8, 300) == (pairs ? 300 + 7 : 300 + 19 + 1));
    }
    SetAssociativeCache c({"l3", 1, 64, 2, 4});
    c.fill(128);  // a prefetch: placed, not counted
    CHECK(c.hits() == 0);
    CHECK(c.misses() == 0);
    CHECK(c.access(128));
}
