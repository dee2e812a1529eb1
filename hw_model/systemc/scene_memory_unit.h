#pragma once
// Scene-data memory: the cache hierarchy and DRAM of SceneMemoryModel.

#include "hw_model/cache_model.h"
#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class SceneMemoryUnit : public sc_core::sc_module, public SceneMemoryIf {
public:
    SceneMemoryUnit(sc_core::sc_module_name name, const SceneMemoryConfig& config, double core_mhz)
        : sc_module(name), m_model(config, core_mhz) {}
    uint64_t read(uint64_t address, uint32_t bytes) override { return m_model.read(address, bytes); }
    const SceneMemoryModel& model() const { return m_model; }

private:
    SceneMemoryModel m_model;
};

}  // namespace sfx
