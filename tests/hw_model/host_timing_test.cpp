// The host timing: the cost formula, its fit, scene-data latency through the host's caches, and
// the host configuration's knobs (storage l1d, partition by compress, op_costs).

#include "hw_model/host_timing.h"

#include <catch2/catch.hpp>

#include "hw_model/host_description.h"
#include "base/input_error.h"

using namespace sfx;

namespace {

OpCostConfig cost(const char* op, double per_op, double group, double lane, double pass,
                  double beyond) {
    OpCostConfig c;
    c.op = op;
    c.per_op_cycles = per_op;
    c.per_group_cycles = group;
    c.per_lane_cycles = lane;
    c.per_pass_cycles = pass;
    c.beyond_l1_per_lane_cycles = beyond;
    return c;
}

HostDescription small_host() {
    HostDescription h;
    h.simd_width = 16;
    h.isa = "avx512 (16 lanes)";
    h.tsc_mhz = 1000.0;  // 1 cycle per ns
    h.caches = {{1, "data", 32, 64, 8, false, "test"}, {2, "unified", 256, 64, 8, false, "test"}};
    h.latency_ns = {1.0, 5.0, 81.0};
    return h;
}

}  // namespace

TEST_CASE("An op's host cost is the formula of its kind", "[host_timing]") {
    const OpCostConfig c = cost("box_test", 10, 4, 0.5, 2, 8);
    // 40 lanes: 3 groups of 16; 10 pass; half the buffer beyond the L1D.
    CHECK(host_op_cycles(c, 16, 40, 10, 0.5) == Approx(10 + 12 + 20 + 20 + 160));
    CHECK(host_op_cycles(c, 8, 40, 10, 0.0) == Approx(10 + 20 + 20 + 20));
    CHECK(beyond_l1_fraction(256, 64, 32) == 0.0);   // 16 KiB in 32 KiB
    CHECK(beyond_l1_fraction(1024, 64, 32) == 0.5);  // 64 KiB
    CHECK(beyond_l1_fraction(0, 64, 32) == 0.0);

    // A one-lane op runs in the one-ray loop: its own measured cost, when there is one.
    OpCostConfig one = c;
    CHECK(host_op_cycles(one, 16, 1, 1, 0.5) == Approx(10 + 4 + 0.5 + 2 + 4));
    one.one_lane_cycles = 7;
    CHECK(host_op_cycles(one, 16, 1, 1, 0.5) == Approx(7));
    CHECK(host_op_cycles(one, 16, 1, 0, 0.0) == Approx(7));
    CHECK(host_op_cycles(one, 16, 2, 1, 0.0) == Approx(10 + 4 + 1 + 2));
}

TEST_CASE("The fit recovers costs from exact samples and never goes negative", "[host_timing]") {
    const OpCostConfig truth = cost("triangle_test", 30, 12, 0, 40, 3);
    std::vector<OpCostSample> samples;
    for (uint32_t lanes : {1u, 7u, 16u, 33u, 100u, 512u, 4096u})
        for (double beyond : {0.0, 0.75})
            for (uint32_t passed : {0u, lanes / 3})
                samples.push_back(
                    {lanes, passed, beyond, host_op_cycles(truth, 16, lanes, passed, beyond)});
    const OpCostConfig fit = fit_op_cost("triangle_test", 16, samples);
    CHECK(fit.per_op_cycles == Approx(30).epsilon(1e-6));
    CHECK(fit.per_group_cycles == Approx(12).epsilon(1e-6));
    CHECK(fit.per_lane_cycles == Approx(0).margin(1e-6));
    CHECK(fit.per_pass_cycles == Approx(40).epsilon(1e-6));
    CHECK(fit.beyond_l1_per_lane_cycles == Approx(3).epsilon(1e-6));
    CHECK(fit_error(fit, 16, samples).second < 1e-9);

    // Cycles that fall with length cannot be fitted by non-negative costs: the fit clamps.
    std::vector<OpCostSample> falling = {{1, 0, 0, 100}, {16, 0, 0, 50}, {256, 0, 0, 10}};
    const OpCostConfig f = fit_op_cost("miss_filter", 16, falling);
    for (double v : {f.per_op_cycles, f.per_group_cycles, f.per_lane_cycles, f.per_pass_cycles,
                     f.beyond_l1_per_lane_cycles})
        CHECK(v >= 0.0);
    CHECK_THROWS_AS(fit_op_cost("box_test", 16, {}), std::invalid_argument);
}

TEST_CASE("The one-lane fit recovers each kind's cost from traversals that mix them",
          "[host_timing]") {
    auto sample = [](uint64_t boxes, uint64_t triangles, uint64_t spheres, double cycles) {
        OneLaneSample s;
        s.ops[size_t(OpKind::box_test)] = boxes;
        s.ops[size_t(OpKind::triangle_test)] = triangles;
        s.ops[size_t(OpKind::sphere_test)] = spheres;
        s.cycles = cycles;
        return s;
    };
    std::vector<OneLaneSample> samples;
    for (uint64_t b : {7u, 23u, 130u})
        for (uint64_t t : {0u, 2u, 12u})
            for (uint64_t s : {0u, 1u, 5u})
                samples.push_back(sample(b, t, s, 30.0 * b + 90.0 * t + 40.0 * s));
    const auto fit = fit_one_lane_cycles(samples);
    CHECK(fit[size_t(OpKind::box_test)] == Approx(30).epsilon(1e-6));
    CHECK(fit[size_t(OpKind::triangle_test)] == Approx(90).epsilon(1e-6));
    CHECK(fit[size_t(OpKind::sphere_test)] == Approx(40).epsilon(1e-6));
    CHECK(fit[size_t(OpKind::camera)] == 0.0);  // never made: no cost
    CHECK(one_lane_fit_error(fit, samples).second < 1e-9);
    // A wrong cost shows in the error: 10 % off on the boxes.
    auto off = fit;
    off[size_t(OpKind::box_test)] *= 1.1;
    CHECK(one_lane_fit_error(off, samples).second > 0.05);
    CHECK_THROWS_AS(fit_one_lane_cycles({}), std::invalid_argument);
}

TEST_CASE("Host timing charges ops by kind and scene data by the level that holds it",
          "[host_timing]") {
    const HwConfig host = host_hw_config(
        small_host(), {cost("box_test", 10, 4, 0, 0, 0), cost("camera", 0, 0, 1, 0, 0)});
    FeatureSet features;  // default features: any layout works for the profiles
    const OpCostTable profiles(RayRecordLayout(features), host.datapath);
    SceneDataMap map;
    map.nodes = 100;
    HostTiming timing(host, map, profiles, 64);
    TilePass pass;
    pass.slot_count = 64;  // 4 KiB: in the L1D
    timing.begin_pass(pass);
    std::vector<uint32_t> slots(64);
    std::vector<uint8_t> passed(64, 1);
    StreamOp camera;
    camera.kind = OpKind::camera;
    camera.stage = OpStage::shading;
    camera.length = 64;
    camera.pass_count = 64;
    camera.slots = slots.data();
    camera.passed = passed.data();
    timing.op(camera);
    StreamOp box = camera;
    box.kind = OpKind::box_test;
    box.stage = OpStage::traversal;
    box.object = 3;
    box.length = 20;  // 2 groups
    timing.op(box);   // node 3: first touch, from DRAM: 81 - 1 ns = 80 cycles
    timing.op(box);   // now in the L1D: no extra
    const HostTimingResult& r = timing.result();
    CHECK(r.stage_cycles[size_t(OpStage::shading)] == Approx(64));
    CHECK(r.scene_memory_cycles[size_t(OpStage::traversal)] == Approx(80));
    CHECK(r.stage_cycles[size_t(OpStage::traversal)] == Approx(2 * 18 + 80));
    CHECK(r.frame_cycles() == Approx(64 + 36 + 80));

    StreamOp sphere = box;
    sphere.kind = OpKind::sphere_test;
    CHECK_THROWS_WITH(timing.op(sphere), Catch::Contains("sphere_test"));
}

TEST_CASE("host.hw.yaml reads back with its host knobs", "[host_timing]") {
    OpCostConfig box = cost("box_test", 1, 2, 3, 4, 5);
    box.one_lane_cycles = 6;
    const std::string yaml = host_hw_yaml(small_host(), {box}, "test samples");
    const HwConfig c = parse_hw_config(yaml, "host.hw.yaml");
    CHECK(c.ray_buffer.storage == "l1d");
    CHECK(c.ray_buffer.kib == 32);
    CHECK(c.partition.kind == "compress");
    CHECK(c.simd.width == 16);
    CHECK(c.simd.units == 1);
    CHECK(c.clock.core_mhz == Approx(1000));
    REQUIRE(c.scene_memory.caches.size() == 2);
    CHECK(c.scene_memory.caches[1].hit_latency_ns == Approx(5));
    CHECK(c.scene_memory.dram_latency_ns == Approx(81));
    REQUIRE(c.op_costs.size() == 1);
    CHECK(c.op_costs[0].beyond_l1_per_lane_cycles == Approx(5));
    CHECK(c.op_costs[0].one_lane_cycles == Approx(6));
    // A host file written before one-lane costs were measured: the formula for every op.
    CHECK(parse_hw_config("version: 1\nop_costs:\n  - {op: box_test, per_op_cycles: 3}\n",
                          "old.hw.yaml")
              .op_costs[0]
              .one_lane_cycles == 0.0);
    // The presets carry no op costs, so the store gains no columns from them.
    CHECK(HwConfig().op_costs.empty());

    try {
        parse_hw_config("version: 1\nop_costs:\n  - {op: box_tset}\n", "bad.hw.yaml");
        FAIL("no error for an unknown op kind");
    } catch (const InputError& e) {
        CHECK_THAT(e.what(), Catch::Contains("bad.hw.yaml:3") && Catch::Contains("op_costs[0].op"));
    }
    CHECK_THROWS_AS(parse_hw_config("version: 1\nop_costs:\n  - {op: camera}\n  - {op: camera}\n",
                                    "bad.hw.yaml"),
                    InputError);
    CHECK_THROWS_AS(parse_hw_config("version: 1\nray_buffer: {storage: dram}\n", "bad.hw.yaml"),
                    InputError);
}

TEST_CASE("The host's caches and clock are read from the CPU", "[host_timing]") {
    const std::vector<HostCacheLevel> caches = read_host_caches();
    REQUIRE(!caches.empty());  // sysfs or cpuid: every x86-64 CPU sfx runs on says something
    CHECK(caches.front().level == 1);
    CHECK(caches.front().type == "data");
    for (const HostCacheLevel& l : caches) {
        CHECK(l.kib > 0);
        CHECK(l.line_bytes >= 32);
        CHECK(l.ways >= 1);
    }
    const double mhz = measure_tsc_mhz(0.02);
    CHECK(mhz > 100.0);
    CHECK(mhz < 10000.0);
}
