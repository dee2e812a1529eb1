#pragma once
// The processes of one core (G&R 3.3), each a thin sc_module around CoreModel's arithmetic,
// connected by bounded sc_fifos so that overlap and back-pressure are what the processes do:
//
//   Dispatcher --groups--> FetchUnit[u] --fetched groups (agu.queue_depth)--> SimdUnit[u]
//        ^                  (ids, addresses, gathers)                         (compute, scatters)
//        |                                                                       |
//        +---- ids in place <---- PartitionUnit <---- last mask of a filter -----+
//
// The dispatcher walks the pass's ops in order and hands out lane groups round-robin to the
// SIMD units; it holds an op back only until the partition its stream depends on is done (an op
// that does not partition leaves its stream as it was, so the next op's groups flow on: the
// access side runs ahead of execution, decoupled access/execute). Scene data is requested as an
// op is dispatched, or scene_memory.prefetch_depth ops earlier, or (prefetch_children) when the
// op whose partition feeds it is dispatched (or, where that op's scene data holds its address,
// once that has arrived: CoreModel::request_child_scene).

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "hw_model/core_model.h"
#include "hw_model/systemc/clocked.h"

namespace sfx {

struct PartitionRequest {
    uint32_t op = 0;
    uint64_t ready = 0;  // cycle the op's last mask is known
};
inline std::ostream& operator<<(std::ostream& o, const GroupToken& t) {
    return o << t.op;
}
inline std::ostream& operator<<(std::ostream& o, const PartitionRequest& r) {
    return o << r.op;
}

// Where a core takes its next pass from, and gives back what it measured.
class PassSource {
  public:
    virtual ~PassSource() = default;
    virtual std::shared_ptr<const PassBuffer> next_pass() = 0;  // blocks until a pass is queued
    virtual void pass_done(const FrameTiming& timing) = 0;
};

class Core;

// The access side of one SIMD unit: reads the group's ids, generates its addresses on the
// core's shared address units, gathers its words through the banks and the interconnect, and
// queues it for execution; it runs ahead while the queue has room.
class FetchUnit : public sc_core::sc_module {
  public:
    SC_HAS_PROCESS(FetchUnit);
    FetchUnit(sc_core::sc_module_name name, Core& core, uint32_t unit);
    sc_core::sc_fifo<GroupToken> in;  // from the dispatcher

  private:
    void run();
    Core& m_core;
    uint32_t m_unit;
};

// One N-wide SIMD unit: executes fetched groups in order, scatters the passing lanes' results
// and, for an op's last group, hands the op to the partition unit (or marks it done).
class SimdUnit : public sc_core::sc_module {
  public:
    SC_HAS_PROCESS(SimdUnit);
    SimdUnit(sc_core::sc_module_name name, Core& core, uint32_t unit, uint32_t queue_depth);
    sc_core::sc_fifo<GroupToken> in;  // fetched groups, at most agu.queue_depth

  private:
    void run();
    Core& m_core;
    uint32_t m_unit;
};

// The in-place partition unit (SIMD comparators, then id moves), one op at a time.
class PartitionUnit : public sc_core::sc_module {
  public:
    SC_HAS_PROCESS(PartitionUnit);
    PartitionUnit(sc_core::sc_module_name name, Core& core);
    sc_core::sc_fifo<PartitionRequest> in;

  private:
    void run();
    Core& m_core;
};

// One core: its model, its dispatcher process and its units.
class Core : public sc_core::sc_module {
  public:
    SC_HAS_PROCESS(Core);
    Core(sc_core::sc_module_name name, const HwConfig& config, const OpCostTable& costs,
         const SceneDataMap& map, uint32_t record_words, uint32_t slot_capacity, uint32_t index,
         std::shared_ptr<SceneMemoryModel> scene_memory, std::shared_ptr<CycleWakeups> wakeups,
         PassSource& source);

    CoreModel& model() { return m_model; }
    const CoreClock& clock() const { return m_clock; }
    FetchUnit& fetch_unit(uint32_t u) { return *m_fetch[u]; }
    SimdUnit& simd_unit(uint32_t u) { return *m_simd[u]; }
    PartitionUnit& partition_unit() { return *m_partition; }

    // An op's last group completes (or its partition ends) at `cycle`.
    void op_finished(uint64_t cycle);
    // The partition of op `op` occupied [start, end).
    void partition_done(uint32_t op, uint64_t start, uint64_t end);

  private:
    void dispatch();

    CoreModel m_model;
    CoreClock m_clock;
    PassSource& m_source;
    std::vector<std::unique_ptr<FetchUnit>> m_fetch;
    std::vector<std::unique_ptr<SimdUnit>> m_simd;
    std::unique_ptr<PartitionUnit> m_partition;
    sc_core::sc_event m_partition_event, m_op_event;
    uint32_t m_partitions_pending = 0;
    std::vector<uint8_t> m_partitioned;  // per op of the pass: its partition is done
    uint64_t m_partition_start = 0, m_partition_end = 0;  // the latest partition done
    uint64_t m_outstanding = 0;
    uint64_t m_last_completion = 0;
};

}  // namespace sfx
