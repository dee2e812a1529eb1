#pragma once
// One hardware configuration: `cores.count` cores (each with its own ray buffers, address
// units, SIMD units and partition unit) sharing the scene-data memory's shared levels and its
// DRAM bandwidth. Passes queue here; an idle core takes the next one (tiles are scheduled
// across cores in order). Only the cores' processes run; nothing ticks.

#include <deque>
#include <memory>
#include <vector>

#include "hw_model/systemc/units.h"
#include "hw_model/workload_shape.h"

namespace sfx {

class Accelerator : public sc_core::sc_module, public PassSource {
  public:
    // `lookups`: the scene-data cache lookups it shares with other configurations (else null).
    Accelerator(sc_core::sc_module_name name, const HwConfig& config, const WorkloadShape& shape,
                std::shared_ptr<SharedCacheLookups> lookups = nullptr);

    // Queues a pass for the next idle core (runs when the simulation does).
    void enqueue(std::shared_ptr<const PassBuffer> pass);
    // Warming: the pass's scene data only passes through the caches, its branches through the
    // first core's branch predictor; no time is counted.
    void warm(const PassBuffer& pass);
    // The frame so far (every finished pass), with the scene-cache counters filled in.
    FrameTiming timing() const;
    const HwConfig& config() const { return m_config; }
    uint32_t core_count() const { return uint32_t(m_cores.size()); }

    std::shared_ptr<const PassBuffer> next_pass() override;
    void pass_done(const FrameTiming& timing) override;

  private:
    HwConfig m_config;
    OpCostTable m_costs;
    SceneDataMap m_map;
    std::shared_ptr<SceneMemoryModel> m_scene_memory;
    std::vector<std::unique_ptr<Core>> m_cores;
    std::deque<std::shared_ptr<const PassBuffer>> m_queue;
    sc_core::sc_event m_work;
    FrameTiming m_timing;
    // Every core waiting for a pass: since when (time resolution units), and how many wait.
    uint64_t m_idle_since = 0;
    uint32_t m_waiting = 0;
};

}  // namespace sfx
