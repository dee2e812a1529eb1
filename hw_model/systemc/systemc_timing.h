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

#include <memory>
#include <vector>

#include "hw_model/hw_config.h"
#include "hw_model/pass_buffer.h"
#include "hw_model/prediction.h"
#include "hw_model/workload_shape.h"

namespace sfx {

class Accelerator;
class SharedSceneMemory;

class SystemcTiming : public TraceSink {
public:
    SystemcTiming(const std::vector<HwConfig>& configs, const WorkloadShape& shape);
    ~SystemcTiming() override;
    SystemcTiming(const SystemcTiming&) = delete;
    SystemcTiming& operator=(const SystemcTiming&) = delete;

    void begin_pass(const TilePass& p) override { m_pass.begin_pass(p); }
    void op(const StreamOp& op) override { m_pass.op(op); }
    void end_pass(const TilePass& p) override;

    // While warming, passes only warm the scene-data caches; no time is counted.
    void set_warming(bool warming);

    size_t configs() const { return m_accelerators.size(); }
    FrameTiming timing(size_t config) const;
    const Accelerator& accelerator(size_t config) const { return *m_accelerators[config]; }

private:
    PassBuffer m_pass;
    std::vector<std::shared_ptr<SharedSceneMemory>> m_memories;  // one per distinct memory config
    std::vector<std::unique_ptr<Accelerator>> m_accelerators;
};

}  // namespace sfx
