#pragma once
// Stream filters (Gribble & Ramani 2008, Fig. 2 and Fig. 5): a test is evaluated over a
// stream of ray ids, giving a mask; the stream is then partitioned in
// place, passing ids first (stable, so the order is deterministic), and the passing prefix is
// the output stream. The test may update ray state of the lanes it passes (conditional scatter).

#include <cstdint>

#include "kernels/stream/stream_kernels.h"
#include "kernels/trace.h"

namespace sfx {

// Evaluates `test(id)` over ids[0, n) in stream order; writes mask[i], returns the number
// passing. The tests of the shading stack are per-ray programs (sampling, shading), so they
// run one lane at a time; the partition after them is the back end's compress.
template <class Test>
inline uint32_t evaluate(const uint32_t* ids, uint32_t n, uint8_t* mask, Test&& test) {
    uint32_t passed = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const bool b = test(ids[i]);
        mask[i] = uint8_t(b);
        passed += b;
    }
    return passed;
}

// Trace policies: NoTrace compiles every report away; SinkTrace forwards to a TraceSink
// every op with its slots and pass flags; CountTrace forwards ops without them, for a sink
// that reads counts only (TraceSink::counts_only, the counting sink), so the filters need no mask.
struct NoTrace {
    static constexpr bool k_enabled = false;
    static constexpr bool k_lanes = false;
    void op(OpKind, uint16_t, uint32_t, const uint32_t*, uint32_t, const uint8_t*, uint32_t) {}
};

template <bool Lanes>
struct SinkTraceOf {
    static constexpr bool k_enabled = true;
    static constexpr bool k_lanes = Lanes;
    TraceSink* sink;
    void op(OpKind kind, uint16_t generation, uint32_t object, const uint32_t* ids, uint32_t n,
            const uint8_t* mask, uint32_t passed) {
        if constexpr (!Lanes) ids = nullptr, mask = nullptr;
        sink->op(StreamOp{kind, stage_of(kind), generation, object, n, passed, ids, mask});
    }
};
using SinkTrace = SinkTraceOf<true>;
using CountTrace = SinkTraceOf<false>;

// The filter of Fig. 5: evaluate, report the op (slots in input order), partition by the
// back end's compress. When the trace takes no lanes nothing needs the mask, so the test and
// the partition run in one pass. ids, mask and scratch have k_stream_padding elements of room
// past n.
template <class Trace, class Test>
inline uint32_t filter(const StreamKernels& kernels, Trace& trace, OpKind kind, uint16_t generation,
                       uint32_t object, uint32_t* ids, uint32_t n, uint8_t* mask, uint32_t* scratch,
                       Test&& test) {
    if (n == 0) return 0;
    if constexpr (!Trace::k_lanes) {
        uint32_t front = 0, back = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t id = ids[i];
            if (test(id))
                ids[front++] = id;  // front <= i: never overwrites an unread id
            else
                scratch[back++] = id;
        }
        if (front != 0)
            for (uint32_t i = 0; i < back; ++i) ids[front + i] = scratch[i];
        trace.op(kind, generation, object, ids, n, nullptr, front);
        return front;
    }
    const uint32_t passed = evaluate(ids, n, mask, test);
    trace.op(kind, generation, object, ids, n, mask, passed);
    if (passed != 0 && passed != n) kernels.partition(ids, n, mask, scratch);
    return passed;
}

}  // namespace sfx
