#pragma once
// Scene-data memory: a hierarchy of set-associative caches with tree pseudo-LRU replacement
// (Bikker's model: 32 KiB / 256 KiB / 2 MiB, 8/8/16-way) in front of DRAM. Plain C++; the
// SystemC scene-memory module wraps it. Reads only: scene data is read-only while tracing.

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "hw_model/hw_config.h"
#include "hw_model/machine_resources.h"

namespace sfx {

// The size nearest `kib` that is a whole number of sets of `ways` lines of `line_bytes`, in whole
// KiB (at least one such step): a measured size becomes a cache's. A 20-way level of 64-byte
// lines (the Intel Xeon VM's L3, family 6 model 0xCF) comes in steps of 5 KiB.
uint32_t whole_sets_kib(uint32_t kib, uint32_t ways, uint32_t line_bytes);

class SetAssociativeCache {
  public:
    // `core_mhz` times the level's foreign fills (CacheLevelConfig::foreign_fill_per_us).
    explicit SetAssociativeCache(const CacheLevelConfig& config, double core_mhz = 1000.0);

    // Looks up the line holding `address` at cycle `now`; on a miss, fills it (evicting the
    // pseudo-LRU way). Others' fills into the set since its last lookup come first: each
    // takes the pseudo-LRU way, as a fill of this machine's would.
    bool access(uint64_t address, uint64_t now = 0);
    // Places the line holding `address` if absent (a prefetch: not counted, not touched if
    // present).
    void fill(uint64_t address, uint64_t now = 0);
    void clear();

    const CacheLevelConfig& config() const { return m_config; }
    uint64_t hits() const { return m_hits; }
    uint64_t misses() const { return m_misses; }

  private:
    uint32_t way_holding(uint32_t set, uint64_t line) const;  // m_ways: none
    void touch(uint32_t set, uint32_t way);
    uint32_t victim(uint32_t set) const;
    void place(uint32_t set, uint64_t tag);
    void fill_foreign(uint32_t set, uint64_t now);

    CacheLevelConfig m_config;
    uint32_t m_sets, m_ways, m_line_shift;
    std::vector<uint64_t> m_tags;  // sets * ways; ~0 = empty
    std::vector<uint8_t> m_plru;   // sets * (ways - 1) tree bits (ways rounded up to 2^k)
    uint32_t m_tree_ways;
    uint64_t m_hits = 0, m_misses = 0;
    double m_foreign_per_set_cycle = 0.0;   // others' fills per set per cycle
    std::vector<uint64_t> m_foreign_since;  // per set: the cycle its others' fills are due from
    std::vector<double> m_foreign_due;      // per set: fills due and not yet a whole line
    uint64_t m_foreign_tag = 0;
};

// The line DRAM transfers: the last cache level's (64 bytes without caches).
inline uint32_t dram_line_bytes(const SceneMemoryConfig& memory) {
    return memory.caches.empty() ? 64 : memory.caches.back().line_bytes;
}

// The latency of a read from DRAM of scene data spanning `span_bytes`
// (SceneMemoryConfig::dram_latency_by_span; dram_latency_ns where that is empty or the span
// unknown, 0).
double dram_latency_ns_at(const SceneMemoryConfig& memory, uint64_t span_bytes);

// The pages one core has used, as the number of distinct other pages used since a page's last
// use (its LRU stack distance, Mattson et al. 1970), counted exactly: a Fenwick tree over use
// times marks each page's last use. A DRAM read's latency follows it
// (SceneMemoryConfig::dram_latency_by_span).
class PageRecency {
  public:
    static constexpr uint64_t k_page_bytes = 4096;
    static constexpr uint64_t k_never = ~uint64_t(0);
    // Records a use of the page holding `address`; returns the distinct other pages used since
    // that page's last use, or k_never on its first.
    uint64_t use(uint64_t address);

  private:
    void mark(uint64_t time, int delta);
    uint64_t marked_through(uint64_t time) const;
    void renumber();  // last uses renumbered 1..pages, keeping their order
    uint64_t& last_use_of(uint64_t page);  // 0: never used

    // Pages below k_near_pages (a scene's data lies there, from 0) in a vector, others (the
    // mesh's arrays and the ray buffers, far above) in a map: the time of each one's last use.
    static constexpr uint64_t k_near_pages = uint64_t(1) << 22;
    std::vector<uint64_t> m_near_last_use;
    std::unordered_map<uint64_t, uint64_t> m_far_last_use;
    std::vector<uint32_t> m_marks;  // Fenwick tree over times 1..size-1
    uint64_t m_now = 0;
    uint64_t m_pages = 0;         // distinct pages used
    uint64_t m_latest = k_never;  // the page used last
};

// The latency of a read from DRAM whose page was used `pages_between` distinct pages ago
// (PageRecency; k_never: never) in scene data spanning `span_bytes`: the measured latency of a
// random chase over twice those pages (a random chase over P pages finds each page used P / 2
// distinct pages ago on average: its LRU stack position is uniform), a first use the span's,
// and dram_latency_ns where no table is given.
double dram_latency_ns_after(const SceneMemoryConfig& memory, uint64_t pages_between,
                             uint64_t span_bytes);

// Whole core cycles for a latency in nanoseconds at a clock in MHz (rounded up: a result is
// usable from the first clock edge after it arrives).
uint64_t ns_to_cycles(double ns, double mhz);

// Cycles of scene-data latency a configuration's measured op costs already hold: an L1D hit
// (the microbenchmarks read their scene data from it) on a CPU core (ray_buffer.storage l1d);
// nothing for a machine priced from instruction counts.
uint64_t scene_latency_in_costs(const HwConfig& config);
// Cycles of each hit-primitive read's latency a CPU core hides whatever the level that holds
// the line (OpKindInfo::reads_hit_primitive; hit_latency_beyond): a second-level hit's. The
// tracer's loop over the hits (compute_surfaces) prefetches each hit's triangle 16 hits ahead
// and its vertices 8 ahead, some hundreds of cycles of work, so a line the L2 holds is there
// when its hit is shaded; of a farther level's latency, the part beyond the L2's is left to
// the fitted exposed share (OpCostConfig::hit_read_exposed_share). On the surface-read
// microbenchmark of an Intel Xeon VM (2026-11-29, scalar) the measured cycles beyond a
// resident mesh over the cache model's latency beyond an L1D hit were 0.19 with the mesh in
// the L2, 0.51 in the L3 and 0.42 in DRAM: one share of the latency beyond the L1D, fitted on
// all three, was 0.26 and priced the frames' hit reads (mostly beyond the L2) 20-35 % under.
// A core without a second level hides its first's (scene_latency_in_costs).
uint64_t hit_read_latency_hidden(const HwConfig& config);

// Whether two configurations look up the same scene-data lines in the same order, with caches
// of the same geometry, so that every lookup finds its line at the same level: one core each
// (several cores take passes in an order their timing decides), equal cache sizes, lines and
// ways (latencies may differ) and equal prefetch (which decides when an op's data is looked
// up), and the same storage (an l1d core does not look up its lanes' hit primitives). The trace
// decides the rest: ops are dispatched in order on every machine. Never with others' fills
// (foreign_fill_per_us): they evict by time.
bool same_cache_lookups(const HwConfig& a, const HwConfig& b);

// The lookups of one cache hierarchy shared by configurations with same_cache_lookups: the
// first reader to reach a lookup simulates it, the others read the level it found, so the
// cache simulation is paid once per point group rather than once per configuration. Each
// reader's line is checked against the one simulated (a mismatch is a logic error).
class SharedCacheLookups {
  public:
    explicit SharedCacheLookups(const std::vector<CacheLevelConfig>& levels);
    uint32_t add_reader();
    // The level holding `address` at `reader`'s next lookup (levels: none, DRAM).
    uint32_t level_of(uint32_t reader, uint64_t address);

  private:
    std::vector<SetAssociativeCache> m_levels;
    // Lookups simulated and not yet read by every reader, from lookup number m_first on.
    std::vector<uint64_t> m_addresses;
    std::vector<uint8_t> m_found;
    uint64_t m_first = 0;
    std::vector<uint64_t> m_next;  // per reader: its next lookup's number
};

// The scene-data memory of a machine: per-core private levels and shared levels (as
// configured), then DRAM, whose bandwidth all cores share. Reads are timed: a read issued at a
// cycle returns the cycle its data arrives. With `shared` lookups (same_cache_lookups), the
// caches are those lookups' and only latency and DRAM are this model's own.
class SceneMemoryModel {
  public:
    // `span_bytes`: the scene data's (SceneDataMap::span_bytes), which sets DRAM's latency
    // (dram_latency_ns_at).
    SceneMemoryModel(const SceneMemoryConfig& config, double core_mhz, uint32_t cores = 1,
                     std::shared_ptr<SharedCacheLookups> shared = nullptr, uint64_t span_bytes = 0);

    // Cycle at which `bytes` at `address`, requested by `core` at cycle `now`, have arrived:
    // each line comes from the nearest level holding it (lines of one request overlap: the
    // request waits for its slowest line); lines from DRAM queue for its bandwidth. A line
    // still on its way for an earlier read (a fill in flight) arrives with that fill.
    // `unloaded`: the slowest line's latency had DRAM been idle and no fill been in flight (a
    // CPU core working through its lanes in turn overlaps a share of each, hit_latency_beyond
    // in hw_model/op_costs.h; the queue of one op's reads all issued at once is the
    // accelerator's).
    uint64_t read(uint32_t core, uint64_t address, uint32_t bytes, uint64_t now,
                  uint64_t* unloaded = nullptr);
    // Touches the lines of a read in the caches only (cache warming: no time, no DRAM traffic;
    // looked up at cycle 0, which others' fills do not age: where a level has them, full
    // fidelity times its warm frames instead, run_point_group).
    void warm(uint32_t core, uint64_t address, uint32_t bytes);
    // Lines of other data than the scene's that `core` reads at cycle `now` through the same
    // caches (a CPU core's ray buffers, storage l1d): they take their place in every level as a
    // read's do, and evict scene lines; not counted among the scene's hits and misses, untimed.
    // Returns the farthest level any of them came from (0: every line was in the first level;
    // level_count(): DRAM).
    uint32_t touch_other(uint32_t core, uint64_t address, uint32_t bytes, uint64_t now);
    // The same read issued at cycle 0 (for code that keeps no time).
    uint64_t read(uint64_t address, uint32_t bytes) { return read(0, address, bytes, 0); }

    // Cycles the machine sat idle while others simulated beside it finished their work: later
    // reads are looked up that much earlier on others' fills' clock, so that what a level loses
    // by age does not depend on the configurations timed with this one.
    void pause(uint64_t cycles) { m_paused += cycles; }

    uint32_t level_count() const { return uint32_t(m_config.caches.size()); }
    // Hits and misses of a level, summed over its instances (one per core when private).
    uint64_t hits(uint32_t level) const { return m_hits[level]; }
    uint64_t misses(uint32_t level) const { return m_misses[level]; }
    uint64_t dram_reads() const { return m_dram_reads; }
    uint64_t requests() const { return m_requests; }

  private:
    SetAssociativeCache& instance(uint32_t level, uint32_t core);
    // Records the use of `address`'s page by `core`; returns PageRecency::use's distance (0
    // when DRAM's latency does not depend on it).
    uint64_t use_page(uint32_t core, uint64_t address);
    // The nearest level holding `line` for `core` at cycle `now` (level_count(): DRAM), counted.
    uint32_t look_up(uint32_t core, uint64_t line, uint64_t now);

    // A line filled from beyond the first level, for a read at `issued` (the caches hold it
    // from then on): when it arrives. A later read that finds the line in a cache before then
    // waits for this fill, as a cache's miss status holding register merges a second miss
    // into the first; a read timed before `issued` (reads are not always made in time order)
    // would have missed itself, so it waits at most the fill's own latency.
    struct Fill {
        uint64_t line = ~uint64_t(0), issued = 0, arrival = 0;
    };
    // Fills by line, direct mapped: the lines in flight at once are few (a core's fill
    // buffers), so a fill overwritten while still in flight is rare, and then the read finds
    // the line as the caches say.
    static constexpr size_t k_fills = 1024;

    SceneMemoryConfig m_config;
    std::vector<std::vector<SetAssociativeCache>> m_levels;  // [level][instance]; none if shared
    std::shared_ptr<SharedCacheLookups> m_shared;
    uint32_t m_reader = 0;                   // this model's reader number in m_shared
    std::vector<uint64_t> m_hits, m_misses;  // per level, over its instances
    std::vector<uint64_t> m_latency;         // per level, cycles
    uint64_t m_dram_latency;                 // cycles, at the span (where no table: every read's)
    double m_core_mhz;
    uint64_t m_span_bytes;
    std::vector<PageRecency> m_pages;  // per core; none without dram_latency_by_span
    uint32_t m_line_bytes;
    RateServer m_dram;  // bytes per cycle
    uint64_t m_dram_reads = 0, m_requests = 0;
    uint64_t m_paused = 0;
    std::vector<Fill> m_fills;  // k_fills
};

}  // namespace sfx
