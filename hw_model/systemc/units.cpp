#include "hw_model/systemc/units.h"

#include <algorithm>

namespace sfx {

FetchUnit::FetchUnit(sc_core::sc_module_name name, Core& core, uint32_t unit)
    : sc_module(name), in("in", 2), m_core(core), m_unit(unit) {
    SC_THREAD(run);
}

void FetchUnit::run() {
    sc_core::sc_fifo<GroupToken>& out = m_core.simd_unit(m_unit).in;
    for (;;) {
        GroupToken t = in.read();
        // A fetched group needs room in the unit's queue to land in.
        while (out.num_free() == 0) wait(out.data_read_event());
        const uint64_t free = m_core.model().fetch(t, m_core.clock().now());
        out.write(t);
        m_core.clock().wait_until(free);
    }
}

SimdUnit::SimdUnit(sc_core::sc_module_name name, Core& core, uint32_t unit, uint32_t queue_depth)
    : sc_module(name), in("in", int(queue_depth)), m_core(core), m_unit(unit) {
    SC_THREAD(run);
}

void SimdUnit::run() {
    for (;;) {
        const GroupToken t = in.read();
        const CoreModel::Executed e = m_core.model().execute(t, m_unit, m_core.clock().now());
        m_core.clock().wait_until(e.issue_end);
        if (!e.op_done) continue;
        if (m_core.model().profile(t.op).partitions)
            m_core.partition_unit().in.write({t.op, e.op_completion});
        else
            m_core.op_finished(e.op_completion);
    }
}

PartitionUnit::PartitionUnit(sc_core::sc_module_name name, Core& core)
    : sc_module(name), in("in", 2), m_core(core) {
    SC_THREAD(run);
}

void PartitionUnit::run() {
    for (;;) {
        const PartitionRequest r = in.read();
        const uint64_t ready = std::max(r.ready, m_core.clock().now());
        m_core.clock().wait_until(ready);
        const uint64_t end = m_core.model().partition(r.op, ready);
        m_core.clock().wait_until(end);
        m_core.partition_done(r.op, ready, end);
        m_core.op_finished(end);
    }
}

Core::Core(sc_core::sc_module_name name, const HwConfig& config, const OpCostTable& costs,
           const SceneDataMap& map, uint32_t record_words, uint32_t slot_capacity, uint32_t index,
           std::shared_ptr<SceneMemoryModel> scene_memory, std::shared_ptr<CycleWakeups> wakeups,
           PassSource& source)
    : sc_module(name),
      m_model(config, costs, map, record_words, slot_capacity, index, std::move(scene_memory)),
      m_clock(config.clock.core_mhz, std::move(wakeups)),
      m_source(source) {
    for (uint32_t u = 0; u < config.simd.units; ++u) {
        m_simd.push_back(std::make_unique<SimdUnit>(("simd_" + std::to_string(u)).c_str(), *this, u,
                                                    config.agu.queue_depth));
        m_fetch.push_back(
            std::make_unique<FetchUnit>(("fetch_" + std::to_string(u)).c_str(), *this, u));
    }
    m_partition = std::make_unique<PartitionUnit>("partition", *this);
    SC_THREAD(dispatch);
}

void Core::op_finished(uint64_t cycle) {
    m_last_completion = std::max(m_last_completion, cycle);
    // The dispatcher waits on this only for the pass's last op (it re-waits while ops are
    // outstanding): waking it for every op cost a delta cycle each and changed nothing.
    if (--m_outstanding == 0) m_op_event.notify(sc_core::SC_ZERO_TIME);
}

void Core::partition_done(uint32_t op, uint64_t start, uint64_t end) {
    --m_partitions_pending;
    m_partitioned[op] = 1;
    m_partition_start = start;
    m_partition_end = end;
    m_partition_event.notify(sc_core::SC_ZERO_TIME);
}

void Core::dispatch() {
    const uint32_t units = m_model.units(), width = m_model.width();
    const uint32_t prefetch = m_model.config().scene_memory.prefetch_depth;
    const uint32_t window = m_model.config().cores.op_window;
    const bool children = m_model.config().scene_memory.prefetch_children;
    uint32_t next_unit = 0;
    for (;;) {
        const std::shared_ptr<const PassBuffer> pass = m_source.next_pass();
        const uint64_t start = m_clock.now();
        m_model.begin_pass(pass.get(), start);
        m_last_completion = start;
        const uint32_t ops = uint32_t(pass->size());
        m_partitioned.assign(ops, 0);
        uint32_t next_scene = 0;
        for (uint32_t i = 0; i < ops; ++i) {
            const StreamOp op = pass->at(i);
            if (op.length == 0) continue;
            // Released once the partition that produced its stream is done (every pending one
            // when no op's did), with fewer than `window` partitions pending.
            const int32_t producer = pass->producer(i);
            auto released = [&] {
                if (m_partitions_pending >= window) return false;
                return producer < 0 ? m_partitions_pending == 0 : m_partitioned[producer] != 0;
            };
            bool waited = false;
            while (!released()) {
                wait(m_partition_event);
                waited = true;
            }
            const uint64_t now = m_clock.now();
            const uint32_t horizon = std::min(ops - 1, i + prefetch);
            for (; next_scene <= horizon; ++next_scene) m_model.request_scene(next_scene, now);
            if (children)
                for (const uint32_t* c = pass->consumers_begin(i); c != pass->consumers_end(i); ++c)
                    m_model.request_child_scene(i, *c, now);
            m_model.dispatch_op(i, now);
            ++m_outstanding;
            for (uint32_t first = 0; first < op.length; first += width) {
                GroupToken t;
                t.op = i;
                t.first = first;
                t.lanes = std::min(width, op.length - first);
                if (waited && first == 0) {
                    t.partition_start = m_partition_start;
                    t.partition_end = m_partition_end;
                }
                sc_core::sc_fifo<GroupToken>& fifo = m_fetch[next_unit]->in;
                t.dispatched = m_clock.now();
                while (!fifo.nb_write(t)) {
                    wait(fifo.data_read_event());
                    t.dispatched = m_clock.now();
                }
                next_unit = (next_unit + 1) % units;
            }
            if (m_model.profile(i).partitions) ++m_partitions_pending;
        }
        while (m_outstanding > 0) wait(m_op_event);
        const uint64_t end = std::max(m_clock.now(), m_last_completion);
        m_clock.wait_until(end);
        m_source.pass_done(m_model.end_pass(end));
    }
}

}  // namespace sfx
