#pragma once
// The host CPU described as a hardware configuration: one core of the machine that runs the
// native stream tracer (kernels/stream), with the ISA's SIMD width, the cache hierarchy the CPU
// reports, its time-stamp-counter clock and measured load latencies. `sfx calibrate
// --describe-host` writes it as host.hw.yaml, every value with where it came from; the fitted
// per-op costs (HwConfig::op_costs) are added by the calibration (sweeps/host_calibration.h).
// It is timed by the same machine model as every other configuration (hw_model/core_model.h).

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "base/cache_eviction.h"
#include "hw_model/hw_config.h"

namespace sfx {

struct HostCacheLevel {
    uint32_t level = 1;
    std::string type;  // "data" or "unified" (instruction caches are left out)
    uint32_t kib = 0, line_bytes = 64, ways = 1;
    bool shared = false;  // shared by more than one core
    std::string source;   // "sysfs ..." or "cpuid leaf ..."
};

// Data and unified caches of cpu0, nearest first: /sys/devices/system/cpu/cpu0/cache/ when the
// kernel exposes it, else cpuid's deterministic cache parameters (leaf 0x8000001D on AMD, 4 on
// Intel). Empty if neither says anything.
std::vector<HostCacheLevel> read_host_caches();

// The time-stamp counter's rate in MHz, measured against the steady clock over `seconds`.
double measure_tsc_mhz(double seconds = 0.2);

// Average load-to-use latency in ns of a dependent pointer chase over a random cycle of lines
// spanning `bytes` (so it hits the level that holds that many bytes). With `spin`, each load
// waits for a chain of that many dependent multiplies before the next (its time taken out of
// the latency; the whole step's time in `step_ns`): lines then go untouched longer between
// laps, which tells how long a shared level keeps them while others fill it.
double measure_load_latency_ns(uint64_t bytes, double tsc_mhz, uint32_t spin = 0,
                               double* step_ns = nullptr);

// The KiB a chase spans to read cache level `level`'s latency (0: the nearest of `caches`):
// half the first level; a level behind another twice that one's size (mostly beyond it, as
// the last level's first chase is, last_level_chase_kib), at most half its own. Not half the
// level: an L2 loses lines well below its size (a chase over half the 1 MiB L2 of an AMD Zen 5
// VM read 5.4 ns, over 96 to 288 KiB 4.0-4.1 ns, over 576 KiB 4.7-4.9 and over 960 KiB 8.0-11.3,
// 2026-12-06; on an Intel Xeon VM's 2 MiB L2 the chase over half of it read 5.1 and 7.0 ns in
// two runs of one day).
uint32_t latency_chase_kib(const std::vector<HostCacheLevel>& caches, size_t level);

// Beyond the L3 a core keeps of any current CPU (no larger: the machine may be shared): the
// DRAM chase's size and the last of its spans. The caches are emptied by evict_caches
// (base/cache_eviction.h), which reads at least this much and more where cpuid's L3 is larger.
constexpr uint64_t k_beyond_last_level_bytes = k_min_eviction_bytes;

// Reads the TSC (rdtsc): the clock the native tracer's cycles are counted in.
uint64_t read_tsc();

// The microarchitecture: cpuid's vendor string, display family and model (leaf 1: the base
// family plus the extended family when the base is 0xF; the extended model above the base
// model when the family is 6 or 0xF), stepping and brand string.
struct CpuSignature {
    uint32_t family = 0, model = 0, stepping = 0;
};
CpuSignature decode_cpu_signature(uint32_t leaf1_eax);

struct Microarchitecture {
    std::string vendor;  // "AuthenticAMD", "GenuineIntel", ...
    CpuSignature signature;
    std::string brand;  // "AMD EPYC 7B12" (leaf 0x80000002-4), empty if not given
};
Microarchitecture read_microarchitecture();
// "amd", "intel" or the vendor string lower-cased: what names a host's silicon-check page.
std::string vendor_short_name(const std::string& vendor);
// "AuthenticAMD family 0x17 model 0x31 stepping 0 (AMD EPYC 7B12)".
std::string describe(const Microarchitecture& m);

// A reading of measure_dtlb_pages (below): the chase's TSC ticks a load by pages, and the
// pages the first-level DTLB maps (0: no step found).
struct DtlbReading {
    std::vector<std::pair<uint32_t, double>> chases;
    uint32_t pages = 0;
};
// The 4 KiB pages a core's first-level data TLB maps (RayBufferConfig::dtlb_pages): a random
// chase of one line a page over 8, 16, ... `max_pages` pages of 4 KiB (no huge pages), each
// line at its own offset in its page so that the lines stay in the L1D (at most 512 of them);
// the fastest of many short runs. The reach is the last count before the load's time steps up
// by a third over the fewest pages' (the second-level TLB's hit) for two counts in a row: on
// the Intel Xeon VM of model 0xCF (2026-12-08) 3.9 TSC ticks a load up to 96 pages, 7.4 at
// 112 and 9.1 at 128, where cpuid's leaf 0x18 is empty.
DtlbReading measure_dtlb_pages(uint32_t max_pages = 512);
// That reach from the chases (pages, ticks a load), fewest pages first; 0: no step.
uint32_t dtlb_reach(const std::vector<std::pair<uint32_t, double>>& chases);
// Where a host file's dtlb_pages comes from, with the chase's loads on either side of the step.
std::string describe(const DtlbReading& r);

// A reading of measure_pair_fill (below).
struct PairFillReading {
    double after_even_ns = 0.0, cold_ns = 0.0;
    bool pairs() const { return after_even_ns > 0 && after_even_ns < 0.5 * cold_ns; }
};

struct HostDescription {
    Microarchitecture microarchitecture;
    uint32_t simd_width = 1;
    std::string isa;  // e.g. "avx512 (16 lanes)"
    double tsc_mhz = 0.0;
    // The core's clock while measured, boost included, under the back end's own instructions
    // (base/core_clock.h: the clock under AVX2 or AVX-512 code may be lower than under scalar).
    double core_mhz = 0.0;
    std::vector<HostCacheLevel> caches;
    std::vector<double> latency_ns;  // per cache level, then DRAM (measured)
    // Chases (KiB, ns) from twice the level before the last up to the last level's size (at
    // most 64 MiB), smallest first; the first is the last level's latency. On a virtual machine
    // the L3 a core sees can end well short of what cpuid reports, and where it ends is a draw
    // (the neighbours' share): last_level_seen reads it from these.
    std::vector<std::pair<uint32_t, double>> last_level_chases;
    // Chases over the first of those sizes with loads spaced out (spin): (ns a step, ns a load),
    // shortest step first.
    std::vector<std::pair<double, double>> last_level_idle_chases;
    // DRAM's latency by the span the reads fall in (MiB, ns), smallest first
    // (measure_dram_first_pass_ns): SceneMemoryConfig::dram_latency_by_span.
    std::vector<std::pair<double, double>> dram_span_latencies;
    PairFillReading pair_fill;  // the last level's CacheLevelConfig::pair_fill (0: not measured)
    uint32_t slot_bytes = 0;         // one ray slot of the native tracer (0: unknown)
    uint32_t slot_arrays = 1;        // the arrays it lies in beyond its traversal record
    DtlbReading dtlb;                // the first-level DTLB's reach (measured)
    double speed_probe_cycles = 0.0;  // HwConfig::speed_probe_cycles (0: not measured)
    // The CPU the description was measured on (sched_getcpu; -1: unknown). On a virtual machine
    // one CPU's L3 may not be another's (a neighbour's load on its physical core): the check
    // runs pinned where its host was described (scripts/silicon-check --cpu).
    int cpu = -1;
    // The scene memory's caches and DRAM as another host file of this machine describes them
    // (`sfx calibrate --describe-host --memory-from FILE`), instead of its own chases: the
    // back ends' host files of one check then share one memory, measured once, and their
    // predictions differ only where the back ends do. Empty `memory_source`: measured here.
    SceneMemoryConfig memory;
    std::string memory_source;
    // The model's branch predictor over the traversal's branches and the fitted cost of its
    // mispredictions (sweeps/host_calibration.h), with how it was fitted; kind none: not fitted.
    BranchPredictorConfig branch_predictor;
    std::string branch_predictor_fit;
    // The few-ray loop's costs (its misprediction cost here, the box test's few_lane_cycles and
    // few_ray_entry_cycles in the op costs) and the one-ray and few-ray loops' exposed share of
    // a node read (the box test's node_read_exposed_share) as another back end's host file of
    // this machine gives them (`sfx calibrate --describe-host --few-ray-from FILE`): those loops
    // run the same code at every width of k_few_ray_min_width lanes or more, and fitted on each
    // back end apart they differed by the fits' noise where the core's loops did not. Empty:
    // fitted here.
    std::string few_ray_source;
};

// The latency of a read from DRAM within `span_bytes`: the first pass of a random chase over
// the span (at most 2^16 of its lines), right after evict_caches, so that every load of it
// misses every cache; the fastest of `runs`. The span sets how many DRAM rows and pages the
// loads fall in: a scene of a few MiB reads DRAM faster than the 256 MiB chase of
// dram_latency_ns (huge pages, as the BVH is allocated).
double measure_dram_first_pass_ns(uint64_t span_bytes, double tsc_mhz, int runs = 5);

// Whether a read from DRAM brings the other line of its 128-byte pair into the caches (an
// adjacent-line prefetch, CacheLevelConfig::pair_fill): after evict_caches, a random chase over
// the even lines of `pair_bytes` (three laps), then the first pass over its odd lines, in ns a
// load; against that first pass right after evict_caches alone (from DRAM). The fastest of
// `runs` each. Pairs where the odd lines came at under half DRAM's latency.
PairFillReading measure_pair_fill(double tsc_mhz, uint64_t pair_bytes = uint64_t(1) << 20,
                                  int runs = 5);

// Runs the last level's chases (HostDescription::last_level_chases and
// last_level_idle_chases) from `h.caches` at `h.tsc_mhz`; none with fewer than two levels.
// describe_host runs it, and the silicon check again around its renders: the L3 a core of a
// shared machine keeps moves within a minute.
void chase_last_level(HostDescription& h);

// The last cache level as this core sees it, from its chases, by the LRU stack: a line is
// still there when the lines filled since its last touch, this core's and others', number
// fewer than the level holds. A chase over S lines with steps of t ns fills S of its own and
// r t S of others' between touches of a line, so it hits while S (1 + r t) < C. The chases over
// growing sizes cross at S* (steps of the level's latency H), the spaced-out chases over S0
// lines at t*: two equations for the capacity C and others' fill rate r. A crossing is where a
// chase's latency passes the midpoint between H and a line evicted (the largest size chase;
// where even it kept its lines, the median of the three most spaced-out). On this project's
// AMD VM (2026-11-27) the chases jumped from 16 to 115 ns between 4 and 6 MiB, and a 2 MiB
// chase went from 14 to 127 ns as its steps grew from 0.1 to 1 us. Without crossings, the level cpuid reports and no others' fills.
struct SeenLevel {
    uint32_t kib = 0;
    double latency_ns = 0.0;
    double foreign_fill_per_us = 0.0;  // r, lines per microsecond
    bool cut = false;                  // ends short of what cpuid reports
};
SeenLevel last_level_seen(const HostDescription& host);

// Measures what describe_host needs (the ISA comes from the caller: kernels/simd/isa.h);
// without `measure_memory`, no load latencies or chases (the caller sets memory_source).
HostDescription describe_host(uint32_t simd_width, const std::string& isa,
                              bool measure_memory = true);

// The configuration: one core, one SIMD unit of the ISA's width at the TSC clock; the ray
// buffers in the L1D (storage l1d, no banks), partition by compress; the caches as scene
// memory with measured latencies (or HostDescription::memory, where it names its source).
// `op_costs` as given (the fitted ones, or empty).
HwConfig host_hw_config(const HostDescription& host, const std::vector<OpCostConfig>& op_costs);

// host.hw.yaml text: host_hw_config with a comment on every value naming its source.
std::string host_hw_yaml(const HostDescription& host, const std::vector<OpCostConfig>& op_costs,
                         const std::string& fit_note);

}  // namespace sfx
