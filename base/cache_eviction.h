#pragma once
// Evicting the caches before a measurement that needs its data in DRAM (a scene's cold render,
// DRAM's latency, the branch microbenchmark's evicted batches): other data read a line at a
// time, three times the largest cache the CPU reports and at least 256 MiB. The largest cache,
// not what a core keeps of it: on the Intel Xeon VM of family 6 model 0xCF (cpuid's L3 260 MiB,
// a core's chases keeping 17-29 MiB of it) a chase over 4 MiB, run five times and then read
// after 256 MiB of other data, still read at 44-91 ns a load against 34 ns warm and 110-127 ns
// after 768 MiB (medians of 4096-load runs, 2026-12-07): one core there fills the whole L3, and
// 256 MiB left much of a scene in it.

#include <cstdint>
#include <string>

namespace sfx {

constexpr uint64_t k_min_eviction_bytes = uint64_t(256) << 20;

// How much other data evicts caches whose largest level holds `largest_cache_bytes`.
uint64_t eviction_bytes(uint64_t largest_cache_bytes);

// The largest cache sysfs reports under `cache_dir` (index0, index1, ... each with its `size`,
// "48K"); 0 where it reports none. A plain read of sysfs: hw_model's read_host_caches, which
// describes every level (and falls back to cpuid), is above this layer.
uint64_t largest_cache_bytes(const std::string& cache_dir = "/sys/devices/system/cpu/cpu0/cache");

// Reads eviction_bytes(largest_cache_bytes()) of other data (in huge pages, allocated once) a
// line at a time: nothing read before it is left in this core's caches.
void evict_caches();

}  // namespace sfx
