#pragma once
// What each kind of stream operation asks of the hardware: which ray-record words it gathers
// for every lane, which it scatters for the lanes that pass, how many SIMD compute instructions
// it issues per lane group, which datapath latency it pays, what scene data it fetches, and
// whether its mask partitions the stream; or, on a CPU core, what the op's kind was measured to
// cost (HwConfig::op_costs). This is the one place a lane group's issue cycles are priced
// (OpProfile::issue_cycles); the models decide when a group issues and what it waits for.

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hw_model/cache_model.h"
#include "hw_model/hw_config.h"
#include "hw_model/workload_shape.h"
#include "kernels/trace.h"
#include "workloads/scene.h"

namespace sfx {

// Word offsets of the ray-record fields (structure of arrays: field word w of slot s is at
// w * capacity + s). Fields a scene does not need are absent (offset -1).
class RayRecordLayout {
  public:
    explicit RayRecordLayout(const FeatureSet& features);
    const FeatureSet& features() const { return m_features; }
    uint32_t words() const { return m_words; }
    uint32_t bytes() const { return m_words * 4; }
    // Word offsets of a named field (empty when the scene has no such field).
    const std::vector<uint32_t>& field(const std::string& name) const;

  private:
    FeatureSet m_features;
    uint32_t m_words = 0;
    std::vector<std::pair<std::string, std::vector<uint32_t>>> m_fields;
    std::vector<uint32_t> m_none;
};

// A filter's per-group body by function-unit class (issue: cluster): instructions, or steps of
// a dependent chain.
struct UnitClassCounts {
    uint32_t fpu = 0, alu = 0, mul = 0;
    uint32_t total() const { return fpu + alu + mul; }
    // The chain's latency at the datapath's class latencies.
    uint32_t latency(const DatapathConfig& d) const {
        return fpu * d.fpu_latency_cycles + alu * d.alu_latency_cycles + mul * d.mul_latency_cycles;
    }
};

// A filter's per-group body as a modulo-scheduled loop on a cluster (Rau, "Iterative modulo
// scheduling", MICRO 1994): a group every `ii` cycles, the larger of the resource bound (each
// class's instructions over its units, rounded up) and the recurrence bound (the loop-carried
// chain's latency at distance 1); a group's mask `length` cycles after it starts (its dependent
// chain; at least ii).
struct ModuloSchedule {
    uint32_t resource_ii = 1, recurrence_ii = 0, ii = 1, length = 1;
};
ModuloSchedule modulo_schedule(const UnitClassCounts& body, const UnitClassCounts& chain,
                               const UnitClassCounts& recurrence, const DatapathConfig& datapath);

// The lanes of an op's rarer outcome, passing or failing (`passed` of `lanes`): what a
// branch predictor misses on outcomes in no order (OpCostConfig::per_minority_lane_cycles).
inline uint32_t minority_lanes(uint32_t passed, uint32_t lanes) {
    passed = std::min(passed, lanes);
    return std::min(passed, lanes - passed);
}
// How often a stream's outcomes (`passed`, one per lane, in stream order) change from one lane
// to the next.
inline uint32_t outcome_changes(const uint8_t* passed, uint32_t lanes) {
    uint32_t changes = 0;
    for (uint32_t i = 1; i < lanes; ++i) changes += (passed[i] != 0) != (passed[i - 1] != 0);
    return changes;
}
// The lanes whose outcome a filter's branch predictor misses: on outcomes in no order, the
// rarer outcome's lanes (it guesses the commoner one); on outcomes in runs, about one at each
// change (its history follows a run). The fewer of the two. A frame's streams come in runs
// where neighbouring pixels agree or a generation's rays were pushed by kind (its shadow rays
// before its bounces); the microbenchmarks' streams are dealt at random, where the rarer
// outcome's lanes are the fewer. Without the lanes' order (counts only), the rarer outcome's.
inline uint32_t mispredicted_lanes(uint32_t passed, uint32_t lanes, uint32_t changes) {
    return std::min(minority_lanes(passed, lanes), changes);
}

// A CPU core's tracer (trace off, kernels/stream/stream_tracer.cpp) sorts a generation's
// stream by material once, at its first material filter (the op right after the depth filter,
// priced over its lanes as the sort: its microbenchmark times the sort), and the later
// material filters find their lanes in place: they cost nothing. The trace keeps G&R's
// filter stack, one partition per material, which a machine priced from instructions runs.
// On an Intel Xeon VM (2026-11-29) the filters priced as partitions came out 2-4x the sort.
// `previous`: the kind of the pass's op before.
inline bool placed_by_material_sort(OpKind kind, OpKind previous) {
    return kind == OpKind::material_filter && previous != OpKind::depth_filter;
}

struct OpProfile {
    std::vector<uint32_t> gather_words;   // gathered for every lane
    std::vector<uint32_t> scatter_words;  // scattered for passing lanes
    uint32_t compute_instructions = 1;    // SIMD instructions per lane group
    uint32_t chain_steps = 1;             // longest dependent chain of those instructions
    uint32_t latency_cycles = 1;          // chain_steps * fp latency: paid once per group
    // The same body by function-unit class (their totals are compute_instructions and
    // chain_steps), the loop-carried chain, and its schedule on the configured cluster.
    UnitClassCounts body, chain, recurrence;
    ModuloSchedule schedule;
    uint32_t scene_bytes = 0;             // scene data fetched once per op (broadcast operand)
    // Scene data gathered per lane (op table: reads_hit_primitive): each lane's hit primitive,
    // `lane_scene_words` words of it (a triangle's vertices, or a sphere) per lane group.
    bool lane_scene_reads = false;
    uint32_t lane_scene_words = 0;
    bool partitions = false;              // the mask partitions the stream in place (op table)
    bool pushes_rays = false;             // passing lanes write the next generation (op table)
    // A CPU core's fitted cost of this kind (HwConfig::op_costs): it replaces the instruction
    // count and chain, and holds the lanes' loads, stores and compress-stores.
    bool measured = false;
    OpCostConfig cost;

    // Cycles a SIMD unit spends issuing one group of `lanes` lanes, `passed` of them passing
    // (the pass rate where the closed form prices a bucket of one-lane ops), of an op of
    // `length` lanes, `op_mispredicted` of them mispredicted (mispredicted_lanes;
    // `first`: the op's first group,
    // which carries a measured per-op cost), with a share `beyond_l1` of its lanes paying for
    // an l1d buffer beyond the L1D (beyond_cache_share, lanes_opening_pages) and `beyond_l2`
    // for one beyond the L2 as well, `op_failed_candidates`
    // of the op's lanes failing candidates (StreamOp::failed_candidates; 0: none, or a mean
    // over ops where the closed form prices a bucket of them), and a share `beyond_l1_skipping`
    // beyond the L1D that skip lines in a page the lane before opened (beyond_cache_skipping_share,
    // lane_skips_lines), and a share `beyond_tlb` that open a page beyond the first-level DTLB's
    // reach (beyond_tlb_share). A measured
    // minority cost and failed candidates' cost are the op's, shared by its groups by lanes (the
    // trace does not say which lanes they are). Fractional for measured costs (the caller carries
    // the remainder); instruction-priced groups cost compute_instructions (programmable), the
    // initiation interval (pipelined) or the body's modulo-schedule II (cluster).
    double issue_cycles(const DatapathConfig& datapath, uint32_t length, uint32_t op_mispredicted,
                        uint32_t lanes, double passed, bool first, double beyond_l1,
                        double beyond_l2 = 0.0, double op_failed_candidates = 0.0,
                        double beyond_l1_skipping = 0.0, double beyond_tlb = 0.0) const;
    // Cycles an op adds on its first group when it enters the traversal's one-ray or few-ray
    // loop from the stream loop (TraversalLoop, kernels/trace.h): a measured box test's loop
    // entry cost; 0 for any other op or loop.
    double loop_entry_cycles(TraversalLoop loop) const;
    // Cycles the op adds on its first group when it starts a traversal (StreamOp::
    // starts_traversal): a measured box test's traversal_start_cycles; 0 otherwise.
    double traversal_start_cycles() const;
    // Cycles the op adds on its first group as a frame calls it, cold: a measured op's
    // cold_call_cycles; 0 otherwise.
    double cold_call_cycles() const;
    // Cycles the op adds on its first group when it starts a traversal whose `lanes` rays share
    // one origin (StreamOp::origin_shared): a measured box test's shared_origin_per_lane_cycles
    // x the lanes after the first (each compared with it); 0 otherwise.
    double shared_origin_cycles(uint32_t lanes) const;
    // Cycles from a group's first issue to its mask: the measured cost (its loads and chain are
    // inside it), the datapath's dependent chain or the cluster's schedule length.
    double result_cycles(const DatapathConfig& datapath, double issue) const;
};

// One profile per OpKind for a scene's layout and a configuration's datapath.
class OpCostTable {
  public:
    OpCostTable(const RayRecordLayout& layout, const DatapathConfig& datapath);
    // With the configuration's partition (compress adds its two compress-stores per group to
    // the instruction count) and measured op costs.
    OpCostTable(const RayRecordLayout& layout, const HwConfig& config);
    // A kind the workload can emit (`needed`) without a measured cost on a configuration that
    // has measured costs: throws InputError naming the configuration and the kind.
    void check_measured(const std::array<bool, k_op_kind_count>& needed,
                        const std::string& config_name) const;
    const OpProfile& operator[](OpKind kind) const { return m_profiles[size_t(kind)]; }

  private:
    std::array<OpProfile, k_op_kind_count> m_profiles;
};

// Where the scene data of an op's object lives (a flat layout: nodes, then triangles' vertex
// triples, then spheres, then materials; far beyond them, for scene_memory.hit_reads mesh, the
// mesh's triangle records and vertices), for the cache model.
struct SceneDataMap {
    uint64_t node_bytes = 32, triangle_bytes = 36, sphere_bytes = 16, material_bytes = 64;
    // The mesh's own arrays (workloads/scene.h): a triangle's record (three vertex ids and a
    // material: 16 bytes, Triangle), and its vertices, assumed its own three (36 bytes) in
    // triangle order (a mesh shares vertices; the trace names no vertex ids).
    uint64_t mesh_triangle_bytes = 16;
    uint64_t nodes = 0, triangles = 0, spheres = 0;
    uint64_t vertices = 0;  // the meshes' own (0: unknown; three a triangle then)
    std::shared_ptr<const std::vector<uint8_t>> node_leaf;  // WorkloadShape::node_leaf

    uint64_t address(OpKind kind, uint32_t object) const;
    // The bytes the scene's data spans: nodes, primitive records, and the mesh's triangle
    // records and its vertices (12 bytes each; hit_reads mesh reads them), without the room
    // address() leaves for materials (a few lines). What DRAM's latency depends on
    // (dram_latency_ns_at).
    uint64_t span_bytes() const;

    // The reads of a hit primitive's surface (a global primitive id: triangles, then spheres):
    // its record as its intersection test fetched it, or (`mesh`) the mesh's triangle record
    // and then its vertices; a sphere's record either way. Returns how many (1 or 2).
    struct Read {
        uint64_t address = 0;
        uint32_t bytes = 0;
    };
    uint32_t hit_reads(uint32_t prim, bool mesh, Read out[2]) const;
};
// The scene data of a workload laid out as SceneDataMap says.
SceneDataMap scene_data_map(const WorkloadShape& shape);

// A CPU core's lane: the reads of its hit primitive `prim` (SceneDataMap::hit_reads) looked up
// in `memory` at `now`, their latencies beyond `hidden` cycles (hit_read_latency_hidden)
// summed, DRAM taken as idle. CoreModel::request_scene prices a group's lanes with it,
// and the exposed-share fit (hw_model/op_cost_fit.h) models its microbenchmark with it.
uint64_t hit_latency_beyond(SceneMemoryModel& memory, const SceneDataMap& map, uint32_t core,
                            uint32_t prim, bool mesh, uint64_t now, uint64_t hidden);
// The same reads touched in the caches only (warming).
void warm_hit(SceneMemoryModel& memory, const SceneDataMap& map, uint32_t core, uint32_t prim,
              bool mesh);

}  // namespace sfx
