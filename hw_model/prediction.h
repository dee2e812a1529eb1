#pragma once
// What a timing model predicts for one hardware configuration: a frame's cycles and where they
// went. Stats are a tree of dotted names with units (gem5 style); ratios (fps, utilization,
// percentages, rates) are derived when the stats are dumped, never accumulated.

#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "hw_model/action_counts.h"
#include "hw_model/counter_info.h"
#include "hw_model/hw_config.h"
#include "hw_model/tech_table.h"
#include "kernels/trace.h"

namespace sfx {

enum class Fidelity { analytic, sampled, full };
const char* to_string(Fidelity f);
Fidelity parse_fidelity(const std::string& text);  // throws std::invalid_argument

// Stall cycles by cause. A template so that a model may sum expected (fractional) stalls in
// the same shape and round once (analytic_model.cpp).
template <class T>
struct StallCounts {
    T bank_conflict{};  // gathers/scatters waiting on a busy bank
    T alignment{};      // id-stream groups straddling or starting off a buffer line
    T address_fetch{};  // address generation slower than the data it feeds
    T partition{};      // in-place partition after a filter
    T scene_memory{};   // waiting for a node, primitive or material
    T interconnect{};   // address and data words contending for the interconnect
    T pipeline_fill{};  // waiting out bank, interconnect and datapath latencies
    T unit_idle{};      // a SIMD unit with no group released to it (too few groups)

    template <class A, class B, class F>
    static void visit(A& a, B& b, F&& f) {
        f(CounterInfo("bank_conflict", "cycles", "waiting on a busy ray-buffer bank"),
          a.bank_conflict, b.bank_conflict);
        f(CounterInfo("alignment", "cycles", "SIMD groups not aligned to buffer lines"),
          a.alignment, b.alignment);
        f(CounterInfo("address_fetch", "cycles", "address generation behind the data path"),
          a.address_fetch, b.address_fetch);
        f(CounterInfo("partition", "cycles", "in-place stream partition"), a.partition,
          b.partition);
        f(CounterInfo("scene_memory", "cycles", "waiting for scene data"), a.scene_memory,
          b.scene_memory);
        f(CounterInfo("interconnect", "cycles", "interconnect contention"), a.interconnect,
          b.interconnect);
        f(CounterInfo("pipeline_fill", "cycles",
                      "waiting out bank, interconnect and datapath latency"),
          a.pipeline_fill, b.pipeline_fill);
        f(CounterInfo("unit_idle", "cycles", "a SIMD unit with no group released to it"),
          a.unit_idle, b.unit_idle);
    }
    T total() const {
        T sum{};
        visit(*this, *this, [&](const CounterInfo&, const T& v, const T&) { sum += v; });
        return sum;
    }
    StallCounts& operator+=(const StallCounts& o) {
        visit(*this, o, [](const CounterInfo&, T& x, const T& y) { x += y; });
        return *this;
    }
};
using StallCycles = StallCounts<uint64_t>;

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

    template <class A, class B, class F>
    static void visit(A& a, B& b, F&& f) {
        f(CounterInfo("load", "instructions", "loads (Table 5)"), a.load, b.load);
        f(CounterInfo("store", "instructions", "stores (Table 5)"), a.store, b.store);
        f(CounterInfo("compute", "instructions", "compute on ray data (Table 5)"), a.compute,
          b.compute);
        f(CounterInfo("scatter_gather", "instructions", "scatters and gathers (Table 5)"),
          a.scatter_gather, b.scatter_gather);
        f(CounterInfo("partition", "instructions", "partition (Table 5)"), a.partition,
          b.partition);
        f(CounterInfo("option", "instructions",
                      "instructions of the ops a workload option adds (its own overhead; also "
                      "counted in the classes above)"),
          a.option, b.option);
    }
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
    uint64_t scene_memory_cycles = 0;  // of the stalls, waiting for scene data

    template <class A, class B, class F>
    static void visit(A& a, B& b, F&& f) {
        f(CounterInfo("ops", "operations", "filter operations issued"), a.ops, b.ops);
        f(CounterInfo("lanes", "rays", "useful lanes: the operations' stream lengths"), a.lanes,
          b.lanes);
        f(CounterInfo("groups", "groups", "lane groups issued: sum of ceil(length / width)"),
          a.groups, b.groups);
        f(CounterInfo("busy_cycles", "cycles", "unit-cycles issuing work"), a.busy_cycles,
          b.busy_cycles);
        f(CounterInfo("stall_cycles", "cycles", "unit-cycles stalled"), a.stall_cycles,
          b.stall_cycles);
        f(CounterInfo("scene_memory_cycles", "cycles",
                      "unit-cycles stalled waiting for scene data (part of stall_cycles)"),
          a.scene_memory_cycles, b.scene_memory_cycles);
    }
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
    // The box tests' unit-cycles (busy and stalled) by the native tracer's loop that runs them
    // (TraversalLoop, kernels/trace.h): what the tracer's stage clock splits the traversal
    // into (RenderStats::short_loop_tsc). Cycle-level models only.
    uint64_t traversal_loop_cycles[3] = {0, 0, 0};
    // Of those, what the box tests' mispredicted branches cost (branch_cycles by loop), and
    // their wait for scene data (stall_cycles.scene_memory by loop): what each loop's
    // prediction is made of, beside its ops' own costs.
    uint64_t traversal_loop_branch_cycles[3] = {0, 0, 0};
    uint64_t traversal_loop_memory_cycles[3] = {0, 0, 0};
    // The intersection ops' unit-cycles by the loop whose leaf code runs them (that of the box
    // test of their leaf): what the tracer's stage clock splits the intersection stage into
    // (RenderStats::short_loop_leaf_tsc). Cycle-level models only.
    uint64_t intersection_loop_cycles[3] = {0, 0, 0};
    // Each op kind's unit-cycles (busy and stalled), what the tracer's stage clock splits the
    // shading stage into (RenderStats::shading_op_tsc). Cycle-level models only.
    uint64_t op_cycles[k_op_kind_count] = {};
    // A CPU core's branch predictor (HwConfig::branch_predictor): the traversal's branches it
    // mispredicted, and the unit-cycles they cost (part of the busy cycles). Cycle level only.
    uint64_t branch_mispredictions = 0, branch_cycles = 0;

    // Every counter of a and b in step (b's cache levels are made a's first if a has fewer).
    template <class A, class B, class F>
    static void visit(A& a, B& b, F&& f);

    FrameTiming& operator+=(const FrameTiming& o);
    // Adds o * weight (each counter rounded): the expansion of a sampled pass to its stratum.
    void add_scaled(const FrameTiming& o, double weight);
};

// What happened between two snapshots of the same model (b taken after a).
FrameTiming timing_between(const FrameTiming& a, const FrameTiming& b);

// Scales the stall causes, and each stage's stall cycles, by one factor so that busy and stall
// unit-cycles add up to `units` x the cycles, as they do at cycle level by construction: a
// closed form's (calibrated) cycles keep its work and its mix of causes. Unchanged when there
// is no stall to scale.
void fit_stalls_to_cycles(FrameTiming& t, uint32_t units);

template <class A, class B, class F>
void FrameTiming::visit(A& a, B& b, F&& f) {
    f(CounterInfo("cycles", "core-cycles", "cycles summed over passes"), a.cycles, b.cycles);
    StallCycles::visit(a.stalls, b.stalls,
                       [&](const CounterInfo& c, auto& x, auto& y) { f(c.under("stalls"), x, y); });
    OpMix::visit(a.mix, b.mix,
                 [&](const CounterInfo& c, auto& x, auto& y) { f(c.under("mix"), x, y); });
    for (int s = 0; s < 2; ++s)
        for (uint32_t k = 0; k < k_op_stage_count; ++k)
            StageTiming::visit(a.stages[s][k], b.stages[s][k],
                               [&](const CounterInfo& c, auto& x, auto& y) {
                                   f(c.under(to_string(OpStage(k)))
                                         .under(s == 0 ? "primary" : "secondary")
                                         .under("stages"),
                                     x, y);
                               });
    f(CounterInfo("field_accesses", "accesses", "one field word for one lane group"),
      a.field_accesses, b.field_accesses);
    f(CounterInfo("conflicted_accesses", "accesses", "field accesses that waited on a bank"),
      a.conflicted_accesses, b.conflicted_accesses);
    if constexpr (!std::is_const_v<A>) {
        if (a.cache_hits.size() < b.cache_hits.size()) {
            a.cache_hits.resize(b.cache_hits.size());
            a.cache_misses.resize(b.cache_misses.size());
        }
    }
    for (size_t i = 0; i < b.cache_hits.size() && i < a.cache_hits.size(); ++i) {
        f(CounterInfo(index_name(i), "lookups", "scene-cache hits").under("cache_hits"),
          a.cache_hits[i], b.cache_hits[i]);
        f(CounterInfo(index_name(i), "lookups", "scene-cache misses").under("cache_misses"),
          a.cache_misses[i], b.cache_misses[i]);
    }
    f(CounterInfo("dram_reads", "lines", "scene-data lines read from DRAM"), a.dram_reads,
      b.dram_reads);
    f(CounterInfo("passes", "passes", "tile passes"), a.passes, b.passes);
    const char* loops[3] = {"one_ray", "few_ray", "stream"};
    for (int l = 0; l < 3; ++l)
        f(CounterInfo(loops[l], "cycles",
                      "box tests' unit-cycles in the tracer's loop of that name")
              .under("traversal_loop_cycles"),
          a.traversal_loop_cycles[l], b.traversal_loop_cycles[l]);
    for (int l = 0; l < 3; ++l)
        f(CounterInfo(loops[l], "cycles",
                      "of those, what the box tests' mispredicted branches cost")
              .under("traversal_loop_branch_cycles"),
          a.traversal_loop_branch_cycles[l], b.traversal_loop_branch_cycles[l]);
    for (int l = 0; l < 3; ++l)
        f(CounterInfo(loops[l], "cycles", "of those, the box tests' wait for scene data")
              .under("traversal_loop_memory_cycles"),
          a.traversal_loop_memory_cycles[l], b.traversal_loop_memory_cycles[l]);
    for (int l = 0; l < 3; ++l)
        f(CounterInfo(loops[l], "cycles",
                      "intersection ops' unit-cycles in the leaf code of the tracer's loop of "
                      "that name")
              .under("intersection_loop_cycles"),
          a.intersection_loop_cycles[l], b.intersection_loop_cycles[l]);
    for (uint32_t k = 0; k < k_op_kind_count; ++k)
        f(CounterInfo(k_op_kinds[k].name, "cycles", "the op kind's unit-cycles, busy and stalled")
              .under("op_cycles"),
          a.op_cycles[k], b.op_cycles[k]);
    f(CounterInfo("mispredictions", "branches",
                  "traversal branches the core's branch predictor mispredicted")
          .under("branch_predictor"),
      a.branch_mispredictions, b.branch_mispredictions);
    f(CounterInfo("cycles", "cycles", "unit-cycles the mispredictions cost (part of busy)")
          .under("branch_predictor"),
      a.branch_cycles, b.branch_cycles);
    ActionCounts::visit(a.actions, b.actions, [&](const CounterInfo& c, auto& x, auto& y) {
        f(c.under("actions"), x, y);
    });
}

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
    // Per bounce (0 = primary .. 3; seeds/000 Tables 2 and 4): rays per visited node (box-test
    // stream length), per visited leaf (primitive-test stream length), box tests per ray.
    static constexpr uint32_t k_bounces = 4;
    double rays_per_node[k_bounces] = {};
    double rays_per_leaf[k_bounces] = {};
    double bounce_box_tests_per_ray[k_bounces] = {};
    // RayGrid batching: mean rays per traced queue, and the share of queues that were full.
    double batch_mean_queue = 0.0;
    double batch_full_share = 0.0;
    double batch_lanes_per_ray = 0.0;  // walk and enqueue lanes per secondary ray
    double host_seconds = 0.0;   // the functional render's share plus this model's own time
    double error_relative = -1;  // half-width of the frame-cycle interval / estimate; <0: unknown
    uint64_t sample_passes = 0;  // tile passes timed (all of them at full fidelity)
    uint64_t total_passes = 0;

    // The frame's cycles: passes' core-cycles over the cores (tiles keep every core busy).
    double frame_cycles() const;
    double frame_seconds() const;
    double fps() const;
    // Every stat with its dotted name, unit and description; the JSON and result columns.
    std::vector<Stat> stats() const;
};

}  // namespace sfx
