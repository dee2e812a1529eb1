#pragma once
// The N-wide SIMD execution unit: one function unit per kind of operation the scene needs
// (a triangle-only scene elaborates no sphere unit). Pipelined: one group issues per cycle
// per instruction; the datapath latency is paid once per operation by the sequencer.

#include <array>
#include <memory>
#include <string>

#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class FunctionUnit : public sc_core::sc_module {
public:
    explicit FunctionUnit(sc_core::sc_module_name name) : sc_module(name) {}
    uint64_t issued = 0;  // instructions issued
};

class SimdUnit : public sc_core::sc_module, public SimdIf {
public:
    SimdUnit(sc_core::sc_module_name name, const std::array<bool, k_op_kind_count>& needed)
        : sc_module(name) {
        for (uint32_t k = 0; k < k_op_kind_count; ++k)
            if (needed[k])
                m_units[k] = std::make_unique<FunctionUnit>(
                    (std::string(to_string(OpKind(k))) + "_unit").c_str());
    }
    uint64_t execute(OpKind kind, uint64_t groups, uint32_t instructions) override {
        FunctionUnit* unit = m_units[size_t(kind)].get();
        if (!unit) throw std::logic_error(std::string("no function unit for ") + to_string(kind));
        const uint64_t cycles = groups * instructions;
        unit->issued += cycles;
        return cycles;
    }
    bool supports(OpKind kind) const override { return m_units[size_t(kind)] != nullptr; }
    uint32_t unit_count() const {
        uint32_t n = 0;
        for (const auto& u : m_units) n += u ? 1 : 0;
        return n;
    }

private:
    std::array<std::unique_ptr<FunctionUnit>, k_op_kind_count> m_units;
};

}  // namespace sfx
