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
// spanning `bytes` (so it hits the level that holds that many bytes).
double measure_load_latency_ns(uint64_t bytes, double tsc_mhz);

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
    // Chases over 4, 8 and 16 MiB (KiB, ns) when the last level reports more than 16 MiB: on a
    // virtual machine the L3 a core sees can end well short of what cpuid reports, and its
    // latency (the 8 MiB chase) is then a draw on that knee. Reported, not used.
    std::vector<std::pair<uint32_t, double>> last_level_chases;
    uint32_t slot_bytes = 0;         // one ray slot of the native tracer (0: unknown)
    double speed_probe_cycles = 0.0;  // HwConfig::speed_probe_cycles (0: not measured)
    // The CPU the description was measured on (sched_getcpu; -1: unknown). On a virtual machine
    // one CPU's L3 may not be another's (a neighbour's load on its physical core): the check
    // runs pinned where its host was described (scripts/silicon-check --cpu).
    int cpu = -1;
};

// Measures what describe_host needs (the ISA comes from the caller: kernels/simd/isa.h).
HostDescription describe_host(uint32_t simd_width, const std::string& isa);

// The configuration: one core, one SIMD unit of the ISA's width at the TSC clock; the ray
// buffers in the L1D (storage l1d, no banks), partition by compress; the caches as scene
// memory with measured latencies. `op_costs` as given (the fitted ones, or empty).
HwConfig host_hw_config(const HostDescription& host, const std::vector<OpCostConfig>& op_costs);

// host.hw.yaml text: host_hw_config with a comment on every value naming its source.
std::string host_hw_yaml(const HostDescription& host, const std::vector<OpCostConfig>& op_costs,
                         const std::string& fit_note);

}  // namespace sfx
