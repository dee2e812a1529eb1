#pragma once
// One tile pass of the trace held in memory, so that every hardware configuration of a point
// group replays the same pass (trace once, time many). Memory: one pass, never a frame.

#include <cstdint>
#include <vector>

#include "hw_model/ray_buffer_model.h"
#include "kernels/trace.h"

namespace sfx {

class PassBuffer : public TraceSink {
public:
    void begin_pass(const TilePass& p) override {
        m_pass = p;
        m_ops.clear();
        m_offsets.clear();
        m_moved.clear();
        m_slots.clear();
        m_passed.clear();
    }
    void op(const StreamOp& op) override {
        StreamOp copy = op;
        copy.slots = nullptr;
        copy.passed = nullptr;
        m_offsets.push_back(m_slots.size());
        m_ops.push_back(copy);
        m_slots.insert(m_slots.end(), op.slots, op.slots + op.length);
        m_passed.insert(m_passed.end(), op.passed, op.passed + op.length);
        m_moved.push_back(stable_partition_moves(op.passed, op.length));
    }
    void end_pass(const TilePass& p) override { m_pass = p; }

    const TilePass& pass() const { return m_pass; }
    // Ids a stable partition of op i moves: the same for every configuration.
    uint32_t moved_ids(size_t i) const { return m_moved[i]; }
    size_t size() const { return m_ops.size(); }
    // The op with its views pointing into this buffer.
    StreamOp at(size_t i) const {
        StreamOp op = m_ops[i];
        op.slots = m_slots.data() + m_offsets[i];
        op.passed = m_passed.data() + m_offsets[i];
        return op;
    }

private:
    TilePass m_pass;
    std::vector<StreamOp> m_ops;
    std::vector<size_t> m_offsets;
    std::vector<uint32_t> m_slots;
    std::vector<uint8_t> m_passed;
    std::vector<uint32_t> m_moved;
};

}  // namespace sfx
