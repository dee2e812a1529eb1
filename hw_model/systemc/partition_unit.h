#pragma once
// The partition unit: SIMD comparators form the mask's active and inactive partitions in place.

#include "hw_model/systemc/unit_interfaces.h"

namespace sfx {

class PartitionUnit : public sc_core::sc_module, public PartitionIf {
public:
    PartitionUnit(sc_core::sc_module_name name, const PartitionConfig& config, uint32_t width)
        : sc_module(name), m_config(config), m_width(width) {}
    PartitionCost partition(uint32_t length, uint32_t moved_ids) override {
        return partition_cost(m_config, m_width, length, moved_ids);
    }

private:
    PartitionConfig m_config;
    uint32_t m_width;
};

}  // namespace sfx
