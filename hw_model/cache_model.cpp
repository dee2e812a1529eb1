#include "hw_model/cache_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sfx {

SetAssociativeCache::SetAssociativeCache(const CacheLevelConfig& config) : m_config(config) {
    const uint64_t lines = uint64_t(config.kib) * 1024 / config.line_bytes;
    if (config.ways == 0 || lines % config.ways != 0 ||
        (config.line_bytes & (config.line_bytes - 1)))
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

uint64_t ns_to_cycles(double ns, double mhz) {
    return uint64_t(std::ceil(ns * mhz / 1000.0 - 1e-9));
}

uint64_t scene_latency_in_costs(const HwConfig& c) {
    if (c.ray_buffer.storage != "l1d" || c.scene_memory.caches.empty()) return 0;
    return ns_to_cycles(c.scene_memory.caches.front().hit_latency_ns, c.clock.core_mhz);
}

SceneMemoryModel::SceneMemoryModel(const SceneMemoryConfig& config, double core_mhz, uint32_t cores)
    : m_config(config),
      m_dram_latency(ns_to_cycles(config.dram_latency_ns, core_mhz)),
      // GB/s at core_mhz cycles per microsecond: bytes per cycle = GB/s * 1000 / MHz.
      m_dram(config.dram_bandwidth_gbps * 1000.0 / core_mhz) {
    for (const CacheLevelConfig& level : config.caches) {
        m_levels.emplace_back(level.shared ? 1 : std::max(1u, cores), SetAssociativeCache(level));
        m_latency.push_back(ns_to_cycles(level.hit_latency_ns, core_mhz));
    }
    m_line_bytes = config.caches.empty() ? 64 : config.caches.back().line_bytes;
}

SetAssociativeCache& SceneMemoryModel::instance(uint32_t level, uint32_t core) {
    std::vector<SetAssociativeCache>& v = m_levels[level];
    return v[v.size() == 1 ? 0 : core % v.size()];
}

uint64_t SceneMemoryModel::hits(uint32_t level) const {
    uint64_t n = 0;
    for (const SetAssociativeCache& c : m_levels[level]) n += c.hits();
    return n;
}

uint64_t SceneMemoryModel::misses(uint32_t level) const {
    uint64_t n = 0;
    for (const SetAssociativeCache& c : m_levels[level]) n += c.misses();
    return n;
}

void SceneMemoryModel::clear() {
    for (auto& level : m_levels)
        for (SetAssociativeCache& c : level) c.clear();
    m_dram = RateServer(m_dram.per_cycle());
    m_dram_reads = m_requests = 0;
}

void SceneMemoryModel::warm(uint32_t core, uint64_t address, uint32_t bytes) {
    if (bytes == 0) return;
    for (uint64_t line = address / m_line_bytes; line <= (address + bytes - 1) / m_line_bytes;
         ++line)
        for (uint32_t level = 0; level < m_levels.size(); ++level)
            if (instance(level, core).access(line * m_line_bytes)) break;
}

uint64_t SceneMemoryModel::read(uint32_t core, uint64_t address, uint32_t bytes, uint64_t now) {
    ++m_requests;
    if (bytes == 0) return now;
    const uint64_t first = address / m_line_bytes, last = (address + bytes - 1) / m_line_bytes;
    uint64_t arrival = now;
    for (uint64_t line = first; line <= last; ++line) {
        uint64_t ready = 0;
        bool from_dram = true;
        for (uint32_t level = 0; level < m_levels.size(); ++level) {  // inclusive: all filled
            if (instance(level, core).access(line * m_line_bytes)) {
                ready = now + m_latency[level];
                from_dram = false;
                break;
            }
        }
        if (from_dram) {
            ++m_dram_reads;
            // The line leaves DRAM after its latency, then occupies the channel for its transfer.
            const double start = m_dram.serve(double(now + m_dram_latency), double(m_line_bytes));
            ready = uint64_t(std::ceil(start + double(m_line_bytes) / m_dram.per_cycle() - 1e-9));
        }
        arrival = std::max(arrival, ready);
    }
    return arrival;
}

}  // namespace sfx
