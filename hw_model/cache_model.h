#pragma once
// Scene-data memory: a hierarchy of set-associative caches with tree pseudo-LRU replacement
// (Bikker's model: 32 KiB / 256 KiB / 2 MiB, 8/8/16-way) in front of DRAM. Plain C++; the
// SystemC scene-memory module wraps it. Reads only: scene data is read-only while tracing.

#include <cstdint>
#include <string>
#include <vector>

#include "hw_model/hw_config.h"

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
    std::vector<uint64_t> m_tags;    // sets * ways; ~0 = empty
    std::vector<uint8_t> m_plru;     // sets * (ways - 1) tree bits (ways rounded up to 2^k)
    uint32_t m_tree_ways;
    uint64_t m_hits = 0, m_misses = 0;
};

class SceneMemoryModel {
public:
    SceneMemoryModel(const SceneMemoryConfig& config, double core_mhz);

    // Cycles to read `bytes` at `address`: the latency of the nearest level holding each line
    // (lines of one request overlap: the request costs its slowest line), plus DRAM transfer
    // time for lines that came from DRAM.
    uint64_t read(uint64_t address, uint32_t bytes);
    void clear();

    const std::vector<SetAssociativeCache>& levels() const { return m_levels; }
    uint64_t dram_reads() const { return m_dram_reads; }
    uint64_t requests() const { return m_requests; }

private:
    std::vector<SetAssociativeCache> m_levels;
    uint32_t m_dram_latency;
    double m_dram_cycles_per_line;
    uint32_t m_line_bytes;
    uint64_t m_dram_reads = 0, m_requests = 0;
};

}  // namespace sfx
