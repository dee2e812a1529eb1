#include "hw_model/systemc/systemc_timing.h"

#include <atomic>
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
        // Configurations whose scene-data lookups are the same share one cache simulation.
        std::vector<std::shared_ptr<SharedCacheLookups>> lookups(configs.size());
        for (size_t i = 0; i < configs.size(); ++i)
            for (size_t j = i + 1; j < configs.size(); ++j)
                if (!configs[i].scene_memory.caches.empty() &&
                    same_cache_lookups(configs[i], configs[j])) {
                    if (!lookups[i])
                        lookups[i] =
                            std::make_shared<SharedCacheLookups>(configs[i].scene_memory.caches);
                    lookups[j] = lookups[i];
                }
        for (size_t i = 0; i < configs.size(); ++i) {
            m_accelerators.push_back(std::make_unique<Accelerator>(
                ("accelerator_" + std::to_string(i)).c_str(), configs[i], shape, lookups[i]));
            m_batch = std::max(m_batch, configs[i].cores.count);
        }
        sc_core::sc_start(sc_core::SC_ZERO_TIME);  // end elaboration; processes wait for passes
    } catch (...) {
        m_accelerators.clear();
        g_in_use = false;
        throw;
    }
}

SystemcTiming::~SystemcTiming() {
    m_accelerators.clear();
    g_in_use = false;
}

void SystemcTiming::begin_pass(const TilePass& p) {
    m_pass = std::make_shared<PassBuffer>();
    m_pass->begin_pass(p);
}

void SystemcTiming::end_pass(const TilePass& p) {
    m_pass->end_pass(p);
    if (m_warming) {
        for (auto& a : m_accelerators) a->warm(*m_pass);
        return;
    }
    m_held.push_back(std::move(m_pass));
    if (m_held.size() >= m_batch) flush();
}

void SystemcTiming::flush() {
    if (m_held.empty()) return;
    for (auto& a : m_accelerators)
        for (const auto& pass : m_held) a->enqueue(pass);
    m_held.clear();
    sc_core::sc_start();  // until every core waits for its next pass
}

void SystemcTiming::set_warming(bool warming) {
    flush();  // warming passes follow the timed ones they come after
    m_warming = warming;
}

FrameTiming SystemcTiming::timing(size_t config) {
    flush();
    return m_accelerators[config]->timing();
}

}  // namespace sfx
