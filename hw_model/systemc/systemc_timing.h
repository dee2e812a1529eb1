#pragma once
// Cycle-level timing of a trace on SystemC accelerators: a TraceSink that holds one tile pass
// and replays it on every configuration of a point group in one simulation.
//
// SystemC elaborates once per simulation context and cannot add modules afterwards. A point
// group (one scene, tile, resolution, spp) therefore elaborates one accelerator per hardware
// configuration side by side, all fed by the same pass: the functional render is paid once,
// and one kernel run per pass advances every accelerator (bench/hw_model_bench measures the
// cost of each extra configuration). Each SystemcTiming starts a fresh simulation context, so
// a process can time one point group after another; only one may exist at a time.
//
// Cores: passes are held until there are as many as the largest configuration has cores, then
// queued to every accelerator at once and simulated together, so that the cores of a
// configuration run side by side and contend for the shared scene memory. Reading a timing
// runs what is held first.

#include <memory>
#include <vector>

#include "hw_model/hw_config.h"
#include "hw_model/pass_buffer.h"
#include "hw_model/prediction.h"
#include "hw_model/workload_shape.h"

namespace sfx {

class Accelerator;

class SystemcTiming : public TraceSink {
  public:
    SystemcTiming(const std::vector<HwConfig>& configs, const WorkloadShape& shape);
    ~SystemcTiming() override;
    SystemcTiming(const SystemcTiming&) = delete;
    SystemcTiming& operator=(const SystemcTiming&) = delete;

    void begin_pass(const TilePass& p) override;
    void op(const StreamOp& op) override { m_pass->op(op); }
    void end_pass(const TilePass& p) override;
    void end_frame() override { flush(); }

    // While warming, passes only warm the scene-data caches; no time is counted.
    void set_warming(bool warming);

    size_t configs() const { return m_accelerators.size(); }
    // The frame so far on configuration `config` (runs the passes held back first).
    FrameTiming timing(size_t config);
    const Accelerator& accelerator(size_t config) const { return *m_accelerators[config]; }
    // Simulates every pass held back.
    void flush();

  private:
    std::shared_ptr<PassBuffer> m_pass;
    std::vector<std::shared_ptr<const PassBuffer>> m_held;
    uint32_t m_batch = 1;  // the most cores of any configuration
    bool m_warming = false;
    std::vector<std::unique_ptr<Accelerator>> m_accelerators;
};

}  // namespace sfx
