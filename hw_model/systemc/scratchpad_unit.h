#pragma once
// The scratchpad for intermediate results (filter masks, shading temporaries): `ports`
// words per cycle.

#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class ScratchpadUnit : public sc_core::sc_module, public ScratchpadIf {
public:
    ScratchpadUnit(sc_core::sc_module_name name, const ScratchpadConfig& config)
        : sc_module(name), m_ports(config.ports) {}
    uint64_t access(uint64_t words) override { return (words + m_ports - 1) / m_ports; }

private:
    uint32_t m_ports;
};

}  // namespace sfx
