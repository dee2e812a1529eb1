#pragma once
// The arithmetic of one core of the machine, in plain C++: what a lane group's fetch, a SIMD
// unit's execution of it and an op's partition cost on the core's shared resources (banks,
// address-generation units, interconnect, scratchpad, scene memory), and where every SIMD
// unit's cycles went. The SystemC processes (hw_model/systemc) decide *when* each step runs
// (a dispatcher, a fetch and an execute process per SIMD unit, a partition unit); this class
// prices a step at the cycle a process asks, so the order of requests in flight decides the
// conflicts. Tests drive it directly, without a kernel.

#include <cstdint>
#include <memory>
#include <vector>

#include "hw_model/branch_predictor.h"
#include "hw_model/cache_model.h"
#include "hw_model/hw_config.h"
#include "hw_model/machine_resources.h"
#include "hw_model/op_costs.h"
#include "hw_model/pass_buffer.h"
#include "hw_model/prediction.h"

namespace sfx {

// One lane group of one op on its way through a core.
struct GroupToken {
    uint32_t op = 0;     // index in the pass
    uint32_t first = 0;  // first position in the op's stream
    uint32_t lanes = 0;
    // The partition the dispatcher waited on before releasing this op (first group only).
    uint64_t partition_start = 0, partition_end = 0;
    uint64_t dispatched = 0;  // cycle the dispatcher released the group
    // Filled by the fetch: when the gathered words reach the SIMD unit, and the excess cycles
    // of the fetch over a conflict-free, aligned, unthrottled one, by cause.
    uint64_t data_ready = 0;
    uint64_t alignment = 0, conflict = 0, address = 0, interconnect = 0;
};

class CoreModel {
  public:
    CoreModel(const HwConfig& config, const OpCostTable& costs, const SceneDataMap& map,
              uint32_t record_words, uint32_t slot_capacity, uint32_t core_index,
              std::shared_ptr<SceneMemoryModel> scene_memory);

    // A pass starts at `now`; per-op state is sized for it (and the traversal's branches run
    // through the core's branch predictor, if it has one).
    void begin_pass(const PassBuffer* pass, uint64_t now);
    // Warming: the pass's branches train the branch predictor; nothing is timed.
    void warm_branches(const PassBuffer& pass);
    // Counts an op as it is dispatched at `now` (ops, lanes, groups, the op mix); an l1d
    // core's ray lines go through its caches then.
    void dispatch_op(uint32_t op, uint64_t now = 0);
    // Requests op's scene data (a node, primitive or material) at `now`, unless it was
    // requested before (prefetched).
    void request_scene(uint32_t op, uint64_t now);
    // Requests the scene data of `consumer`, an op `producer`'s partition feeds, when
    // `producer` is dispatched at `now` (scene_memory.prefetch_children): then if its address
    // follows from the producer's object (a node's left child, left_child_index), else once the
    // producer's own scene data has arrived, which holds it (a right child, a leaf's
    // primitives).
    void request_child_scene(uint32_t producer, uint32_t consumer, uint64_t now);

    // The access side of a group at `now`: id-stream read, address generation, gathers through
    // the banks and the interconnect. Fills token.data_ready and the excess causes; returns the
    // cycle the access side may start the next group.
    uint64_t fetch(GroupToken& token, uint64_t now);

    struct Executed {
        uint64_t start = 0;       // first issue cycle
        uint64_t issue_end = 0;   // the unit may issue the next group from here
        uint64_t completion = 0;  // mask known and scatters done
        bool op_done = false;     // this was the op's last outstanding group
        uint64_t op_completion = 0;
    };
    // A SIMD unit executes a fetched group; `unit_free` is when it finished issuing its previous
    // group, `now` >= unit_free. Books the scatters and the mask's scratchpad write and charges
    // the unit's idle cycles before `start` to their causes.
    Executed execute(const GroupToken& token, uint32_t unit, uint64_t now);

    // The partition unit compacts op's stream once every group's mask is known (`ready`);
    // returns the cycle its ids are in place.
    uint64_t partition(uint32_t op, uint64_t ready);

    // The pass ends at `end` (every op done); returns its timing (SIMD units' tails charged).
    FrameTiming end_pass(uint64_t end);

    const HwConfig& config() const { return m_config; }
    uint32_t units() const { return m_config.simd.units; }
    uint32_t width() const { return m_config.simd.width; }
    const OpProfile& profile(uint32_t op) const;
    const PassBuffer& pass() const { return *m_pass; }

  private:
    void touch_ray_lines(uint32_t op, const StreamOp& stream_op, uint64_t now);
    // Books `words` for `lanes` slots of `buffer` (0: current generation, 1: next), one word's
    // requests per cycle at the earliest, from `issue`; returns the cycle the last word's data
    // is out of its bank.
    // `ready_at[w]`, when given, is the first cycle word w's addresses can be used.
    uint64_t book_words(uint32_t buffer, const std::vector<uint32_t>& words, const uint32_t* slots,
                        uint32_t lanes, uint64_t issue, const std::vector<uint64_t>* ready_at,
                        uint64_t& conflict_cycles, uint64_t& address_cycles);
    // Books the interconnect for `words` words ready at `ready`; returns the cycle the last
    // has crossed, and adds the cycles spent waiting for it beyond an idle interconnect.
    uint64_t cross(uint64_t ready, uint64_t words, uint64_t& wait_cycles);
    // Records a group's completion; the op's last group marks it done.
    Executed finish_group(const GroupToken& token, Executed e);
    void charge_idle(uint64_t idle_from, uint64_t start, const GroupToken& token,
                     StageTiming& stage);

    HwConfig m_config;
    OpCostTable m_costs;
    SceneDataMap m_map;
    uint32_t m_core;
    bool m_l1d;               // a CPU core: ray buffers behind its L1D, measured op costs
    bool m_mesh_hits;         // scene_memory.hit_reads mesh
    uint32_t m_record_bytes;  // the scene's ray record (a slot, unless ray_buffer.slot_bytes)
    uint64_t m_scene_hidden;  // scene-data latency already inside measured costs (L1D hit)
    uint64_t m_hit_read_hidden;  // of each hit-primitive read's (hit_read_latency_hidden)
    RayBufferModel m_layout;
    BankSchedule m_banks[2];  // the current generation's buffer and the next one's
    CapacityServer m_agu, m_interconnect, m_scratchpad;
    uint64_t m_crossing_cycles;
    std::shared_ptr<SceneMemoryModel> m_scene_memory;

    const PassBuffer* m_pass = nullptr;
    uint64_t m_pass_start = 0;
    std::vector<uint64_t> m_scene_ready;    // per op
    std::vector<uint64_t> m_scene_arrival;  // per op: when its own scene data arrived (or now)
    std::vector<uint8_t> m_scene_requested;  // per op: its scene data was requested
    // Per op that reads each lane's hit primitive: where its groups' entries start in
    // m_group_scene_ready, or m_group_lane_stall on a CPU core (k_none otherwise); per such
    // group, when its lanes' reads arrived.
    std::vector<size_t> m_group_scene_offset;
    std::vector<uint64_t> m_group_scene_ready;
    // A CPU core (m_l1d) instead: per such group, the cycles its lanes' reads add.
    std::vector<uint64_t> m_group_lane_stall;
    // Per op whose ray lines a CPU core reads (touch_ray_lines): where its groups' entries start
    // in m_group_beyond_lanes (k_none otherwise); per such group, its lanes that pay for ray data
    // beyond the L1D, and of them those beyond the L2 too, and those beyond the L1D that skip
    // lines in a page the lane before opened.
    struct BeyondLanes {
        uint32_t l1 = 0, l2 = 0, l1_skipping = 0;
        uint32_t pages = 0;  // lanes that open a page of their array, in the L1D or not
    };
    // The share of the pass's slots beyond the first-level DTLB's reach (beyond_tlb_fraction).
    double m_beyond_tlb = 0.0;
    std::vector<size_t> m_group_beyond_offset;
    std::vector<BeyondLanes> m_group_beyond_lanes;
    static constexpr size_t k_none = ~size_t(0);
    // When the scene data a group waits for (its op's, its lanes') has arrived.
    uint64_t scene_ready(const GroupToken& t) const;
    std::vector<uint32_t> m_groups_left;    // per op
    std::vector<uint32_t> m_mispredicted_lanes;  // per op: its filter branch's (mispredicted_lanes)
    std::vector<uint8_t> m_placed_by_sort;  // per op: a measured placed_by_material_sort op
    std::vector<uint64_t> m_op_completion;  // per op: latest group completion so far
    std::vector<uint64_t> m_unit_free;      // per SIMD unit
    std::vector<double> m_unit_carry;       // per SIMD unit: fractional issue cycles owed
    std::vector<uint8_t> m_unit_stage;  // per SIMD unit: [secondary * 3 + stage] of its last group
    // Per op: the native tracer's loop that runs it (traversal_loops: a box test's or an
    // intersection op's, else stream), and whether it enters that loop from the stream loop (a
    // short loop's first op).
    std::vector<TraversalLoop> m_loop;
    std::vector<uint8_t> m_enters_loop;
    // A CPU core's branch predictor (null: none), and per op of the pass its mispredictions.
    std::unique_ptr<TagePredictor> m_predictor;
    std::vector<uint32_t> m_mispredicted;
    // The tree's leaves (SceneDataMap::node_leaf), empty where unknown.
    const std::vector<uint8_t>& node_leaf() const;
    uint64_t m_partition_free = 0;
    FrameTiming m_timing;  // the current pass
    std::vector<uint32_t> m_scratch;
    std::vector<uint32_t> m_lane_banks;  // scratch: each lane's slot bank
    std::vector<uint64_t> m_ready_at;
};

}  // namespace sfx
