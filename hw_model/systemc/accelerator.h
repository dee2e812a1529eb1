#pragma once
// One accelerator: the units of Sec. 3.3 for one hardware configuration, wired to a sequencer.
// Only the function units the scene needs are elaborated.

#include <memory>

#include "hw_model/systemc/address_unit.h"
#include "hw_model/systemc/interconnect_unit.h"
#include "hw_model/systemc/partition_unit.h"
#include "hw_model/systemc/ray_buffer_unit.h"
#include "hw_model/systemc/scene_memory_unit.h"
#include "hw_model/systemc/scratchpad_unit.h"
#include "hw_model/systemc/sequencer.h"
#include "hw_model/systemc/simd_unit.h"
#include "hw_model/workload_shape.h"

namespace sfx {

class Accelerator : public sc_core::sc_module {
public:
    Accelerator(sc_core::sc_module_name name, const HwConfig& config, const WorkloadShape& shape,
                std::shared_ptr<SharedSceneMemory> scene_memory);

    void start(const PassBuffer* pass) { m_sequencer->start(pass); }
    void set_warming(bool warming) { m_sequencer->set_warming(warming); }
    // The frame so far, with the scene-cache counters filled in.
    FrameTiming timing() const;
    const SimdUnit& simd() const { return *m_simd; }

private:
    std::unique_ptr<RayBufferUnit> m_ray_buffer;
    std::unique_ptr<AddressUnit> m_address;
    std::unique_ptr<SimdUnit> m_simd;
    std::unique_ptr<PartitionUnit> m_partition;
    std::unique_ptr<ScratchpadUnit> m_scratchpad;
    std::unique_ptr<InterconnectUnit> m_interconnect;
    std::unique_ptr<SceneMemoryUnit> m_scene_memory;
    std::unique_ptr<Sequencer> m_sequencer;
};

}  // namespace sfx
