#pragma once
// Stream filters (Gribble & Ramani 2008, Fig. 2 and Fig. 5): a test is evaluated over a
// stream of ray ids in groups of Width lanes, giving a mask; the stream is then partitioned in
// place, passing ids first (stable, so the order is deterministic), and the passing prefix is
// the output stream. The test may update ray state of the lanes it passes (conditional scatter).

#include <cstdint>

#include "kernels/trace.h"

namespace sfx {

// Host lanes per filter group. The functional result and the trace never depend on it: the
// trace records whole streams and a timing model chunks them at the width it models.
constexpr int k_host_width = 8;

// Evaluates `test(id)` over ids[0, n) in groups of Width lanes; writes mask[i], returns the
// number passing. The last group is partial, as in Fig. 5 (inactive lanes are not tested).
template <int Width, class Test>
inline uint32_t evaluate(const uint32_t* ids, uint32_t n, uint8_t* mask, Test&& test) {
    uint32_t passed = 0;
    uint32_t g = 0;
    for (; g + Width <= n; g += Width)
        for (int lane = 0; lane < Width; ++lane) {
            const bool b = test(ids[g + lane]);
            mask[g + lane] = uint8_t(b);
            passed += b;
        }
    for (; g < n; ++g) {
        const bool b = test(ids[g]);
        mask[g] = uint8_t(b);
        passed += b;
    }
    return passed;
}

// Stable in-place partition of ids[0, n) by mask: passing ids first. `scratch` holds n ids.
inline void partition(uint32_t* ids, uint32_t n, const uint8_t* mask, uint32_t passed,
                      uint32_t* scratch) {
    if (passed == 0 || passed == n) return;
    uint32_t front = 0, back = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t id = ids[i];
        if (mask[i]) ids[front++] = id;
        else scratch[back++] = id;
    }
    for (uint32_t i = 0; i < back; ++i) ids[front + i] = scratch[i];
}

// Trace policies: NoTrace compiles every report away; SinkTrace forwards to a TraceSink.
struct NoTrace {
    static constexpr bool k_enabled = false;
    void op(OpKind, uint16_t, uint32_t, const uint32_t*, uint32_t, const uint8_t*, uint32_t) {}
};

struct SinkTrace {
    static constexpr bool k_enabled = true;
    TraceSink* sink;
    void op(OpKind kind, uint16_t generation, uint32_t object, const uint32_t* ids, uint32_t n,
            const uint8_t* mask, uint32_t passed) {
        StreamOp o;
        o.kind = kind;
        o.stage = stage_of(kind);
        o.generation = generation;
        o.object = object;
        o.length = n;
        o.pass_count = passed;
        o.slots = ids;
        o.passed = mask;
        sink->op(o);
    }
};

// The filter of Fig. 5: evaluate, report the op (slots in input order), partition.
// Without a trace nothing needs the mask, so the test and the partition run in one pass.
template <int Width, class Trace, class Test>
inline uint32_t filter(Trace& trace, OpKind kind, uint16_t generation, uint32_t object,
                       uint32_t* ids, uint32_t n, uint8_t* mask, uint32_t* scratch, Test&& test) {
    if (n == 0) return 0;
    if constexpr (!Trace::k_enabled) {
        uint32_t front = 0, back = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t id = ids[i];
            if (test(id)) ids[front++] = id;  // front <= i: never overwrites an unread id
            else scratch[back++] = id;
        }
        if (front != 0)
            for (uint32_t i = 0; i < back; ++i) ids[front + i] = scratch[i];
        return front;
    }
    const uint32_t passed = evaluate<Width>(ids, n, mask, test);
    trace.op(kind, generation, object, ids, n, mask, passed);
    partition(ids, n, mask, passed, scratch);
    return passed;
}

}  // namespace sfx
