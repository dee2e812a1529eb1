#pragma once
// The banked ray buffers (current and next generation) with one address generator per bank.
// Conflict arithmetic lives in RayBufferModel; this module owns it and counts.

#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class RayBufferUnit : public sc_core::sc_module, public RayBufferIf {
public:
    RayBufferUnit(sc_core::sc_module_name name, const RayBufferConfig& config,
                  uint32_t record_words, uint32_t capacity)
        : sc_module(name), m_model(config, record_words, capacity) {}

    RayBufferModel::Access access_fields(uint32_t words, const uint32_t* slots,
                                         uint32_t lanes) override {
        return m_model.access_fields(words, slots, lanes);
    }
    RayBufferModel::Contiguous access_ids(uint64_t offset, uint32_t lanes) override {
        return m_model.access_contiguous(offset, lanes);
    }
    uint32_t fill_cycles() const override { return m_model.fill_cycles(); }

private:
    RayBufferModel m_model;
};

}  // namespace sfx
