#pragma once
// The sequencer replays a tile pass of the trace on one accelerator. Each stream operation
// becomes: id-stream reads, gathers of the ray words the op reads (slot -> bank), compute over
// ceil(len / width) lane groups, conditional scatters of the words it writes, address
// generation beside all of that, the scene-data fetch of the op's node/primitive/material,
// the mask's in-place partition, and the interconnect traffic. Cycles are integers counted
// here; simulated time is annotated through a quantum keeper, so no process wakes per clock.

#include <systemc>
#include <tlm>
#include <tlm_utils/tlm_quantumkeeper.h>

#include "hw_model/op_costs.h"
#include "hw_model/pass_buffer.h"
#include "hw_model/prediction.h"
#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class Sequencer : public sc_core::sc_module {
public:
    sc_core::sc_port<RayBufferIf> ray_buffer;
    sc_core::sc_port<AddressIf> address;
    sc_core::sc_port<SimdIf> simd;
    sc_core::sc_port<PartitionIf> partition;
    sc_core::sc_port<ScratchpadIf> scratchpad;
    sc_core::sc_port<InterconnectIf> interconnect;
    sc_core::sc_port<SceneMemoryIf> scene_memory;

    SC_HAS_PROCESS(Sequencer);
    Sequencer(sc_core::sc_module_name name, const OpCostTable& costs, const SceneDataMap& map,
              uint32_t width, double core_mhz);

    // Starts replaying `pass` at the next delta cycle; the pass must outlive the simulation
    // run (sc_start returns when every sequencer is idle again).
    void start(const PassBuffer* pass);
    // Warming: passes only feed the scene-data caches (their fetches, in order) and count no
    // time, so a sampled pass starts with the caches the full frame would have left.
    void set_warming(bool warming) { m_warming = warming; }
    const FrameTiming& timing() const { return m_timing; }

private:
    void run();
    uint64_t time_op(size_t index, const StreamOp& op, FrameTiming& t);

    OpCostTable m_costs;
    SceneDataMap m_map;
    uint32_t m_width;
    sc_core::sc_time m_period;
    const PassBuffer* m_pass = nullptr;
    bool m_warming = false;
    sc_core::sc_event m_start;
    tlm_utils::tlm_quantumkeeper m_keeper;
    FrameTiming m_timing;
    std::vector<uint32_t> m_scratch_slots;
};

}  // namespace sfx
