#pragma once
// Scene-data memory: a hierarchy of set-associative caches with tree pseudo-LRU replacement
// (Bikker's model: 32 KiB / 256 KiB / 2 MiB, 8/8/16-way) in front of DRAM. Plain C++; the
// SystemC scene-memory module wraps it. Reads only: scene data is read-only while tracing.

#include <cstdint>
#include <string>
#include <vector>

#include "hw_model/hw_config.h"
#include "hw_model/machine_resources.h"

namespace sfx {

class SetAssociativeCache {
  public:
    explicit SetAssociativeCache(const CacheLevelConfig& config);

    // Looks up the line holding `address`; on a miss, fills it (evicting the pseudo-LRU way).
    bool access(uint64_t address);
    void clear();

    const CacheLevelConfig& config() const { return m_config; }
    uint64_t hits() const { return m_hits; }
    uint64_t misses() const { return m_misses; }

  private:
    void touch(uint32_t set, uint32_t way);
    uint32_t victim(uint32_t set) const;

    CacheLevelConfig m_config;
    uint32_t m_sets, m_ways, m_line_shift;
    std::vector<uint64_t> m_tags;  // sets * ways; ~0 = empty
    std::vector<uint8_t> m_plru;   // sets * (ways - 1) tree bits (ways rounded up to 2^k)
    uint32_t m_tree_ways;
    uint64_t m_hits = 0, m_misses = 0;
};

// Whole core cycles for a latency in nanoseconds at a clock in MHz (rounded up: a result is
// usable from the first clock edge after it arrives).
uint64_t ns_to_cycles(double ns, double mhz);

// Cycles of scene-data latency a configuration's measured op costs already hold: an L1D hit
// (the microbenchmarks read their scene data from it) on a CPU core (ray_buffer.storage l1d);
// nothing for a machine priced from instruction counts.
uint64_t scene_latency_in_costs(const HwConfig& config);

// The scene-data memory of a machine: per-core private levels and shared levels (as
// configured), then DRAM, whose bandwidth all cores share. Reads are timed: a read issued at a
// cycle returns the cycle its data arrives.
class SceneMemoryModel {
  public:
    SceneMemoryModel(const SceneMemoryConfig& config, double core_mhz, uint32_t cores = 1);

    // Cycle at which `bytes` at `address`, requested by `core` at cycle `now`, have arrived:
    // each line comes from the nearest level holding it (lines of one request overlap: the
    // request waits for its slowest line); lines from DRAM queue for its bandwidth.
    uint64_t read(uint32_t core, uint64_t address, uint32_t bytes, uint64_t now);
    // Touches the lines of a read in the caches only (cache warming: no time, no DRAM traffic).
    void warm(uint32_t core, uint64_t address, uint32_t bytes);
    // The same read issued at cycle 0 (for code that keeps no time).
    uint64_t read(uint64_t address, uint32_t bytes) { return read(0, address, bytes, 0); }
    void clear();

    uint32_t level_count() const { return uint32_t(m_config.caches.size()); }
    // Hits and misses of a level, summed over its instances (one per core when private).
    uint64_t hits(uint32_t level) const;
    uint64_t misses(uint32_t level) const;
    uint64_t dram_reads() const { return m_dram_reads; }
    uint64_t requests() const { return m_requests; }

  private:
    SetAssociativeCache& instance(uint32_t level, uint32_t core);

    SceneMemoryConfig m_config;
    std::vector<std::vector<SetAssociativeCache>> m_levels;  // [level][instance]
    std::vector<uint64_t> m_latency;                         // per level, cycles
    uint64_t m_dram_latency;
    uint32_t m_line_bytes;
    RateServer m_dram;  // bytes per cycle
    uint64_t m_dram_reads = 0, m_requests = 0;
};

}  // namespace sfx
