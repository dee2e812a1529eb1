#pragma once
// The hierarchical interconnect of multiplexers and pipeline registers between the buffers,
// the address units and the SIMD unit. It moves width_words per interconnect cycle; when
// contention is modelled, address and data words share it.

#include <cmath>

#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class InterconnectUnit : public sc_core::sc_module, public InterconnectIf {
public:
    InterconnectUnit(sc_core::sc_module_name name, const InterconnectConfig& config,
                     const ClockConfig& clock)
        : sc_module(name), m_config(config),
          m_words_per_core_cycle(double(config.width_words) * clock.interconnect_mhz / clock.core_mhz),
          // One pipeline register per level, clocked at the interconnect clock.
          m_crossing(uint32_t(std::ceil(config.mux_levels * clock.core_mhz / clock.interconnect_mhz))) {}
    uint64_t transfer(uint64_t words, uint64_t available_cycles) override {
        if (!m_config.contention) return 0;
        const uint64_t needed = uint64_t(std::ceil(double(words) / m_words_per_core_cycle));
        return needed > available_cycles ? needed - available_cycles : 0;
    }
    uint32_t crossing_cycles() const override { return m_crossing; }

private:
    InterconnectConfig m_config;
    double m_words_per_core_cycle;
    uint32_t m_crossing;
};

}  // namespace sfx
