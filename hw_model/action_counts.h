#pragma once
// What the hardware did in a frame, unit by unit, with no price attached: counting apart from
// costing (Accelergy's action counts). The timing models count; area_energy.h prices the counts
// with a technology table. Every field is a count of events or cycles, so counts add, subtract
// (between snapshots) and expand by a sampling weight exactly as cycles do.

#include <array>
#include <cmath>
#include <cstdint>

#include "hw_model/counter_info.h"
#include "kernels/trace.h"

namespace sfx {

// Units whose busy cycles are counted (idle = frame cycles - busy: the leakage of an idle unit).
enum class HwUnit : uint8_t { ray_buffer, agu, simd, partition, scratchpad, interconnect, count };
constexpr uint32_t k_hw_unit_count = uint32_t(HwUnit::count);
inline const char* to_string(HwUnit u) {
    static const char* names[] = {"ray_buffer", "agu",        "simd",
                                  "partition",  "scratchpad", "interconnect"};
    return names[size_t(u)];
}

struct ActionCounts {
    static constexpr uint32_t k_max_cache_levels = 8;  // check_hw_config allows at most 8

    // Ray buffers: one 32-bit word read from or written to one bank (ids, gathered and
    // scattered ray words, pushed ids, ids the partition moves).
    uint64_t bank_reads = 0;
    uint64_t bank_writes = 0;
    uint64_t agu_addresses = 0;  // addresses computed by the address-generation units
    // SIMD, per op kind: instructions issued (one per lane group) and lane-instructions that
    // carry a ray (the lanes doing useful work).
    std::array<uint64_t, k_op_kind_count> simd_instructions{};
    std::array<uint64_t, k_op_kind_count> simd_lane_ops{};
    uint64_t partition_compares = 0;      // mask lanes compared
    uint64_t partition_moves = 0;         // ids moved (their bank read and write are counted above)
    uint64_t scratchpad_accesses = 0;     // words read or written
    uint64_t interconnect_word_hops = 0;  // words moved x multiplexer levels crossed
    // Scene-data caches, nearest first: lookups, and lines filled on a miss.
    std::array<uint64_t, k_max_cache_levels> cache_accesses{};
    std::array<uint64_t, k_max_cache_levels> cache_fills{};
    uint64_t dram_bytes = 0;
    std::array<uint64_t, k_hw_unit_count> busy_cycles{};  // by HwUnit

    // Every counter of a and b in step, named (counter_info.h).
    template <class A, class B, class F>
    static void visit(A& a, B& b, F&& f) {
        f(CounterInfo("bank_reads", "words", "32-bit words read from ray-buffer banks"),
          a.bank_reads, b.bank_reads);
        f(CounterInfo("bank_writes", "words", "32-bit words written to ray-buffer banks"),
          a.bank_writes, b.bank_writes);
        f(CounterInfo("agu_addresses", "addresses", "addresses the AGUs computed"), a.agu_addresses,
          b.agu_addresses);
        for (uint32_t k = 0; k < k_op_kind_count; ++k) {
            const char* kind = to_string(OpKind(k));
            f(CounterInfo(kind, "instructions", "SIMD instructions issued (one per lane group)")
                  .under("simd_instructions"),
              a.simd_instructions[k], b.simd_instructions[k]);
            f(CounterInfo(kind, "lane-instructions", "lane-instructions that carry a ray")
                  .under("simd_lane_ops"),
              a.simd_lane_ops[k], b.simd_lane_ops[k]);
        }
        f(CounterInfo("partition_compares", "lanes", "mask lanes compared"), a.partition_compares,
          b.partition_compares);
        f(CounterInfo("partition_moves", "ids", "ids the partition moved"), a.partition_moves,
          b.partition_moves);
        f(CounterInfo("scratchpad_accesses", "words", "scratchpad words read or written"),
          a.scratchpad_accesses, b.scratchpad_accesses);
        f(CounterInfo("interconnect_word_hops", "word-hops",
                      "words moved x multiplexer levels crossed"),
          a.interconnect_word_hops, b.interconnect_word_hops);
        for (uint32_t i = 0; i < k_max_cache_levels; ++i) {
            f(CounterInfo(index_name(i), "lookups", "scene-cache lookups").under("cache_accesses"),
              a.cache_accesses[i], b.cache_accesses[i]);
            f(CounterInfo(index_name(i), "lines", "scene-cache lines filled").under("cache_fills"),
              a.cache_fills[i], b.cache_fills[i]);
        }
        f(CounterInfo("dram_bytes", "bytes", "scene-data bytes read from DRAM"), a.dram_bytes,
          b.dram_bytes);
        for (uint32_t u = 0; u < k_hw_unit_count; ++u)
            f(CounterInfo(to_string(HwUnit(u)), "cycles", "cycles the unit was busy")
                  .under("busy_cycles"),
              a.busy_cycles[u], b.busy_cycles[u]);
    }

    ActionCounts& operator+=(const ActionCounts& o) {
        visit(*this, o, [](const CounterInfo&, uint64_t& x, uint64_t y) { x += y; });
        return *this;
    }
    ActionCounts& operator-=(const ActionCounts& o) {
        visit(*this, o, [](const CounterInfo&, uint64_t& x, uint64_t y) { x -= y; });
        return *this;
    }
    // Adds o * weight, each counter rounded: a sampled pass expanded to its stratum.
    void add_scaled(const ActionCounts& o, double weight) {
        visit(*this, o, [weight](const CounterInfo&, uint64_t& x, uint64_t y) {
            x += uint64_t(std::llround(double(y) * weight));
        });
    }
    bool operator==(const ActionCounts& o) const {
        bool equal = true;
        visit(*this, o,
              [&equal](const CounterInfo&, uint64_t x, uint64_t y) { equal = equal && x == y; });
        return equal;
    }
};

}  // namespace sfx
