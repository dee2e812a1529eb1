#include "hw_model/systemc/accelerator.h"

namespace sfx {

Accelerator::Accelerator(sc_core::sc_module_name name, const HwConfig& c,
                         const WorkloadShape& shape, std::shared_ptr<SharedCacheLookups> lookups)
    : sc_module(name),
      m_config(c),
      m_costs(RayRecordLayout(shape.features), c),
      m_scene_memory(std::make_shared<SceneMemoryModel>(c.scene_memory, c.clock.core_mhz,
                                                        c.cores.count, std::move(lookups),
                                                        scene_data_map(shape).span_bytes())) {
    m_costs.check_measured(shape.needed_kinds(), c.name);
    const RayRecordLayout layout(shape.features);
    const uint32_t slots = buffer_slots(c.ray_buffer, layout.bytes(), shape.slots());
    m_map = scene_data_map(shape);
    // The cores share one clock and one table of wake-ups: their processes due in the same
    // cycle resume in an order of this accelerator's own making.
    const auto wakeups = std::make_shared<CycleWakeups>();
    for (uint32_t i = 0; i < c.cores.count; ++i)
        m_cores.push_back(std::make_unique<Core>(
            ("core_" + std::to_string(i)).c_str(), c, m_costs, m_map, layout.words(),
            slots, i, m_scene_memory, wakeups, *this));
}

void Accelerator::enqueue(std::shared_ptr<const PassBuffer> pass) {
    m_queue.push_back(std::move(pass));
    m_work.notify(sc_core::SC_ZERO_TIME);
}

std::shared_ptr<const PassBuffer> Accelerator::next_pass() {
    while (m_queue.empty()) {
        // Every core waiting: the machine is idle until its next pass comes, however long the
        // other configurations of its simulation take to finish theirs. That wait is not its
        // own time, so its scene memory leaves it out (SceneMemoryModel::pause).
        if (++m_waiting == m_cores.size()) m_idle_since = sc_core::sc_time_stamp().value();
        sc_core::wait(m_work);
        if (m_waiting-- == m_cores.size())
            m_scene_memory->pause((sc_core::sc_time_stamp().value() - m_idle_since) /
                                  clock_period(m_config.clock.core_mhz));
    }
    std::shared_ptr<const PassBuffer> p = std::move(m_queue.front());
    m_queue.pop_front();
    return p;
}

void Accelerator::pass_done(const FrameTiming& timing) {
    m_timing += timing;
}

void Accelerator::warm(const PassBuffer& pass) {
    m_cores[0]->model().warm_branches(pass);
    for (size_t i = 0; i < pass.size(); ++i) {
        const StreamOp op = pass.at(i);
        const OpProfile& p = m_costs[op.kind];
        if (p.scene_bytes && op.object != k_no_object && op.length)
            m_scene_memory->warm(0, m_map.address(op.kind, op.object), p.scene_bytes);
        // The lanes' hit-primitive reads (CoreModel::request_scene) need warming of their own
        // only from the mesh's arrays: otherwise each is a line the intersection op that found
        // the hit fetched.
        const uint32_t* hits = pass.lane_hits(i);
        if (p.lane_scene_reads && hits && m_config.scene_memory.hit_reads == "mesh")
            for (uint32_t lane = 0; lane < op.length; ++lane)
                if (hits[lane] != k_no_object)
                    warm_hit(*m_scene_memory, m_map, 0, hits[lane], true);
    }
}

FrameTiming Accelerator::timing() const {
    FrameTiming t = m_timing;
    t.cache_hits.clear();
    t.cache_misses.clear();
    for (uint32_t level = 0; level < m_scene_memory->level_count(); ++level) {
        t.cache_hits.push_back(m_scene_memory->hits(level));
        t.cache_misses.push_back(m_scene_memory->misses(level));
    }
    t.dram_reads = m_scene_memory->dram_reads();
    // ACTIONS: cache lookups and fills per level (summed over a private level's instances),
    // DRAM bytes in lines of the last level.
    for (uint32_t level = 0; level < m_scene_memory->level_count() &&
                             level < ActionCounts::k_max_cache_levels;
         ++level) {
        t.actions.cache_accesses[level] = m_scene_memory->hits(level) + m_scene_memory->misses(level);
        t.actions.cache_fills[level] = m_scene_memory->misses(level);
    }
    t.actions.dram_bytes = m_scene_memory->dram_reads() * dram_line_bytes(m_config.scene_memory);
    return t;
}

}  // namespace sfx
