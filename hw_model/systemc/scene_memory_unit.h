#pragma once
// Scene-data memory: the cache hierarchy and DRAM of SceneMemoryModel.
//
// Accelerators whose scene-memory configurations are equal see the same sequence of fetches
// (the trace fixes it), so they share one SharedSceneMemory: the first accelerator to reach an
// operation simulates its fetch and records the latency, the others read it. Every
// accelerator reaches the operations in order, so the caches still see the accesses in order.

#include <limits>
#include <memory>
#include <vector>

#include "hw_model/cache_model.h"
#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class SharedSceneMemory {
public:
    SharedSceneMemory(const SceneMemoryConfig& config, double core_mhz) : m_model(config, core_mhz) {}
    void begin_pass(size_t ops) { m_latency.assign(ops, k_unknown); }
    uint64_t read(size_t op, uint64_t address, uint32_t bytes) {
        if (m_latency[op] == k_unknown) m_latency[op] = m_model.read(address, bytes);
        return m_latency[op];
    }
    const SceneMemoryModel& model() const { return m_model; }

private:
    static constexpr uint64_t k_unknown = std::numeric_limits<uint64_t>::max();
    SceneMemoryModel m_model;
    std::vector<uint64_t> m_latency;  // per operation of the current pass
};

class SceneMemoryUnit : public sc_core::sc_module, public SceneMemoryIf {
public:
    SceneMemoryUnit(sc_core::sc_module_name name, std::shared_ptr<SharedSceneMemory> memory)
        : sc_module(name), m_memory(std::move(memory)) {}
    uint64_t read(size_t op, uint64_t address, uint32_t bytes) override {
        return m_memory->read(op, address, bytes);
    }
    const SceneMemoryModel& model() const { return m_memory->model(); }

private:
    std::shared_ptr<SharedSceneMemory> m_memory;
};

}  // namespace sfx
