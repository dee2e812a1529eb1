#pragma once
// One tile pass of the trace held in memory, so that every hardware configuration of a point
// group replays the same pass (trace once, time many). Memory: one pass, never a frame.

#include <cstdint>
#include <unordered_map>
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
        m_producer.clear();
        m_streams.clear();
        m_consumers.clear();
        m_consumer_start.clear();
        m_hit.assign(p.slot_count, k_no_object);
        m_lane_hits.clear();
        m_lane_hit_offset.clear();
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
        // The op whose partition produced this stream: the latest one whose passing ids, in
        // order, are this op's ids (a child's stream is its parent's passing prefix).
        const auto producer = m_streams.find(stream_key(op.slots, op.passed, op.length, false));
        m_producer.push_back(producer == m_streams.end() ? -1 : int32_t(producer->second));
        if (op_info(op.kind).partitions && op.length > 0)  // an empty op is never dispatched
            m_streams[stream_key(op.slots, op.passed, op.length, true)] =
                uint32_t(m_ops.size() - 1);
        // Each slot's hit so far: an intersection op's passing lanes took a closer hit; a
        // pushed ray (the slot's next generation) has none yet.
        const bool hits = op.kind == OpKind::triangle_test || op.kind == OpKind::sphere_test;
        if (hits || op_info(op.kind).pushes_rays)
            for (uint32_t i = 0; i < op.length; ++i)
                if (op.passed[i] && op.slots[i] < m_hit.size())
                    m_hit[op.slots[i]] = hits ? op.object : k_no_object;
        m_lane_hit_offset.push_back(k_no_lane_hits);
        if (op_info(op.kind).reads_hit_primitive) {
            m_lane_hit_offset.back() = m_lane_hits.size();
            for (uint32_t i = 0; i < op.length; ++i)
                m_lane_hits.push_back(op.slots[i] < m_hit.size() ? m_hit[op.slots[i]]
                                                                 : k_no_object);
        }
    }
    void end_pass(const TilePass& p) override {
        m_pass = p;
        // The consumers of each op, grouped by producer (counting sort: in op order).
        m_consumer_start.assign(m_ops.size() + 1, 0);
        for (const int32_t producer : m_producer)
            if (producer >= 0) ++m_consumer_start[size_t(producer) + 1];
        for (size_t i = 0; i < m_ops.size(); ++i) m_consumer_start[i + 1] += m_consumer_start[i];
        m_consumers.resize(m_consumer_start.back());
        std::vector<uint32_t> next(m_consumer_start.begin(), m_consumer_start.end() - 1);
        for (size_t i = 0; i < m_producer.size(); ++i)
            if (m_producer[i] >= 0) m_consumers[next[size_t(m_producer[i])]++] = uint32_t(i);
    }

    const TilePass& pass() const { return m_pass; }
    // Ids a stable partition of op i moves: the same for every configuration.
    uint32_t moved_ids(size_t i) const { return m_moved[i]; }
    // The earlier op whose partition produced op i's stream, or -1 when none did (then op i is
    // taken to depend on every earlier partition). The same for every configuration.
    int32_t producer(size_t i) const { return m_producer[i]; }
    // The ops whose producer op i is, in order (after end_pass).
    const uint32_t* consumers_begin(size_t i) const {
        return m_consumers.data() + m_consumer_start[i];
    }
    const uint32_t* consumers_end(size_t i) const {
        return m_consumers.data() + m_consumer_start[i + 1];
    }
    // For an op that reads each lane's hit primitive (OpKindInfo::reads_hit_primitive): the
    // primitive each lane's ray had hit when the op ran (k_no_object: none), in stream order;
    // nullptr for other ops. The trace carries it implicitly: the last intersection op a slot
    // passed in is its hit.
    const uint32_t* lane_hits(size_t i) const {
        return m_lane_hit_offset[i] == k_no_lane_hits ? nullptr
                                                      : m_lane_hits.data() + m_lane_hit_offset[i];
    }
    size_t size() const { return m_ops.size(); }
    // The op with its views pointing into this buffer.
    StreamOp at(size_t i) const {
        StreamOp op = m_ops[i];
        op.slots = m_slots.data() + m_offsets[i];
        op.passed = m_passed.data() + m_offsets[i];
        return op;
    }

private:
    // A hash of a stream: every id (`passing_only`: only the passing ones), in order.
    static uint64_t stream_key(const uint32_t* slots, const uint8_t* passed, uint32_t length,
                               bool passing_only) {
        uint64_t h = 0x9e3779b97f4a7c15ull, n = 0;
        for (uint32_t i = 0; i < length; ++i) {
            if (passing_only && !passed[i]) continue;
            h = (h ^ slots[i]) * 0x100000001b3ull;
            h ^= h >> 29;
            ++n;
        }
        return h ^ (n * 0xbf58476d1ce4e5b9ull);
    }

    TilePass m_pass;
    std::vector<StreamOp> m_ops;
    std::vector<size_t> m_offsets;
    std::vector<uint32_t> m_slots;
    std::vector<uint8_t> m_passed;
    std::vector<uint32_t> m_moved;
    std::vector<int32_t> m_producer;
    std::vector<uint32_t> m_consumers, m_consumer_start;
    std::unordered_map<uint64_t, uint32_t> m_streams;  // passing-stream key -> latest op
    static constexpr size_t k_no_lane_hits = ~size_t(0);
    std::vector<uint32_t> m_hit;        // per slot: the primitive its ray hit so far
    std::vector<uint32_t> m_lane_hits;  // lane_hits() of the ops that read them, concatenated
    std::vector<size_t> m_lane_hit_offset;  // per op: into m_lane_hits, or k_no_lane_hits
};

}  // namespace sfx
