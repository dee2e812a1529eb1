#pragma once
// Plain SystemC interfaces between the sequencer and the units. Calls are blocking and
// loosely timed: each returns the cycles its work takes and the caller annotates them
// (STYLE: annotate time, don't tick it).

#include <systemc>

#include "hw_model/prediction.h"
#include "hw_model/ray_buffer_model.h"

namespace sfx {

struct RayBufferIf : virtual sc_core::sc_interface {
    // `words` field words for a group of lanes, one after another (gathers or scatters).
    virtual RayBufferModel::Access access_fields(uint32_t words, const uint32_t* slots,
                                                 uint32_t lanes) = 0;
    // A run of the id stream.
    virtual RayBufferModel::Contiguous access_ids(uint64_t offset, uint32_t lanes) = 0;
    virtual uint32_t fill_cycles() const = 0;
};

struct AddressIf : virtual sc_core::sc_interface {
    virtual uint64_t generate(uint64_t addresses) = 0;  // cycles for that many addresses
};

struct SimdIf : virtual sc_core::sc_interface {
    // Issue cycles of `instructions` per group over `groups` groups of kind `kind`.
    virtual uint64_t execute(OpKind kind, uint64_t groups, uint32_t instructions) = 0;
    virtual bool supports(OpKind kind) const = 0;
};

struct PartitionIf : virtual sc_core::sc_interface {
    virtual PartitionCost partition(uint32_t length, uint32_t moved_ids) = 0;
};

struct ScratchpadIf : virtual sc_core::sc_interface {
    virtual uint64_t access(uint64_t words) = 0;  // cycles to move that many words
};

struct InterconnectIf : virtual sc_core::sc_interface {
    // Stall cycles when `words` must cross in `available_cycles` core cycles.
    virtual uint64_t transfer(uint64_t words, uint64_t available_cycles) = 0;
    // Core cycles for data to cross the multiplexer levels once (paid once per operation).
    virtual uint32_t crossing_cycles() const = 0;
};

struct SceneMemoryIf : virtual sc_core::sc_interface {
    // Cycles until the data of operation `op` of the current pass arrives.
    virtual uint64_t read(size_t op, uint64_t address, uint32_t bytes) = 0;
};

}  // namespace sfx
