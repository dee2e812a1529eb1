#include "hw_model/systemc/systemc_timing.h"

#include <atomic>
#include <map>
#include <cstdlib>
#include <stdexcept>

#include <tlm>

#include "hw_model/systemc/accelerator.h"

namespace sfx {
namespace {

std::atomic<bool> g_in_use{false};

// A fresh simulation context for each point group: the previous one is abandoned (SystemC
// 2.3 offers no reset; its memory is small and released at exit).
void new_simulation_context() {
    setenv("SC_COPYRIGHT_MESSAGE", "DISABLE", 0);
    sc_core::sc_curr_simcontext = new sc_core::sc_simcontext();
    sc_core::sc_default_global_context = sc_core::sc_curr_simcontext;
    sc_core::sc_report_handler::set_actions(sc_core::SC_INFO, sc_core::SC_DO_NOTHING);
    // Sequencers run ahead of the kernel by up to one quantum: a wait() per quantum rather
    // than per operation. Nothing else shares time with them, so the quantum never changes
    // a result, only how often the kernel switches contexts.
    tlm::tlm_global_quantum::instance().set(sc_core::sc_time(100, sc_core::SC_US));
}

}  // namespace

SystemcTiming::SystemcTiming(const std::vector<HwConfig>& configs, const WorkloadShape& shape) {
    if (g_in_use.exchange(true))
        throw std::logic_error("one SystemcTiming at a time: SystemC has one simulation context");
    try {
        new_simulation_context();
        std::map<std::string, std::shared_ptr<SharedSceneMemory>> by_config;
        for (size_t i = 0; i < configs.size(); ++i) {
            HwConfig memory_only;  // the key: the scene-memory parameters and the core clock
            memory_only.scene_memory = configs[i].scene_memory;
            memory_only.clock.core_mhz = configs[i].clock.core_mhz;
            auto& memory = by_config[dump_hw_config(memory_only)];
            if (!memory) {
                memory = std::make_shared<SharedSceneMemory>(configs[i].scene_memory,
                                                             configs[i].clock.core_mhz);
                m_memories.push_back(memory);
            }
            m_accelerators.push_back(std::make_unique<Accelerator>(
                ("accelerator_" + std::to_string(i)).c_str(), configs[i], shape, memory));
        }
        sc_core::sc_start(sc_core::SC_ZERO_TIME);  // end elaboration; threads wait for passes
    } catch (...) {
        m_accelerators.clear();
        m_memories.clear();
        g_in_use = false;
        throw;
    }
}

SystemcTiming::~SystemcTiming() {
    m_accelerators.clear();
    m_memories.clear();
    g_in_use = false;
}

void SystemcTiming::end_pass(const TilePass& p) {
    m_pass.end_pass(p);
    for (auto& m : m_memories) m->begin_pass(m_pass.size());
    for (auto& a : m_accelerators) a->start(&m_pass);
    sc_core::sc_start();  // until every sequencer waits for the next pass
}

void SystemcTiming::set_warming(bool warming) {
    for (auto& a : m_accelerators) a->set_warming(warming);
}

FrameTiming SystemcTiming::timing(size_t config) const { return m_accelerators[config]->timing(); }

}  // namespace sfx
