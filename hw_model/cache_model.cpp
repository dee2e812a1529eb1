#include "hw_model/cache_model.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace sfx {

uint32_t whole_sets_kib(uint32_t kib, uint32_t ways, uint32_t line_bytes) {
    const uint64_t set_bytes = uint64_t(std::max(1u, ways)) * line_bytes;
    const uint64_t step = set_bytes / std::gcd(set_bytes, uint64_t(1024));  // KiB
    return uint32_t(std::max<uint64_t>(step, (uint64_t(kib) + step / 2) / step * step));
}

SetAssociativeCache::SetAssociativeCache(const CacheLevelConfig& config, double core_mhz)
    : m_config(config) {
    const uint64_t lines = uint64_t(config.kib) * 1024 / config.line_bytes;
    if (config.ways == 0 || lines % config.ways != 0 ||
        (config.line_bytes & (config.line_bytes - 1)))
        throw std::invalid_argument("cache " + config.name + ": " + std::to_string(config.kib) +
                                    " KiB is not a whole number of sets of " +
                                    std::to_string(config.ways) + " ways of " +
                                    std::to_string(config.line_bytes) + "-byte lines");
    m_ways = config.ways;
    m_sets = uint32_t(lines / config.ways);
    m_line_shift = 0;
    while ((1u << m_line_shift) < config.line_bytes) ++m_line_shift;
    m_tree_ways = 1;
    while (m_tree_ways < m_ways) m_tree_ways *= 2;
    m_foreign_per_set_cycle = config.foreign_fill_per_us / core_mhz / double(m_sets);
    clear();
}

void SetAssociativeCache::clear() {
    m_tags.assign(size_t(m_sets) * m_ways, ~0ull);
    m_plru.assign(size_t(m_sets) * std::max(1u, m_tree_ways - 1), 0);
    m_hits = m_misses = 0;
    if (m_foreign_per_set_cycle > 0) {
        m_foreign_since.assign(m_sets, 0);
        m_foreign_due.assign(m_sets, 0.0);
    }
}

// Others' fills due in `set` since its last lookup, in whole lines (the rest carried); more
// than the ways have replaced the set whatever their number. Their tags have the top bit set,
// which no address of this machine's reaches.
void SetAssociativeCache::fill_foreign(uint32_t set, uint64_t now) {
    if (now <= m_foreign_since[set]) return;  // another core's lookup, earlier in time
    const double due =
        m_foreign_due[set] + double(now - m_foreign_since[set]) * m_foreign_per_set_cycle;
    m_foreign_since[set] = now;
    const uint32_t lines = uint32_t(std::min<double>(std::floor(due), m_ways));
    m_foreign_due[set] = due - std::floor(due);
    for (uint32_t i = 0; i < lines; ++i)
        place(set, (1ull << 63) | (m_foreign_tag++ & ((1ull << 62) - 1)));
}

// A fill, this machine's or another's: an empty way first, else the pseudo-LRU way.
void SetAssociativeCache::place(uint32_t set, uint64_t tag) {
    uint64_t* tags = &m_tags[size_t(set) * m_ways];
    uint32_t way = m_ways;
    for (uint32_t w = 0; w < m_ways && way == m_ways; ++w)
        if (tags[w] == ~0ull) way = w;
    if (way == m_ways) way = victim(set);
    tags[way] = tag;
    touch(set, way);
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

bool SetAssociativeCache::access(uint64_t address, uint64_t now) {
    const uint64_t line = address >> m_line_shift;
    const uint32_t set = uint32_t(line % m_sets);
    if (m_foreign_per_set_cycle > 0) fill_foreign(set, now);
    const uint32_t way = way_holding(set, line);
    if (way < m_ways) {
        ++m_hits;
        touch(set, way);
        return true;
    }
    ++m_misses;
    place(set, line);
    return false;
}

void SetAssociativeCache::fill(uint64_t address, uint64_t now) {
    const uint64_t line = address >> m_line_shift;
    const uint32_t set = uint32_t(line % m_sets);
    if (m_foreign_per_set_cycle > 0) fill_foreign(set, now);
    if (way_holding(set, line) == m_ways) place(set, line);
}

uint32_t SetAssociativeCache::way_holding(uint32_t set, uint64_t line) const {
    const uint64_t* tags = &m_tags[size_t(set) * m_ways];
    for (uint32_t w = 0; w < m_ways; ++w)
        if (tags[w] == line) return w;
    return m_ways;
}

double dram_latency_ns_at(const SceneMemoryConfig& memory, uint64_t span_bytes) {
    const std::vector<DramSpanLatency>& points = memory.dram_latency_by_span;
    if (points.empty() || span_bytes == 0) return memory.dram_latency_ns;
    const double mib = double(span_bytes) / double(1u << 20);
    if (mib <= points.front().span_mib) return points.front().latency_ns;
    for (size_t i = 1; i < points.size(); ++i) {
        const DramSpanLatency &a = points[i - 1], &b = points[i];
        if (mib > b.span_mib) continue;
        const double f = std::log(mib / a.span_mib) / std::log(b.span_mib / a.span_mib);
        return std::exp(std::log(a.latency_ns) + f * std::log(b.latency_ns / a.latency_ns));
    }
    return points.back().latency_ns;
}

uint64_t PageRecency::use(uint64_t address) {
    const uint64_t page = address / k_page_bytes;
    // The most recent page again: no other page since, and its place in the order stands.
    if (page == m_latest) return 0;
    m_latest = page;
    if (++m_now >= m_marks.size()) renumber();
    uint64_t& last = last_use_of(page);
    uint64_t between = k_never;
    if (last == 0) {
        ++m_pages;
    } else {
        // Every page seen holds one mark, at its last use: those after this page's are the
        // pages used since.
        between = m_pages - marked_through(last);
        mark(last, -1);
    }
    last = m_now;
    mark(m_now, +1);
    return between;
}

uint64_t& PageRecency::last_use_of(uint64_t page) {
    if (page >= k_near_pages) return m_far_last_use[page];
    if (page >= m_near_last_use.size())
        m_near_last_use.resize(
            std::min<size_t>(k_near_pages, std::max<size_t>(page + 1, 2 * m_near_last_use.size())),
            0);
    return m_near_last_use[page];
}

void PageRecency::mark(uint64_t time, int delta) {
    for (; time < m_marks.size(); time += time & (~time + 1)) m_marks[time] += uint32_t(delta);
}

uint64_t PageRecency::marked_through(uint64_t time) const {
    uint64_t n = 0;
    for (; time > 0; time -= time & (~time + 1)) n += m_marks[time];
    return n;
}

void PageRecency::renumber() {
    // Only the order of last uses matters: renumbering keeps the tree as small as the pages.
    std::vector<std::pair<uint64_t, uint64_t*>> by_time;  // (last use, where it is kept)
    by_time.reserve(m_pages);
    for (uint64_t& time : m_near_last_use)
        if (time != 0) by_time.emplace_back(time, &time);
    for (auto& [page, time] : m_far_last_use) by_time.emplace_back(time, &time);
    std::sort(by_time.begin(), by_time.end());
    m_marks.assign(std::max<size_t>(1024, 2 * by_time.size() + 2), 0);
    uint64_t time = 0;
    for (const auto& [old, kept] : by_time) {
        *kept = ++time;
        mark(time, +1);
    }
    m_now = time + 1;
}

double dram_latency_ns_after(const SceneMemoryConfig& memory, uint64_t pages_between,
                             uint64_t span_bytes) {
    if (pages_between == PageRecency::k_never || span_bytes == 0)
        return dram_latency_ns_at(memory, span_bytes);
    const uint64_t chase_bytes = 2 * (pages_between + 1) * PageRecency::k_page_bytes;
    return dram_latency_ns_at(memory, std::min(chase_bytes, span_bytes));
}

uint64_t ns_to_cycles(double ns, double mhz) {
    return uint64_t(std::ceil(ns * mhz / 1000.0 - 1e-9));
}

uint64_t scene_latency_in_costs(const HwConfig& c) {
    if (c.ray_buffer.storage != "l1d" || c.scene_memory.caches.empty()) return 0;
    return ns_to_cycles(c.scene_memory.caches.front().hit_latency_ns, c.clock.core_mhz);
}

uint64_t hit_read_latency_hidden(const HwConfig& c) {
    if (c.ray_buffer.storage != "l1d" || c.scene_memory.caches.size() < 2)
        return scene_latency_in_costs(c);
    return ns_to_cycles(c.scene_memory.caches[1].hit_latency_ns, c.clock.core_mhz);
}

bool same_cache_lookups(const HwConfig& a, const HwConfig& b) {
    const SceneMemoryConfig &x = a.scene_memory, &y = b.scene_memory;
    if (a.cores.count != 1 || b.cores.count != 1 || x.caches.size() != y.caches.size() ||
        x.prefetch_depth != y.prefetch_depth || x.prefetch_children != y.prefetch_children)
        return false;
    // Others' fills evict by time, and each machine's lookups come at its own times.
    for (const SceneMemoryConfig* m : {&x, &y})
        for (const CacheLevelConfig& level : m->caches)
            if (level.foreign_fill_per_us > 0) return false;
    // Every machine looks its lanes' hit primitives up (CoreModel::request_scene), where
    // hit_reads says.
    if (x.hit_reads != y.hit_reads) return false;
    // A core whose ray buffers are its L1D reads their lines through the same caches
    // (CoreModel::dispatch_op), at addresses its slot size sets.
    const bool a_l1d = a.ray_buffer.storage == "l1d", b_l1d = b.ray_buffer.storage == "l1d";
    if (a_l1d != b_l1d || (a_l1d && a.ray_buffer.slot_bytes != b.ray_buffer.slot_bytes))
        return false;
    for (size_t i = 0; i < x.caches.size(); ++i)
        if (x.caches[i].kib != y.caches[i].kib ||
            x.caches[i].line_bytes != y.caches[i].line_bytes ||
            x.caches[i].ways != y.caches[i].ways || x.caches[i].pair_fill != y.caches[i].pair_fill)
            return false;
    return true;
}

namespace {

// The nearest of `levels` caches holding `address` (`levels`: none); each level missed fills
// it (inclusive), as a read does; a read from memory also fills the other line of its 128-byte
// pair into a last level that pairs (CacheLevelConfig::pair_fill).
template <class CacheOf>
uint32_t first_holding(uint32_t levels, uint64_t address, uint64_t now, CacheOf cache_of) {
    uint32_t level = 0;
    while (level < levels && !cache_of(level).access(address, now)) ++level;
    if (level == levels && levels > 0) {
        SetAssociativeCache& last = cache_of(levels - 1);
        if (last.config().pair_fill) last.fill(address ^ uint64_t(last.config().line_bytes), now);
    }
    return level;
}

}  // namespace

SharedCacheLookups::SharedCacheLookups(const std::vector<CacheLevelConfig>& levels) {
    for (const CacheLevelConfig& level : levels) m_levels.emplace_back(level);
}

uint32_t SharedCacheLookups::add_reader() {
    if (m_first > 0 || !m_found.empty())
        throw std::logic_error("SharedCacheLookups: a reader joins after the first lookup");
    m_next.push_back(0);
    return uint32_t(m_next.size() - 1);
}

uint32_t SharedCacheLookups::level_of(uint32_t reader, uint64_t address) {
    const uint64_t i = m_next[reader]++ - m_first;
    if (i < m_found.size()) {
        if (m_addresses[i] != address)
            throw std::logic_error("SharedCacheLookups: readers look up different lines");
        return m_found[i];
    }
    // This reader is the first here: simulate, and keep the outcome for the others.
    const uint32_t level =
        first_holding(uint32_t(m_levels.size()), address, 0,
                      [&](uint32_t l) -> SetAssociativeCache& { return m_levels[l]; });
    m_addresses.push_back(address);
    m_found.push_back(uint8_t(level));
    // Forget what every reader has read (now and then, so each erase moves little).
    if (m_found.size() >= 4096) {
        const uint64_t read_by_all = *std::min_element(m_next.begin(), m_next.end()) - m_first;
        if (read_by_all >= m_found.size() / 2) {
            m_addresses.erase(m_addresses.begin(), m_addresses.begin() + ptrdiff_t(read_by_all));
            m_found.erase(m_found.begin(), m_found.begin() + ptrdiff_t(read_by_all));
            m_first += read_by_all;
        }
    }
    return level;
}

SceneMemoryModel::SceneMemoryModel(const SceneMemoryConfig& config, double core_mhz, uint32_t cores,
                                   std::shared_ptr<SharedCacheLookups> shared, uint64_t span_bytes)
    : m_config(config),
      m_shared(std::move(shared)),
      m_hits(config.caches.size(), 0),
      m_misses(config.caches.size(), 0),
      m_dram_latency(ns_to_cycles(dram_latency_ns_at(config, span_bytes), core_mhz)),
      m_core_mhz(core_mhz),
      m_span_bytes(span_bytes),
      m_pages(config.dram_latency_by_span.empty() ? 0 : std::max(1u, cores)),
      // GB/s at core_mhz cycles per microsecond: bytes per cycle = GB/s * 1000 / MHz.
      m_dram(config.dram_bandwidth_gbps * 1000.0 / core_mhz),
      m_fills(k_fills) {
    if (m_shared) m_reader = m_shared->add_reader();
    for (const CacheLevelConfig& level : config.caches) {
        if (!m_shared)
            m_levels.emplace_back(level.shared ? 1 : std::max(1u, cores),
                                  SetAssociativeCache(level, core_mhz));
        m_latency.push_back(ns_to_cycles(level.hit_latency_ns, core_mhz));
    }
    m_line_bytes = dram_line_bytes(config);
}

SetAssociativeCache& SceneMemoryModel::instance(uint32_t level, uint32_t core) {
    std::vector<SetAssociativeCache>& v = m_levels[level];
    return v[v.size() == 1 ? 0 : core % v.size()];
}

uint64_t SceneMemoryModel::use_page(uint32_t core, uint64_t address) {
    return m_pages.empty() ? 0 : m_pages[core % m_pages.size()].use(address);
}

uint32_t SceneMemoryModel::look_up(uint32_t core, uint64_t line, uint64_t now) {
    const uint64_t address = line * m_line_bytes;
    const uint32_t levels = level_count();
    const uint32_t level =
        m_shared
            ? m_shared->level_of(m_reader, address)
            : first_holding(levels, address, now - std::min(now, m_paused),
                            [&](uint32_t l) -> SetAssociativeCache& { return instance(l, core); });
    for (uint32_t l = 0; l < level; ++l) ++m_misses[l];
    if (level < levels) ++m_hits[level];
    return level;
}

uint32_t SceneMemoryModel::touch_other(uint32_t core, uint64_t address, uint32_t bytes,
                                       uint64_t now) {
    if (bytes == 0) return 0;
    const uint32_t levels = level_count();
    uint32_t farthest = 0;
    for (uint64_t line = address / m_line_bytes; line <= (address + bytes - 1) / m_line_bytes;
         ++line) {
        const uint64_t at = line * m_line_bytes;
        use_page(core, at);
        const uint32_t level = m_shared ? m_shared->level_of(m_reader, at)
                                        : first_holding(levels, at, now - std::min(now, m_paused),
                                                        [&](uint32_t l) -> SetAssociativeCache& {
                                                            return instance(l, core);
                                                        });
        farthest = std::max(farthest, level);
    }
    return farthest;
}

void SceneMemoryModel::warm(uint32_t core, uint64_t address, uint32_t bytes) {
    if (bytes == 0) return;
    for (uint64_t line = address / m_line_bytes; line <= (address + bytes - 1) / m_line_bytes;
         ++line) {
        use_page(core, line * m_line_bytes);
        look_up(core, line, 0);
    }
}

uint64_t SceneMemoryModel::read(uint32_t core, uint64_t address, uint32_t bytes, uint64_t now,
                                uint64_t* unloaded) {
    ++m_requests;
    if (unloaded) *unloaded = 0;
    if (bytes == 0) return now;
    const uint64_t first = address / m_line_bytes, last = (address + bytes - 1) / m_line_bytes;
    uint64_t arrival = now;
    for (uint64_t line = first; line <= last; ++line) {
        const uint32_t level = look_up(core, line, now);
        const uint64_t pages_between = use_page(core, line * m_line_bytes);
        uint64_t ready = 0, latency = 0;
        Fill& fill = m_fills[line % k_fills];
        if (level < level_count()) {
            latency = m_latency[level];
            ready = now + latency;
            if (fill.line == line && fill.arrival > ready)
                ready = std::min(fill.arrival, now + (fill.arrival - fill.issued));
        } else {
            ++m_dram_reads;
            const uint64_t dram_latency =
                m_pages.empty()
                    ? m_dram_latency
                    : ns_to_cycles(dram_latency_ns_after(m_config, pages_between, m_span_bytes),
                                   m_core_mhz);
            // The line leaves DRAM after its latency, then occupies the channel for its transfer.
            const double transfer = double(m_line_bytes) / m_dram.per_cycle();
            const double start = m_dram.serve(double(now + dram_latency), double(m_line_bytes));
            ready = uint64_t(std::ceil(start + transfer - 1e-9));
            latency = dram_latency + uint64_t(std::ceil(transfer - 1e-9));
        }
        if (level > 0 && (fill.line != line || ready > fill.arrival)) fill = {line, now, ready};
        arrival = std::max(arrival, ready);
        if (unloaded) *unloaded = std::max(*unloaded, latency);
    }
    return arrival;
}

}  // namespace sfx
