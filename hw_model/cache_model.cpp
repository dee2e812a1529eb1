#include "hw_model/cache_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sfx {

SetAssociativeCache::SetAssociativeCache(const CacheLevelConfig& config) : m_config(config) {
    const uint64_t lines = uint64_t(config.kib) * 1024 / config.line_bytes;
    if (config.ways == 0 || lines % config.ways != 0 || (config.line_bytes & (config.line_bytes - 1)))
        throw std::invalid_argument("cache " + config.name + ": bad geometry");
    m_ways = config.ways;
    m_sets = uint32_t(lines / config.ways);
    m_line_shift = 0;
    while ((1u << m_line_shift) < config.line_bytes) ++m_line_shift;
    m_tree_ways = 1;
    while (m_tree_ways < m_ways) m_tree_ways *= 2;
    clear();
}

void SetAssociativeCache::clear() {
    m_tags.assign(size_t(m_sets) * m_ways, ~0ull);
    m_plru.assign(size_t(m_sets) * std::max(1u, m_tree_ways - 1), 0);
    m_hits = m_misses = 0;
}

// Tree PLRU: each internal node's bit points to the half to evict next; touching a way turns
// the bits on its path away from it.
void SetAssociativeCache::touch(uint32_t set, uint32_t way) {
    uint8_t* bits = &m_plru[size_t(set) * std::max(1u, m_tree_ways - 1)];
    uint32_t node = 0, lo = 0, span = m_tree_ways;
    while (span > 1) {
        span /= 2;
        const bool right = way >= lo + span;
        bits[node] = right ? 0 : 1;  // point at the other half
        node = 2 * node + (right ? 2 : 1);
        if (right) lo += span;
    }
}

uint32_t SetAssociativeCache::victim(uint32_t set) const {
    const uint8_t* bits = &m_plru[size_t(set) * std::max(1u, m_tree_ways - 1)];
    uint32_t node = 0, lo = 0, span = m_tree_ways;
    while (span > 1) {
        span /= 2;
        const bool right = bits[node] != 0;
        // Ways past the real associativity (non-power-of-two ways) are never chosen.
        const bool go_right = right && lo + span < m_ways;
        node = 2 * node + (go_right ? 2 : 1);
        if (go_right) lo += span;
    }
    return std::min(lo, m_ways - 1);
}

bool SetAssociativeCache::access(uint64_t address) {
    const uint64_t line = address >> m_line_shift;
    const uint32_t set = uint32_t(line % m_sets);
    uint64_t* tags = &m_tags[size_t(set) * m_ways];
    for (uint32_t w = 0; w < m_ways; ++w)
        if (tags[w] == line) {
            ++m_hits;
            touch(set, w);
            return true;
        }
    ++m_misses;
    uint32_t way = m_ways;
    for (uint32_t w = 0; w < m_ways && way == m_ways; ++w)
        if (tags[w] == ~0ull) way = w;  // fill empty ways first
    if (way == m_ways) way = victim(set);
    tags[way] = line;
    touch(set, way);
    return false;
}

SceneMemoryModel::SceneMemoryModel(const SceneMemoryConfig& config, double core_mhz)
    : m_dram_latency(config.dram_latency_cycles) {
    for (const CacheLevelConfig& level : config.caches) m_levels.emplace_back(level);
    m_line_bytes = config.caches.empty() ? 64 : config.caches.back().line_bytes;
    // GB/s at core_mhz cycles per microsecond: bytes per cycle = GB/s * 1000 / MHz.
    const double bytes_per_cycle = config.dram_bandwidth_gbps * 1000.0 / core_mhz;
    m_dram_cycles_per_line = double(m_line_bytes) / bytes_per_cycle;
}

void SceneMemoryModel::clear() {
    for (SetAssociativeCache& c : m_levels) c.clear();
    m_dram_reads = m_requests = 0;
}

uint64_t SceneMemoryModel::read(uint64_t address, uint32_t bytes) {
    ++m_requests;
    if (bytes == 0) return 0;
    const uint64_t first = address / m_line_bytes, last = (address + bytes - 1) / m_line_bytes;
    uint64_t worst = 0;
    double transfer = 0.0;
    for (uint64_t line = first; line <= last; ++line) {
        uint64_t latency = m_dram_latency;
        bool from_dram = true;
        for (SetAssociativeCache& level : m_levels) {  // inclusive: every level is filled
            if (level.access(line * m_line_bytes)) {
                latency = level.config().hit_latency_cycles;
                from_dram = false;
                break;
            }
        }
        if (from_dram) {
            ++m_dram_reads;
            transfer += m_dram_cycles_per_line;
        }
        worst = std::max(worst, latency);
    }
    return worst + uint64_t(std::ceil(transfer));
}

}  // namespace sfx
