#pragma once
// What a timing model predicts for one hardware configuration: a frame's cycles and where they
// went. Stats are a tree of dotted names with units (gem5 style); ratios (fps, utilization,
// percentages, rates) are derived when the stats are dumped, never accumulated.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hw_model/action_counts.h"
#include "hw_model/hw_config.h"
#include "hw_model/tech_table.h"
#include "kernels/trace.h"

namespace sfx {

enum class Fidelity { analytic, sampled, full };
const char* to_string(Fidelity f);
Fidelity parse_fidelity(const std::string& text);  // throws std::invalid_argument

struct StallCycles {
    uint64_t bank_conflict = 0;  // gathers/scatters waiting on a busy bank
    uint64_t alignment = 0;      // id-stream groups straddling or starting off a buffer line
    uint64_t address_fetch = 0;  // address generation slower than the data it feeds
    uint64_t partition = 0;      // in-place partition after a filter
    uint64_t scene_memory = 0;   // waiting for a node, primitive or material
    uint64_t interconnect = 0;   // address and data words contending for the interconnect
    uint64_t pipeline_fill = 0;  // waiting out bank, interconnect and datapath latencies
    uint64_t unit_idle = 0;      // a SIMD unit with no group released to it (too few groups)

    uint64_t total() const {
        return bank_conflict + alignment + address_fetch + partition + scene_memory + interconnect +
               pipeline_fill + unit_idle;
    }
    StallCycles& operator+=(const StallCycles& o);
};

// SIMD instructions by class, as the paper's Table 5 counts them.
struct OpMix {
    uint64_t load = 0;     // id-stream reads and scene-data reads (address integer ops subsumed)
    uint64_t store = 0;    // id-stream writes (the next generation's ids, partition moves)
    uint64_t compute = 0;  // arithmetic on ray data
    uint64_t scatter_gather = 0;  // ray-record gathers and conditional scatters
    uint64_t partition = 0;       // comparator passes of the partition unit
    // Of all the above, those issued for ops a workload option adds (is_option_kind): the
    // option's own overhead. Not part of total().
    uint64_t option = 0;

    uint64_t total() const { return load + store + compute + scatter_gather + partition; }
    OpMix& operator+=(const OpMix& o);
};

// Cycle counters of SIMD units are summed over the units of every core (unit-cycles): per pass,
// busy plus stall cycles of all stages equal units x the pass's cycles.
struct StageTiming {
    uint64_t ops = 0;
    uint64_t lanes = 0;        // useful lanes (stream lengths)
    uint64_t groups = 0;       // lane groups issued: sum of ceil(len / width)
    uint64_t busy_cycles = 0;  // unit-cycles issuing work (no stalls)
    uint64_t stall_cycles = 0;
    StageTiming& operator+=(const StageTiming& o);
};

struct FrameTiming {
    uint64_t cycles = 0;  // summed over passes, each on the core that ran it (core-cycles)
    StallCycles stalls;
    OpMix mix;
    StageTiming stages[2][k_op_stage_count];         // [secondary][stage]
    uint64_t field_accesses = 0;                     // one field word for one lane group
    uint64_t conflicted_accesses = 0;                // of those, how many waited on a bank
    std::vector<uint64_t> cache_hits, cache_misses;  // per scene-cache level
    uint64_t dram_reads = 0;
    uint64_t passes = 0;
    ActionCounts actions;  // what each unit did, for area_energy's costing

    FrameTiming& operator+=(const FrameTiming& o);
    // Adds o * weight (each counter rounded): the expansion of a sampled pass to its stratum.
    void add_scaled(const FrameTiming& o, double weight);
};

// What happened between two snapshots of the same model (b taken after a).
FrameTiming timing_between(const FrameTiming& a, const FrameTiming& b);

struct Stat {
    std::string name;
    double value = 0.0;
    std::string unit;
    std::string description;
};

struct Prediction {
    HwConfig config;  // fully resolved
    Fidelity fidelity = Fidelity::full;
    uint32_t tile = 0;
    uint32_t bytes_per_ray = 0;
    FrameTiming timing;
    // Ideal utilization at this configuration's width, from the trace: [secondary][stage] and
    // over all rays [stage].
    double ideal_utilization[2][k_op_stage_count] = {};
    double ideal_utilization_all[k_op_stage_count] = {};
    // The workload's own measures (the same for every configuration of a render): box tests
    // per traced ray [secondary] and the mean depth of primary entry points (root 0).
    double box_tests_per_ray[2] = {};
    double entry_depth = 0.0;
    double host_seconds = 0.0;   // the functional render's share plus this model's own time
    double error_relative = -1;  // half-width of the frame-cycle interval / estimate; <0: unknown
    uint64_t sample_passes = 0;  // tile passes timed (all of them at full fidelity)
    uint64_t total_passes = 0;
    // The technology table pricing area and energy in stats(); null: default_tech_table().
    std::shared_ptr<const TechTable> tech;

    // The frame's cycles: passes' core-cycles over the cores (tiles keep every core busy).
    double frame_cycles() const;
    double frame_seconds() const;
    double fps() const;
    // Every stat with its dotted name, unit and description; the JSON and result columns.
    std::vector<Stat> stats() const;
};

}  // namespace sfx
