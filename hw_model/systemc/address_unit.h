#pragma once
// Address-generation units: compute gather/scatter addresses beside the data path.

#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class AddressUnit : public sc_core::sc_module, public AddressIf {
public:
    AddressUnit(sc_core::sc_module_name name, const AguConfig& config)
        : sc_module(name), m_config(config) {}
    uint64_t generate(uint64_t addresses) override { return address_cycles(m_config, addresses); }

private:
    AguConfig m_config;
};

}  // namespace sfx
