#pragma once
// check_same_counts: two counting sinks hold the same figures (per stage, kind and bounce),
// for tests that count one workload by two paths (counts-only and full trace, a file replay).

#include <catch2/catch.hpp>

#include "kernels/trace.h"

namespace sfx::test {

inline void check_same_counts(const CountingSink& a, const CountingSink& b) {
    CHECK(a.rays() == b.rays());
    for (const bool secondary : {false, true}) {
        CHECK(a.rays(secondary) == b.rays(secondary));
        for (uint32_t st = 0; st < k_op_stage_count; ++st) {
            INFO((secondary ? "secondary" : "primary") << " stage " << st);
            const auto& x = a.stage(secondary, OpStage(st));
            const auto& y = b.stage(secondary, OpStage(st));
            CHECK(x.ops == y.ops);
            CHECK(x.lanes == y.lanes);
            CHECK(x.passed == y.passed);
            CHECK(x.groups == y.groups);
            CHECK(x.histogram == y.histogram);
        }
        for (uint32_t k = 0; k < k_op_kind_count; ++k) {
            INFO("kind " << k);
            CHECK(a.kind_lanes(OpKind(k), secondary) == b.kind_lanes(OpKind(k), secondary));
        }
    }
    for (uint32_t k = 0; k < k_op_kind_count; ++k)
        CHECK(a.kind_ops(OpKind(k)) == b.kind_ops(OpKind(k)));
    for (uint32_t g = 0; g < CountingSink::k_bounce_slots; ++g) {
        INFO("bounce " << g);
        const CountingSink::BounceCounts x = a.bounce(g), y = b.bounce(g);
        CHECK(x.rays == y.rays);
        CHECK(x.box_ops == y.box_ops);
        CHECK(x.box_lanes == y.box_lanes);
        CHECK(x.prim_ops == y.prim_ops);
        CHECK(x.prim_lanes == y.prim_lanes);
    }
}

}  // namespace sfx::test
