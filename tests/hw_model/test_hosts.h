#pragma once
// What the hardware-model tests share: a small triangle workload's shape, and a host described
// as sfx calibrate --describe-host would, without measuring this machine.

#include <vector>

#include "hw_model/host_description.h"
#include "hw_model/workload_shape.h"

namespace sfx {

inline WorkloadShape triangle_shape(uint32_t tile) {
    WorkloadShape s;
    s.features.triangles = true;
    s.features.lambertian = true;
    s.features.light_count = 1;
    s.triangles = 100;
    s.bvh_nodes = 64;
    s.tile = tile;
    return s;
}

// 16 lanes at 1 GHz (a cycle a nanosecond); a 32 KiB L1D (1 ns), a 256 KiB L2 (5 ns), DRAM
// 81 ns; 64-byte ray slots.
inline HostDescription small_host() {
    HostDescription h;
    h.simd_width = 16;
    h.isa = "avx512 (16 lanes)";
    h.tsc_mhz = h.core_mhz = 1000.0;
    h.caches = {{1, "data", 32, 64, 8, false, "test"}, {2, "unified", 256, 64, 8, false, "test"}};
    h.latency_ns = {1.0, 5.0, 81.0};
    h.slot_bytes = 64;
    return h;
}

// `costs`, and a free cost for every other op kind: a host that can time any workload.
inline std::vector<OpCostConfig> costs_for_every_kind(std::vector<OpCostConfig> costs) {
    for (const OpKindInfo& k : k_op_kinds) {
        bool given = false;
        for (const OpCostConfig& c : costs) given |= c.op == k.name;
        if (given) continue;
        costs.emplace_back();
        costs.back().op = k.name;
    }
    return costs;
}

}  // namespace sfx
