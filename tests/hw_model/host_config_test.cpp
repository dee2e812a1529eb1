// The host CPU as a configuration of the machine model: measured op costs priced where every op
// is priced (OpProfile), their fit, scene-data latency through the host's caches, and the host
// configuration's knobs (storage l1d, slot_bytes, partition by compress, op_costs).

#include <catch2/catch.hpp>
#include <functional>
#include <numeric>
#include <random>

#include "base/input_error.h"
#include "hw_model/analytic_model.h"
#include "hw_model/cache_model.h"
#include "hw_model/host_description.h"
#include "hw_model/op_cost_fit.h"
#include "hw_model/op_costs.h"
#include "hw_model/ray_buffer_model.h"
#include "hw_model/systemc/systemc_timing.h"
#include "tests/hw_model/test_hosts.h"
#include "workloads/scene_loader.h"

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

// A host configuration with a cost for every op kind: `costs` as given, the rest free.
HwConfig host_with(std::vector<OpCostConfig> costs) {
    return host_hw_config(small_host(), costs_for_every_kind(std::move(costs)));
}

WorkloadShape shape() {
    return triangle_shape(8);
}

// `ops` in one pass of 64 slots, timed by the cycle-level model and by the closed form.
uint64_t cycle_level_cycles(const HwConfig& host, const std::vector<StreamOp>& ops) {
    SystemcTiming timing({host}, shape());
    TilePass pass;
    pass.slot_count = 64;
    timing.begin_pass(pass);
    for (const StreamOp& op : ops) timing.op(op);
    timing.end_pass(pass);
    return timing.timing(0).cycles;
}
uint64_t closed_form_cycles(const HwConfig& host, const std::vector<StreamOp>& ops) {
    TraceProfile profile(shape());
    TilePass pass;
    pass.slot_count = 64;
    profile.begin_pass(pass);
    for (const StreamOp& op : ops) profile.op(op);
    profile.end_pass(pass);
    return analytic_timing(host, shape(), profile).cycles;
}

// One box test of `lanes` lanes (all passing) on node `node`, per pass, in passes of `slots`
// ray slots, timed by the machine model.
FrameTiming time_boxes(const HwConfig& config, uint32_t passes, uint32_t lanes, uint32_t slots = 64,
                       uint32_t node = 3, uint32_t stride = 1) {
    SystemcTiming timing({config}, shape());
    std::vector<uint32_t> ids(lanes);
    for (uint32_t i = 0; i < lanes; ++i) ids[i] = i * stride;
    std::vector<uint8_t> passed(lanes, 1);
    for (uint32_t p = 0; p < passes; ++p) {
        TilePass pass;
        pass.slot_count = slots;
        timing.begin_pass(pass);
        timing.op({OpKind::box_test, OpStage::traversal, 0, node, lanes, lanes, ids.data(),
                   passed.data()});
        timing.end_pass(pass);
    }
    return timing.timing(0);
}

// A triangle test (hits on triangle `prim` for 16 lanes, slots 0..15), then the emission
// filter over those lanes, in one pass of 64 slots, timed by the machine model.
FrameTiming time_surfaces(const HwConfig& config, uint32_t prim = 7) {
    SystemcTiming timing({config}, shape());
    std::vector<uint32_t> ids(16);
    for (uint32_t i = 0; i < 16; ++i) ids[i] = i;
    const std::vector<uint8_t> all(16, 1), none(16, 0);
    TilePass pass;
    pass.slot_count = 64;
    timing.begin_pass(pass);
    timing.op(
        {OpKind::triangle_test, OpStage::intersection, 0, prim, 16, 16, ids.data(), all.data()});
    timing.op({OpKind::emission_filter, OpStage::shading, 0, k_no_object, 16, 0, ids.data(),
               none.data()});
    timing.end_pass(pass);
    return timing.timing(0);
}

HwConfig with_hit_share(HwConfig c, double share) {
    for (OpCostConfig& k : c.op_costs)
        if (k.op == "emission_filter") k.hit_read_exposed_share = share;
    return c;
}

}  // namespace

TEST_CASE("A CPU core leaves the measured share of its lanes' hit reads exposed",
          "[host][systemc]") {
    // The host reads a hit's surface from the mesh's arrays (host_hw_config: hit_reads mesh):
    // the triangle's 16-byte record, then its vertices, neither fetched by the triangle test.
    const HwConfig host = host_with({});
    REQUIRE(host.scene_memory.hit_reads == "mesh");
    SceneDataMap map = scene_data_map(shape());
    SceneDataMap::Read reads[2];
    REQUIRE(map.hit_reads(7, true, reads) == 2);
    CHECK(reads[0].bytes == 16);
    CHECK(reads[1].bytes == 36);
    CHECK(reads[1].address == reads[0].address + (map.triangles - 7) * 16 + 7 * 36);
    CHECK(reads[0].address > map.address(OpKind::material_filter, ~0u - 1));  // no overlap
    REQUIRE(map.hit_reads(7, false, reads) == 1);
    CHECK(reads[0].address == map.address(OpKind::triangle_test, 7));
    REQUIRE(map.hit_reads(uint32_t(map.triangles), true, reads) == 1);  // a sphere: its record
    CHECK(reads[0].bytes == 16);

    // The first lane finds both reads in DRAM (81 ns at 1 GHz, then a 64-byte line at 25.6
    // B/cycle: 84 cycles, an L2 hit's 5 hidden by the tracer's prefetches: 79 each, a vertex
    // read across two lines waiting for the later); the other 15 find them in the L1D. Half
    // of 2 x 79 is exposed, as a scene-memory stall of the shading stage; none at share 0.
    REQUIRE(hit_read_latency_hidden(host) == 5);
    const FrameTiming free = time_surfaces(host);
    const FrameTiming half = time_surfaces(with_hit_share(host, 0.5));
    CHECK(half.cycles - free.cycles == 79);
    CHECK(half.stalls.scene_memory - free.stalls.scene_memory == 79);
    CHECK(half.stages[0][size_t(OpStage::shading)].scene_memory_cycles -
              free.stages[0][size_t(OpStage::shading)].scene_memory_cycles ==
          79);
    // Read where the triangle test fetched it, the hit is an L1D hit: nothing exposed.
    HwConfig primitives = with_hit_share(host, 0.5);
    primitives.scene_memory.hit_reads = "primitives";
    CHECK(time_surfaces(primitives).cycles == free.cycles);
    // The reads are looked up whatever the share: the caches see them.
    CHECK(free.dram_reads == half.dram_reads);
    CHECK(free.dram_reads > time_surfaces(primitives).dram_reads);
}

TEST_CASE("The exposed share of hit reads is fitted through the cache model", "[host]") {
    const HwConfig host = host_with({});
    // 16-byte records and 36-byte vertices of a mesh of 2^15 triangles (1.6 MiB, beyond the
    // 256 KiB L2), of 2^13 (416 KiB, partly in it), of 2^12 (208 KiB, inside it) and of 64
    // (inside the L1D).
    auto sample = [](uint32_t triangles, uint32_t seed) {
        HitReadSample s;
        s.triangles = triangles;
        for (uint32_t i = 0; i < 512; ++i) s.timed_prims.push_back((i * 7919u + seed) % triangles);
        return s;
    };
    const HitReadSample resident = sample(64, 1);
    CHECK(modeled_hit_read_cycles(host, resident) == 0.0);  // warmed into the L1D
    // An L2 hit's latency is hidden (hit_read_latency_hidden): a mesh the L2 holds costs none.
    CHECK(modeled_hit_read_cycles(host, sample(1u << 12, 5)) == 0.0);
    HitReadSample big = sample(1u << 15, 3), mid = sample(1u << 13, 5);
    const double modeled_big = modeled_hit_read_cycles(host, big);
    const double modeled_mid = modeled_hit_read_cycles(host, mid);
    // The big mesh's reads mostly come from DRAM (79 beyond the L2 each, two a lane).
    CHECK(modeled_big > 512 * 2 * 40);
    CHECK(modeled_big <= 512 * 2 * 79);
    CHECK(modeled_mid > 0.0);
    CHECK(modeled_mid < modeled_big);
    big.extra_cycles = 0.3 * modeled_big;
    mid.extra_cycles = 0.3 * modeled_mid;
    const HitReadFit fit = fit_hit_read_exposed_share(host, {big, mid});
    CHECK(fit.share == Approx(0.3));
    CHECK(fit.error.second < 1e-9);
    mid.extra_cycles *= 2;  // a sample the one share cannot follow shows in the error
    CHECK(fit_hit_read_exposed_share(host, {big, mid}).error.second > 0.2);
    big.extra_cycles = mid.extra_cycles = 0;  // nothing measured: not negative
    CHECK(fit_hit_read_exposed_share(host, {big, mid}).share == 0.0);
    CHECK_THROWS_AS(fit_hit_read_exposed_share(host, {}), std::invalid_argument);
}

TEST_CASE("A measured op costs the formula of its kind, group by group", "[host]") {
    const OpCostConfig c = cost("box_test", 10, 4, 0.5, 2, 8);
    // 40 lanes: 3 groups of 16; 10 pass; half the buffer beyond the L1D.
    CHECK(measured_op_cycles(c, 16, 40, 10, 0.5) == Approx(10 + 12 + 20 + 20 + 160));
    CHECK(measured_op_cycles(c, 8, 40, 10, 0.0) == Approx(10 + 20 + 20 + 20));
    // The machine model prices a group where the fit does: the first carries the per-op cost.
    OpProfile p;
    p.measured = true;
    p.cost = c;
    CHECK(p.issue_cycles(DatapathConfig{}, 40, 10, 16, 3, true, 0.0) == Approx(10 + 4 + 8 + 6));
    CHECK(p.issue_cycles(DatapathConfig{}, 40, 10, 8, 0, false, 0.5) == Approx(4 + 4 + 32));
    // The op's mispredicted lanes (10 of 40) cost per minority lane, shared by lanes.
    p.cost.per_minority_lane_cycles = 3;
    CHECK(p.issue_cycles(DatapathConfig{}, 40, 10, 16, 3, true, 0.0) ==
          Approx(10 + 4 + 8 + 6 + 3 * 10 * 16 / 40.0));
    CHECK(p.issue_cycles(DatapathConfig{}, 40, 10, 8, 8, false, 0.0) ==
          Approx(4 + 4 + 16 + 3 * 10 * 8 / 40.0));
    OpCostConfig mixed = c;
    mixed.per_minority_lane_cycles = 3;
    CHECK(measured_op_cycles(mixed, 16, 40, 10, 0.0) == Approx(10 + 12 + 20 + 20 + 30));
    CHECK(measured_op_cycles(mixed, 16, 40, 40, 0.0) == Approx(10 + 12 + 20 + 80));
    CHECK(measured_op_cycles(mixed, 16, 40, 0, 0.0) == Approx(10 + 12 + 20));
    CHECK(p.result_cycles(DatapathConfig{}, 12.5) == 12.5);
    CHECK(beyond_cache_fraction(256, 64, 32) == 0.0);   // 16 KiB in 32 KiB
    CHECK(beyond_cache_fraction(1024, 64, 32) == 0.5);  // 64 KiB
    CHECK(beyond_cache_fraction(0, 64, 32) == 0.0);

    // A one-lane op runs in the one-ray loop: its own measured cost, when there is one.
    OpCostConfig one = c;
    CHECK(measured_op_cycles(one, 16, 1, 1, 0.5) == Approx(10 + 4 + 0.5 + 2 + 4));
    one.one_lane_cycles = 7;
    CHECK(measured_op_cycles(one, 16, 1, 1, 0.5) == Approx(7));
    CHECK(measured_op_cycles(one, 16, 1, 0, 0.0) == Approx(7));
    CHECK(measured_op_cycles(one, 16, 2, 1, 0.0) == Approx(10 + 4 + 1 + 2));
    // A stream of 2 to k_few_ray_lanes rays runs in the few-ray loop: its own cost, when
    // there is one (a wide back end's box test); a longer one the formula.
    one.few_lane_cycles = 5;
    CHECK(measured_op_cycles(one, 16, 2, 1, 0.0) == Approx(5));
    CHECK(measured_op_cycles(one, 16, k_few_ray_lanes, 0, 0.5) == Approx(5));
    CHECK(measured_op_cycles(one, 16, k_few_ray_lanes + 1, 1, 0.0) ==
          Approx(10 + 4 + 0.5 * (k_few_ray_lanes + 1) + 2));
    CHECK(measured_op_cycles(one, 16, 1, 1, 0.0) == Approx(7));
    // A fitted 0 is a cost; only a negative one is not measured.
    one.one_lane_cycles = 0;
    one.few_lane_cycles = 0;
    CHECK(measured_op_cycles(one, 16, 1, 1, 0.5) == 0.0);
    CHECK(measured_op_cycles(one, 16, 3, 1, 0.0) == 0.0);
    one.one_lane_cycles = one.few_lane_cycles = -1;
    CHECK(measured_op_cycles(one, 16, 1, 1, 0.5) == Approx(10 + 4 + 0.5 + 2 + 4));
    CHECK(OpCostConfig{}.one_lane_cycles < 0);
    CHECK(OpCostConfig{}.few_lane_cycles < 0);

    // In the model, short-loop costs are kept for the ops those loops run only: a host file
    // written before session 52 gives every op 0.00 (then: not measured). A one-lane camera
    // op stays the formula's; a box test of 3 lanes the few-ray cost on a wide back end only.
    OpCostConfig old_camera = c, old_box = c;
    old_camera.op = "camera";
    old_box.op = "box_test";
    old_camera.one_lane_cycles = old_camera.few_lane_cycles = 0;
    old_box.one_lane_cycles = old_box.few_lane_cycles = 0;
    HwConfig old_host = host_with({old_camera, old_box});
    const DatapathConfig datapath;
    for (const uint32_t width : {1u, 8u}) {
        old_host.simd.width = width;
        const OpCostTable table(RayRecordLayout(FeatureSet{}), old_host);
        CHECK(table[OpKind::camera].issue_cycles(datapath, 1, 0, 1, 1, true, 0.0) ==
              Approx(10 + 4 + 0.5 + 2));
        CHECK(table[OpKind::box_test].issue_cycles(datapath, 1, 0, 1, 1, true, 0.0) == 0.0);
        CHECK(table[OpKind::box_test].issue_cycles(datapath, 3, 0, 3, 1, true, 0.0) ==
              (width == 1 ? Approx(10 + 4 + 1.5 + 2) : Approx(0.0)));
    }
}

TEST_CASE("A thin-lens camera's rays cost what its microbenchmarks add to the pinhole's",
          "[host]") {
    // The fit: the lens samples' cycles beyond the pinhole's fitted cost, per lane (median).
    const OpCostConfig pinhole = cost("camera", 15, 0, 120, 0, 30);
    std::vector<OpCostSample> lens;
    for (uint32_t lanes : {16u, 64u, 256u})
        lens.push_back({lanes, lanes, 0.25,
                        measured_op_cycles(pinhole, 8, lanes, lanes, 0.25) + 80.0 * lanes});
    lens.push_back({32, 32, 0.0, measured_op_cycles(pinhole, 8, 32, 32, 0.0) + 500.0 * 32});
    CHECK(fit_extra_per_passing_lane(pinhole, 8, lens) == Approx(80));
    CHECK(fit_extra_per_passing_lane(pinhole, 8, {}) == 0.0);
    // Never negative: a lens no dearer than the pinhole adds nothing.
    CHECK(fit_extra_per_passing_lane(pinhole, 8, {{64, 64, 0.0, 100.0}}) == 0.0);

    // The model: every lane of a camera op on a scene with a lens pays it, no other op's.
    OpCostConfig camera = pinhole;
    camera.thin_lens_per_lane_cycles = 80;
    HwConfig host = host_with({camera, cost("box_test", 10, 4, 0, 0, 0)});
    FeatureSet pinhole_scene, lens_scene;
    lens_scene.thin_lens = true;
    const OpCostTable plain(RayRecordLayout(pinhole_scene), host),
        with_lens(RayRecordLayout(lens_scene), host);
    const DatapathConfig d;
    CHECK(with_lens[OpKind::camera].issue_cycles(d, 64, 0, 8, 8, false, 0.0) ==
          Approx(plain[OpKind::camera].issue_cycles(d, 64, 0, 8, 8, false, 0.0) + 8 * 80));
    CHECK(with_lens[OpKind::box_test].issue_cycles(d, 64, 0, 8, 8, false, 0.0) ==
          plain[OpKind::box_test].issue_cycles(d, 64, 0, 8, 8, false, 0.0));
}

TEST_CASE("A triangle test's failed candidates cost what their microbenchmark adds", "[host]") {
    // The fit: the failing candidates' cycles beyond the plain test's fitted cost (which
    // prices them as failing lanes), per failed candidate (median).
    const OpCostConfig plain = cost("triangle_test", 20, 6, 3, 40, 2);
    std::vector<OpCostSample> failing;
    for (uint32_t lanes : {16u, 64u, 256u})
        failing.push_back(
            {lanes, 0, 0.0, measured_op_cycles(plain, 8, lanes, 0, 0.0) + 35.0 * lanes, lanes});
    failing.push_back({32, 0, 0.0, measured_op_cycles(plain, 8, 32, 0, 0.0) + 90.0 * 32, 32});
    CHECK(fit_extra_per_failed_candidate(plain, 8, failing) == Approx(35));
    // Samples without failed candidates tell nothing; never negative.
    CHECK(fit_extra_per_failed_candidate(plain, 8, {{64, 0, 0.0, 5000.0, 0}}) == 0.0);
    CHECK(fit_extra_per_failed_candidate(plain, 8, {{64, 0, 0.0, 1.0, 64}}) == 0.0);

    // The model: an op's failed candidates, shared by its groups by lanes.
    OpCostConfig priced = plain;
    priced.per_failed_candidate_cycles = 35;
    CHECK(measured_op_cycles(priced, 8, 40, 10, 0.0, 0.0, 12) ==
          Approx(measured_op_cycles(plain, 8, 40, 10, 0.0) + 35 * 12));
    OpProfile p;
    p.measured = true;
    p.cost = priced;
    CHECK(p.issue_cycles(DatapathConfig{}, 40, 0, 8, 2, false, 0.0, 0.0, 12) ==
          Approx(p.issue_cycles(DatapathConfig{}, 40, 0, 8, 2, false, 0.0) + 35 * 12 * 8 / 40.0));
    // A one-lane op keeps its own timed cost.
    priced.one_lane_cycles = 50;
    CHECK(measured_op_cycles(priced, 8, 1, 0, 0.0, 0.0, 1) == Approx(50));
}

TEST_CASE("A one-lane leaf test costs what its lane's outcome cost on one lane", "[host]") {
    // The fit: the failing lane's median, and the passing lane's and the failed candidate's
    // medians beyond it.
    OpCostConfig triangle = cost("triangle_test", 20, 6, 3, 40, 2);
    std::vector<OpCostSample> one_lane;
    for (double cycles : {60.0, 66.0, 64.0}) one_lane.push_back({1, 0, 0.0, cycles, 0});
    for (double cycles : {150.0, 154.0, 400.0}) one_lane.push_back({1, 1, 0.0, cycles, 0});
    for (double cycles : {130.0, 135.0, 500.0}) one_lane.push_back({1, 0, 0.0, cycles, 1});
    fit_one_lane_by_outcome(triangle, one_lane);
    CHECK(triangle.one_lane_cycles == Approx(64));
    CHECK(triangle.one_lane_pass_cycles == Approx(154 - 64));
    CHECK(triangle.one_lane_failed_candidate_cycles == Approx(135 - 64));
    CHECK(triangle.per_pass_cycles == 40);  // the rest kept
    // Where no lane failed, the median of all and no extras; never negative.
    OpCostConfig sphere = cost("sphere_test", 20, 6, 3, 40, 2);
    fit_one_lane_by_outcome(sphere,
                            {{1, 1, 0.0, 90.0, 0}, {1, 1, 0.0, 95.0, 0}, {1, 1, 0.0, 99.0, 0}});
    CHECK(sphere.one_lane_cycles == Approx(95));
    CHECK(sphere.one_lane_pass_cycles == 0.0);
    fit_one_lane_by_outcome(sphere, {{1, 0, 0.0, 90.0, 0}, {1, 1, 0.0, 80.0, 0}});
    CHECK(sphere.one_lane_cycles == Approx(90));
    CHECK(sphere.one_lane_pass_cycles == 0.0);
    // No one-lane samples (a shading op's): unmeasured, and one lane is priced by the formula.
    OpCostConfig shader = cost("lambertian_indirect", 20, 6, 3, 40, 2);
    fit_one_lane_by_outcome(shader, {});
    CHECK(shader.one_lane_cycles < 0);
    CHECK(measured_op_cycles(shader, 8, 1, 1, 0.0) == Approx(20 + 6 + 3 + 40));

    // The price: the failing lane's, plus the passing lane's or the failed candidate's extra;
    // the closed form's bucket of one-lane ops at its mean pass rate and failed candidates.
    CHECK(measured_op_cycles(triangle, 8, 1, 0, 0.0) == Approx(64));
    CHECK(measured_op_cycles(triangle, 8, 1, 1, 0.0) == Approx(154));
    CHECK(measured_op_cycles(triangle, 8, 1, 0, 0.0, 0.0, 1) == Approx(135));
    OpProfile p;
    p.measured = true;
    p.cost = triangle;
    CHECK(p.issue_cycles(DatapathConfig{}, 1, 0, 1, 0.25, true, 0.0, 0.0, 0.5) ==
          Approx(64 + 0.25 * 90 + 0.5 * 71));
    // A host file of one price (written before the extras) prices every outcome alike.
    OpCostConfig old_file = cost("triangle_test", 20, 6, 3, 40, 2);
    old_file.one_lane_cycles = 123;
    CHECK(measured_op_cycles(old_file, 8, 1, 1, 0.0) == Approx(123));
    CHECK(measured_op_cycles(old_file, 8, 1, 0, 0.0, 0.0, 1) == Approx(123));
    const HwConfig parsed = parse_hw_config(host_hw_yaml(small_host(), {triangle}, "t"), "t.yaml");
    REQUIRE(parsed.op_costs.size() == 1);
    CHECK(parsed.op_costs[0].one_lane_pass_cycles == Approx(90));
    CHECK(parsed.op_costs[0].one_lane_failed_candidate_cycles == Approx(71));
}

TEST_CASE("A passing direct-light lane pays a sphere light's extra in the share on spheres",
          "[host]") {
    OpCostConfig direct = cost("lambertian_direct", 10, 0, 150, 0, 30);
    direct.sphere_light_per_pass_cycles = 60;
    HwConfig host = host_with({direct, cost("lambertian_indirect", 10, 0, 150, 0, 30)});
    FeatureSet quad, half, sphere;
    half.sphere_light_share = 0.5f;
    sphere.sphere_light_share = 1.f;
    const OpCostTable on_quad(RayRecordLayout(quad), host), on_half(RayRecordLayout(half), host),
        on_sphere(RayRecordLayout(sphere), host);
    const DatapathConfig d;
    // A group of 8 lanes, 5 passing.
    auto issue = [&](const OpCostTable& t, OpKind k) {
        return t[k].issue_cycles(d, 64, 0, 8, 5, false, 0.0);
    };
    CHECK(issue(on_half, OpKind::lambertian_direct) ==
          Approx(issue(on_quad, OpKind::lambertian_direct) + 5 * 30));
    CHECK(issue(on_sphere, OpKind::lambertian_direct) ==
          Approx(issue(on_quad, OpKind::lambertian_direct) + 5 * 60));
    CHECK(issue(on_sphere, OpKind::lambertian_indirect) ==
          issue(on_quad, OpKind::lambertian_indirect));
    // The fit: the sphere light's samples beyond the quad's cost, per passing lane; a stream
    // none of whose lanes pass tells nothing.
    std::vector<OpCostSample> on_spheres;
    for (uint32_t lanes : {16u, 64u, 256u})
        on_spheres.push_back(
            {lanes, lanes / 2, 0.0,
             measured_op_cycles(direct, 8, lanes, lanes / 2, 0.0) + 60.0 * (lanes / 2)});
    on_spheres.push_back({64, 0, 0.0, measured_op_cycles(direct, 8, 64, 0, 0.0)});
    CHECK(fit_extra_per_passing_lane(direct, 8, on_spheres) == Approx(60));

    // The share: a light picked at random, then a primitive of it by area.
    CHECK(load_scene("furnace").features().sphere_light_share == Approx(1.f));
    CHECK(load_scene("cornell").features().sphere_light_share == 0.f);
}

TEST_CASE("An emission lane pays a sphere hit's difference in the share of sphere area", "[host]") {
    OpCostConfig emission = cost("emission_filter", 10, 20, 70, 0, 0);
    emission.sphere_hit_per_lane_cycles = -24;
    HwConfig host = host_with({emission, cost("depth_filter", 10, 0, 5, 0, 0)});
    FeatureSet triangles, half, spheres;
    half.sphere_area_share = 0.5f;
    spheres.sphere_area_share = 1.f;
    const OpCostTable on_triangles(RayRecordLayout(triangles), host),
        on_half(RayRecordLayout(half), host), on_spheres(RayRecordLayout(spheres), host);
    const DatapathConfig d;
    auto issue = [&](const OpCostTable& t, OpKind k) {
        return t[k].issue_cycles(d, 64, 0, 8, 0, false, 0.0);
    };
    CHECK(issue(on_half, OpKind::emission_filter) ==
          Approx(issue(on_triangles, OpKind::emission_filter) - 8 * 12));
    CHECK(issue(on_spheres, OpKind::emission_filter) ==
          Approx(issue(on_triangles, OpKind::emission_filter) - 8 * 24));
    CHECK(issue(on_spheres, OpKind::depth_filter) == issue(on_triangles, OpKind::depth_filter));
    // The fit: the sphere hits' samples against the triangle hits' cost, per lane, signed.
    std::vector<OpCostSample> on_sphere_hits;
    for (uint32_t lanes : {16u, 64u, 256u})
        on_sphere_hits.push_back(
            {lanes, 0, 0.0, measured_op_cycles(emission, 8, lanes, 0, 0.0) - 24.0 * lanes});
    CHECK(fit_extra_per_lane(emission, 8, on_sphere_hits) == Approx(-24));
    CHECK(fit_extra_per_lane(emission, 8, {}) == 0.0);
    // A cold call's extra: the median over its lengths, never negative.
    CHECK(fit_cold_call_cycles({60, -400, 80}) == Approx(60));
    CHECK(fit_cold_call_cycles({60, 90}) == Approx(75));
    CHECK(fit_cold_call_cycles({-10, -5, 3}) == 0.0);
    CHECK(fit_cold_call_cycles({}) == 0.0);
    // A host file keeps the sign.
    const HwConfig parsed = parse_hw_config(host_hw_yaml(small_host(), {emission}, "e"), "e.yaml");
    REQUIRE(parsed.op_costs.size() == 1);
    CHECK(parsed.op_costs[0].sphere_hit_per_lane_cycles == Approx(-24));

    // The share: exact where a scene has one kind of primitive, by area where it has both.
    CHECK(load_scene("furnace").features().sphere_area_share == Approx(1.f));
    CHECK(load_scene("conference").features().sphere_area_share == 0.f);
    const float cornell = load_scene("cornell").features().sphere_area_share;
    CHECK(cornell > 0.1f);
    CHECK(cornell < 0.2f);
}

TEST_CASE("The fit recovers costs from exact samples and never goes negative", "[host]") {
    const OpCostConfig truth = cost("triangle_test", 30, 12, 0, 40, 3);
    std::vector<OpCostSample> samples;
    for (uint32_t lanes : {1u, 7u, 16u, 33u, 100u, 512u, 4096u})
        for (double beyond : {0.0, 0.75})
            for (uint32_t passed : {0u, lanes / 3})
                samples.push_back(
                    {lanes, passed, beyond, measured_op_cycles(truth, 16, lanes, passed, beyond)});
    const OpCostConfig fit = fit_op_cost("triangle_test", 16, samples);
    CHECK(fit.per_op_cycles == Approx(30).epsilon(1e-6));
    CHECK(fit.per_group_cycles == Approx(12).epsilon(1e-6));
    CHECK(fit.per_lane_cycles == Approx(0).margin(1e-6));
    CHECK(fit.per_pass_cycles == Approx(40).epsilon(1e-6));
    CHECK(fit.beyond_l1_per_lane_cycles == Approx(3).epsilon(1e-6));
    CHECK(fit.beyond_l2_per_lane_cycles == 0.0);  // no sample beyond the L2
    CHECK(fit.per_minority_lane_cycles == 0.0);  // no stream of many lanes all passed
    CHECK(fit.per_fail_cycles == 0.0);  // a passing lane costs more: the pass column holds it
    CHECK(fit_error(fit, 16, samples).second < 1e-9);

    // Lanes beyond the L2 (a share of those beyond the L1D, on the biggest buffers) tell what
    // the L2 adds from what the L1D does.
    OpCostConfig two_levels = truth;
    two_levels.beyond_l2_per_lane_cycles = 20;
    std::vector<OpCostSample> levels;
    for (uint32_t lanes : {1u, 7u, 16u, 33u, 100u, 512u, 4096u})
        for (const auto& [l1, l2] : {std::pair{0.0, 0.0}, {0.5, 0.0}, {0.9, 0.25}})
            for (uint32_t passed : {0u, lanes / 3})
                levels.push_back({lanes, passed, l1,
                                  measured_op_cycles(two_levels, 16, lanes, passed, l1, l2), 0,
                                  l2});
    const OpCostConfig level_fit = fit_op_cost("triangle_test", 16, levels);
    CHECK(level_fit.beyond_l1_per_lane_cycles == Approx(3).epsilon(1e-6));
    CHECK(level_fit.beyond_l2_per_lane_cycles == Approx(20).epsilon(1e-6));
    CHECK(fit_error(level_fit, 16, levels).second < 1e-9);

    // Lanes beyond the L1D that skip lines in a page the lane before opened (streams of many
    // lanes of one buffer) tell their cost from a page-opening lane's (sparse streams: each
    // lane a page).
    OpCostConfig skipping = truth;
    skipping.beyond_l1_skipping_per_lane_cycles = 1.5;
    std::vector<OpCostSample> dense;
    for (uint32_t lanes : {1u, 7u, 16u, 33u, 100u, 512u, 4096u})
        for (const auto& [opening, inside] : {std::pair{0.0, 0.0}, {0.8, 0.05}, {0.05, 0.85}})
            for (uint32_t passed : {0u, lanes / 3}) {
                OpCostSample s{
                    lanes, passed, opening,
                    measured_op_cycles(skipping, 16, lanes, passed, opening, 0.0, 0.0, inside)};
                s.beyond_l1_skipping = inside;
                dense.push_back(s);
            }
    const OpCostConfig dense_fit = fit_op_cost("triangle_test", 16, dense);
    CHECK(dense_fit.beyond_l1_per_lane_cycles == Approx(3).epsilon(1e-6));
    CHECK(dense_fit.beyond_l1_skipping_per_lane_cycles == Approx(1.5).epsilon(1e-6));
    CHECK(dense_fit.per_pass_cycles == Approx(40).epsilon(1e-6));
    CHECK(fit_error(dense_fit, 16, dense).second < 1e-9);
    // Without such lanes the term is not measured: 0.
    CHECK(level_fit.beyond_l1_skipping_per_lane_cycles == 0.0);
    CHECK(level_fit.beyond_tlb_per_lane_cycles == 0.0);

    // Lanes that open a page beyond the DTLB's reach (the biggest buffers' lanes, in the L1D or
    // not) tell their cost from a lane beyond the L1D's.
    OpCostConfig paged = truth;
    paged.beyond_tlb_per_lane_cycles = 7;
    std::vector<OpCostSample> pages;
    for (uint32_t lanes : {1u, 7u, 16u, 33u, 100u, 512u, 4096u})
        for (const auto& [l1, tlb] : {std::pair{0.0, 0.0}, {0.5, 0.0}, {0.9, 0.6}, {0.1, 0.3}})
            for (uint32_t passed : {0u, lanes / 3}) {
                OpCostSample s{
                    lanes, passed, l1,
                    measured_op_cycles(paged, 16, lanes, passed, l1, 0.0, 0.0, 0.0, tlb)};
                s.beyond_tlb = tlb;
                pages.push_back(s);
            }
    const OpCostConfig page_fit = fit_op_cost("triangle_test", 16, pages);
    CHECK(page_fit.beyond_l1_per_lane_cycles == Approx(3).epsilon(1e-6));
    CHECK(page_fit.beyond_tlb_per_lane_cycles == Approx(7).epsilon(1e-6));
    CHECK(fit_error(page_fit, 16, pages).second < 1e-9);

    // A lane that passes costs less than one that fails (the scalar box test): the passing
    // lanes' cost would be negative, so the failing lanes' column takes it.
    OpCostConfig cheaper_pass = cost("box_test", 0, 0, 25, 0, 8);
    cheaper_pass.per_fail_cycles = 20;
    std::vector<OpCostSample> boxes;
    for (uint32_t lanes : {8u, 24u, 96u, 512u, 4096u})
        for (double beyond : {0.0, 0.5})
            for (uint32_t passed : {lanes, lanes / 2, lanes / 8})
                boxes.push_back({lanes, passed, beyond,
                                 measured_op_cycles(cheaper_pass, 1, lanes, passed, beyond)});
    const OpCostConfig box_fit = fit_op_cost("box_test", 1, boxes);
    CHECK(box_fit.per_fail_cycles == Approx(20).epsilon(1e-6));
    CHECK(box_fit.per_pass_cycles == 0.0);
    CHECK(box_fit.per_lane_cycles + box_fit.per_group_cycles == Approx(25).epsilon(1e-6));
    CHECK(box_fit.beyond_l1_per_lane_cycles == Approx(8).epsilon(1e-6));
    CHECK(fit_error(box_fit, 1, boxes).second < 1e-9);

    // Streams that all pass and that none pass, beside mixed ones, tell a minority lane's cost
    // (a branch predictor's misses) from a lane's and a passing lane's.
    OpCostConfig branchy = cost("lambertian_choice", 12, 0, 8, 2, 0);
    branchy.per_minority_lane_cycles = 25;
    std::vector<OpCostSample> dealt;
    for (uint32_t lanes : {8u, 16u, 48u, 200u, 1024u})
        for (uint32_t passed : {lanes / 2, lanes, 0u, lanes / 5})
            dealt.push_back({lanes, passed, 0.0,
                             measured_op_cycles(branchy, 1, lanes, passed, 0.0)});
    const OpCostConfig branchy_fit = fit_op_cost("lambertian_choice", 1, dealt);
    CHECK(branchy_fit.per_minority_lane_cycles == Approx(25).epsilon(1e-6));
    CHECK(branchy_fit.per_pass_cycles == Approx(2).epsilon(1e-6));
    CHECK(fit_error(branchy_fit, 1, dealt).second < 1e-9);

    // Cycles that fall with length cannot be fitted by non-negative costs: the fit clamps.
    std::vector<OpCostSample> falling = {{1, 0, 0, 100}, {16, 0, 0, 50}, {256, 0, 0, 10}};
    const OpCostConfig f = fit_op_cost("miss_filter", 16, falling);
    for (double v : {f.per_op_cycles, f.per_group_cycles, f.per_lane_cycles, f.per_pass_cycles,
                     f.beyond_l1_per_lane_cycles})
        CHECK(v >= 0.0);
    CHECK_THROWS_AS(fit_op_cost("box_test", 16, {}), std::invalid_argument);
}

TEST_CASE("The short-stream fit recovers each kind's one- and few-lane cost and the stream "
          "loop's per-op box cost from traversals that mix them, beyond what their "
          "stream-priced groups and lanes take",
          "[host]") {
    auto sample = [](uint64_t boxes, uint64_t triangles, uint64_t spheres, uint64_t few_boxes,
                     uint64_t stream_boxes, double stream_cycles, uint64_t one_entries = 0,
                     uint64_t few_entries = 0, uint64_t traversals = 0) {
        OneLaneSample s;
        s.entries = {one_entries, few_entries};
        s.traversals = traversals;
        s.ops[size_t(OpKind::box_test)] = boxes;
        s.ops[size_t(OpKind::triangle_test)] = triangles;
        s.ops[size_t(OpKind::sphere_test)] = spheres;
        s.few_ops[size_t(OpKind::box_test)] = few_boxes;
        s.stream_ops[size_t(OpKind::box_test)] = stream_boxes;
        s.stream_op_cycles = stream_cycles;
        s.cycles = 30.0 * boxes + 90.0 * triangles + 40.0 * spheres + 55.0 * few_boxes +
                   140.0 * stream_boxes + stream_cycles + 25.0 * one_entries + 260.0 * few_entries +
                   70.0 * traversals;
        return s;
    };
    std::vector<OneLaneSample> samples;
    for (uint64_t b : {7u, 23u, 130u})
        for (uint64_t t : {0u, 2u, 12u})
            for (uint64_t s : {0u, 1u, 5u})
                for (uint64_t f : {0u, 3u, 40u})
                    for (uint64_t w : {0u, 4u, 19u})
                        samples.push_back(sample(b, t, s, f, w, f * 70.0 + w * 300.0));
    const ShortStreamCosts fit = fit_short_stream_cycles(samples);
    CHECK(fit.one_lane[size_t(OpKind::box_test)] == Approx(30).epsilon(1e-6));
    CHECK(fit.one_lane[size_t(OpKind::triangle_test)] == Approx(90).epsilon(1e-6));
    CHECK(fit.one_lane[size_t(OpKind::sphere_test)] == Approx(40).epsilon(1e-6));
    CHECK(fit.few_lane[size_t(OpKind::box_test)] == Approx(55).epsilon(1e-6));
    CHECK(fit.stream_per_op[size_t(OpKind::box_test)] == Approx(140).epsilon(1e-6));
    CHECK(fit.stream_measured[size_t(OpKind::box_test)]);
    CHECK_FALSE(fit.stream_measured[size_t(OpKind::triangle_test)]);  // none in the samples
    CHECK(fit.one_lane[size_t(OpKind::camera)] == 0.0);  // never made: no cost, not measured
    CHECK_FALSE(fit.one_lane_measured[size_t(OpKind::camera)]);
    CHECK(fit.few_lane[size_t(OpKind::triangle_test)] == 0.0);
    CHECK_FALSE(fit.few_lane_measured[size_t(OpKind::triangle_test)]);
    CHECK(fit.one_lane_measured[size_t(OpKind::box_test)]);
    CHECK(fit.few_lane_measured[size_t(OpKind::box_test)]);
    CHECK(short_stream_fit_error(fit, samples).second < 1e-9);
    // A wrong cost shows in the error: 10 % off on the boxes, 20 % on the few-ray loop's or the
    // stream loop's.
    ShortStreamCosts off = fit;
    off.one_lane[size_t(OpKind::box_test)] *= 1.1;
    CHECK(short_stream_fit_error(off, samples).second > 0.05);
    off = fit;
    off.few_lane[size_t(OpKind::box_test)] *= 1.2;
    CHECK(short_stream_fit_error(off, samples).second > 0.05);
    off = fit;
    off.stream_per_op[size_t(OpKind::box_test)] *= 1.2;
    CHECK(short_stream_fit_error(off, samples).second > 0.05);

    // The stream-priced ops are not the loops' to carry: ignoring them fits other costs.
    std::vector<OneLaneSample> unpriced = samples;
    for (OneLaneSample& s : unpriced) s.stream_op_cycles = 0;
    CHECK(fit_short_stream_cycles(unpriced).few_lane[size_t(OpKind::box_test)] > 60);
    CHECK_THROWS_AS(fit_short_stream_cycles({}), std::invalid_argument);

    // Leaf tests that the filter microbenchmarks price 30 % over what the stage clock split off
    // (each sample's leaves 200 cycles by the clock): clocked, the fit keeps every cost; priced
    // only, it takes the difference off the others.
    std::vector<OneLaneSample> clocked = samples, priced_only = samples;
    for (size_t i = 0; i < samples.size(); ++i) {
        for (OneLaneSample* s : {&clocked[i], &priced_only[i]}) {
            s->cycles += 200.0;
            s->leaf_op_cycles = 260.0;
            s->stream_op_cycles += 260.0;
        }
        clocked[i].leaf_cycles_clocked = 200.0;
    }
    const ShortStreamCosts clocked_fit = fit_short_stream_cycles(clocked);
    CHECK(clocked_fit.stream_per_op[size_t(OpKind::box_test)] == Approx(140).epsilon(1e-6));
    CHECK(clocked_fit.few_lane[size_t(OpKind::box_test)] == Approx(55).epsilon(1e-6));
    CHECK(clocked_fit.one_lane[size_t(OpKind::box_test)] == Approx(30).epsilon(1e-6));
    const ShortStreamCosts priced_fit = fit_short_stream_cycles(priced_only);
    const double off_by = std::abs(priced_fit.stream_per_op[size_t(OpKind::box_test)] - 140) / 140 +
                          std::abs(priced_fit.few_lane[size_t(OpKind::box_test)] - 55) / 55 +
                          std::abs(priced_fit.one_lane[size_t(OpKind::box_test)] - 30) / 30;
    CHECK(off_by > 0.01);

    // Loop entries: told from the ops only where subtrees hold fewer or more ops per entry (as
    // streams that enter deep and at the root do).
    std::vector<OneLaneSample> entered;
    for (uint64_t b : {7u, 23u, 130u})
        for (uint64_t t : {0u, 2u, 12u})
            for (uint64_t f : {0u, 3u, 40u})
                for (uint64_t e : {1u, 4u, 9u})
                    for (uint64_t g : {0u, 2u, 5u})
                        entered.push_back(sample(b, t, 1, f, 4, 500.0, e, g));
    const ShortStreamCosts with_entries = fit_short_stream_cycles(entered);
    CHECK(with_entries.entry[0] == Approx(25).epsilon(1e-6));
    CHECK(with_entries.entry[1] == Approx(260).epsilon(1e-6));
    CHECK(with_entries.one_lane[size_t(OpKind::box_test)] == Approx(30).epsilon(1e-6));
    CHECK(with_entries.few_lane[size_t(OpKind::box_test)] == Approx(55).epsilon(1e-6));
    CHECK(short_stream_fit_error(with_entries, entered).second < 1e-9);
    ShortStreamCosts no_entry = with_entries;
    no_entry.entry[1] = 0;
    CHECK(short_stream_fit_error(no_entry, entered).second > 0.05);
    // The few-ray loop's costs given (another back end's): priced out, the rest fitted, the
    // given ones returned as given, right or wrong.
    const GivenFewRayCosts right{55.0, 260.0}, wrong{70.0, 200.0};
    const ShortStreamCosts given = fit_short_stream_cycles(entered, &right);
    CHECK(given.few_lane[size_t(OpKind::box_test)] == 55.0);
    CHECK(given.entry[1] == 260.0);
    CHECK(given.few_lane_measured[size_t(OpKind::box_test)]);
    CHECK(given.one_lane[size_t(OpKind::box_test)] == Approx(30).epsilon(1e-6));
    CHECK(given.entry[0] == Approx(25).epsilon(1e-6));
    CHECK(short_stream_fit_error(given, entered).second < 1e-9);
    const ShortStreamCosts given_wrong = fit_short_stream_cycles(entered, &wrong);
    CHECK(given_wrong.few_lane[size_t(OpKind::box_test)] == 70.0);
    CHECK(given_wrong.entry[1] == 200.0);
    CHECK(short_stream_fit_error(given_wrong, entered).second > 0.01);
    CHECK(fit.entry[0] == 0.0);  // samples without entries: none fitted
    CHECK(fit.traversal_start == 0.0);

    // A traversal's start: told from the ops and entries where traversals hold more or fewer of
    // them (streams of one ray and of many, from the root and deep).
    std::vector<OneLaneSample> started;
    for (uint64_t b : {7u, 23u, 130u})
        for (uint64_t w : {0u, 4u, 19u})
            for (uint64_t e : {1u, 4u, 9u})
                for (uint64_t n : {1u, 8u, 32u})
                    started.push_back(sample(b, 0, 0, 0, w, 300.0, e, 0, n));
    const ShortStreamCosts with_starts = fit_short_stream_cycles(started);
    CHECK(with_starts.traversal_start == Approx(70).epsilon(1e-6));
    CHECK(with_starts.entry[0] == Approx(25).epsilon(1e-6));
    CHECK(short_stream_fit_error(with_starts, started).second < 1e-9);
    ShortStreamCosts no_start = with_starts;
    no_start.traversal_start = 0;
    CHECK(short_stream_fit_error(no_start, started).second > 0.05);
}

TEST_CASE(
    "Where the stage clock splits the loops, the short-stream fit takes each loop's costs "
    "from its own cycles, not from how the batches mix the loops",
    "[host]") {
    // Batches whose few-ray box tests are always twice their stream-loop ones: on the whole
    // cycles a few-ray box at 55 and a stream box at 140 fit as well as 45 and 160. The clock
    // says which: each loop's cycles (less its priced mispredictions; a few-ray stream's
    // one-lane subtrees are its own) against its own ops.
    auto sample = [](uint64_t boxes, uint64_t nested, uint64_t stream_boxes, double few_cost,
                     double stream_cost) {
        OneLaneSample s;
        const uint64_t few_boxes = 2 * stream_boxes;
        const double mispredicted_one = 3.0 * double(boxes),
                     mispredicted_few = 7.0 * double(nested);
        s.ops[size_t(OpKind::box_test)] = boxes;
        s.few_ops[size_t(OpKind::box_test)] = few_boxes;
        s.stream_ops[size_t(OpKind::box_test)] = stream_boxes;
        s.few_ray_one_lane_box_ops = nested;
        s.loop_mispredicted_cycles = {mispredicted_one, mispredicted_few};
        s.stream_op_cycles = 900.0 + mispredicted_one + mispredicted_few;
        s.leaf_cycles_clocked = 0.0;
        s.loop_cycles_clocked = {
            30.0 * double(boxes - nested) + mispredicted_one,
            few_cost * double(few_boxes) + 30.0 * double(nested) + mispredicted_few};
        s.cycles = s.loop_cycles_clocked[0] + s.loop_cycles_clocked[1] +
                   stream_cost * double(stream_boxes) + 900.0;
        return s;
    };
    constexpr size_t box = size_t(OpKind::box_test);
    for (const auto& [few_cost, stream_cost] : {std::pair{55.0, 140.0}, std::pair{45.0, 160.0}}) {
        std::vector<OneLaneSample> samples;
        for (uint64_t b : {7u, 23u, 130u})
            for (uint64_t n : {0u, 3u})
                for (uint64_t w : {1u, 4u, 19u})
                    samples.push_back(sample(b, n, w, few_cost, stream_cost));
        const ShortStreamCosts fit = fit_short_stream_cycles(samples);
        CHECK(fit.one_lane[box] == Approx(30).epsilon(1e-6));
        CHECK(fit.few_lane[box] == Approx(few_cost).epsilon(1e-6));
        CHECK(fit.stream_per_op[box] == Approx(stream_cost).epsilon(1e-6));
        CHECK(short_stream_fit_error(fit, samples).second < 1e-9);
        // Given the few-ray loop's cost (another back end's), the stream loop still takes its
        // own from the rest.
        const GivenFewRayCosts given_few{few_cost, 0.0};
        const ShortStreamCosts given = fit_short_stream_cycles(samples, &given_few);
        CHECK(given.stream_per_op[box] == Approx(stream_cost).epsilon(1e-6));
        CHECK(given.one_lane[box] == Approx(30).epsilon(1e-6));
    }
}

TEST_CASE("The box test that enters a short loop from the stream loop carries its entry cost",
          "[host]") {
    OpProfile p;
    p.measured = true;
    p.cost.one_ray_entry_cycles = 25;
    p.cost.few_ray_entry_cycles = 260;
    CHECK(p.loop_entry_cycles(TraversalLoop::one_ray) == 25);
    CHECK(p.loop_entry_cycles(TraversalLoop::few_ray) == 260);
    CHECK(p.loop_entry_cycles(TraversalLoop::stream) == 0);
    p.measured = false;  // instruction-priced: no loops
    CHECK(p.loop_entry_cycles(TraversalLoop::few_ray) == 0);

    // In the machine model: a 16-lane box test passes one ray, whose stream enters the one-ray
    // loop (its first op carries the entry), and the op below it stays in that loop.
    auto time_chain = [](double entry) {
        OpCostConfig box = cost("box_test", 10, 4, 0, 0, 0);
        box.one_lane_cycles = 5;
        box.one_ray_entry_cycles = entry;
        SystemcTiming timing({host_with({box})}, shape());
        const std::vector<uint32_t> ids = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
        std::vector<uint8_t> first(16, 0), one = {1};
        first[0] = 1;
        TilePass pass;
        pass.slot_count = 64;
        timing.begin_pass(pass);
        for (uint32_t length : {16u, 1u, 1u}) {
            StreamOp op;
            op.kind = OpKind::box_test;
            op.stage = OpStage::traversal;
            op.length = length;
            op.pass_count = 1;
            op.slots = ids.data();
            op.passed = length == 16 ? first.data() : one.data();
            timing.op(op);
        }
        timing.end_pass(pass);
        return timing.timing(0);
    };
    const FrameTiming without = time_chain(0), with = time_chain(100);
    const auto busy = [](const FrameTiming& t) {
        return t.stages[0][size_t(OpStage::traversal)].busy_cycles;
    };
    CHECK(busy(without) == 10 + 4 + 5 + 5);
    CHECK(busy(with) == busy(without) + 100);  // one entry, not two
    CHECK(with.traversal_loop_cycles[size_t(TraversalLoop::one_ray)] ==
          without.traversal_loop_cycles[size_t(TraversalLoop::one_ray)] + 100);
}

TEST_CASE("The box test a traversal starts with carries the traversal's start cost", "[host]") {
    OpProfile p;
    p.measured = true;
    p.cost.traversal_start_cycles = 70;
    CHECK(p.traversal_start_cycles() == 70);
    p.measured = false;  // instruction-priced: no start cost
    CHECK(p.traversal_start_cycles() == 0);

    p.measured = true;
    p.cost.shared_origin_per_lane_cycles = 3;
    CHECK(p.shared_origin_cycles(16) == 45);  // the 15 lanes compared with the first
    CHECK(p.shared_origin_cycles(1) == 0);
    p.measured = false;
    CHECK(p.shared_origin_cycles(16) == 0);

    // In the machine model: two traversals of a 16-lane stream, each a box test at its entry and
    // one below it; each pays the start once, on its first op, and the first traversal's rays
    // share one origin: it pays the check of that per lane after the first.
    auto time_traversals = [](double start, double shared_origin = 0.0, double cold = 0.0) {
        OpCostConfig box = cost("box_test", 10, 4, 0, 0, 0);
        box.traversal_start_cycles = start;
        box.shared_origin_per_lane_cycles = shared_origin;
        box.cold_call_cycles = cold;
        SystemcTiming timing({host_with({box})}, shape());
        std::vector<uint32_t> ids(16);
        std::iota(ids.begin(), ids.end(), 0u);
        const std::vector<uint8_t> all(16, 1);
        TilePass pass;
        pass.slot_count = 64;
        timing.begin_pass(pass);
        for (int i = 0; i < 4; ++i) {
            const bool starts = i % 2 == 0;
            StreamOp op;
            op.origin_shared = i < 2;  // the first traversal's ops: only its start pays
            op.kind = OpKind::box_test;
            op.stage = OpStage::traversal;
            op.length = 16;
            op.pass_count = 16;
            op.slots = ids.data();
            op.passed = all.data();
            op.starts_traversal = starts;
            timing.op(op);
        }
        timing.end_pass(pass);
        return timing.timing(0).stages[0][size_t(OpStage::traversal)].busy_cycles;
    };
    CHECK(time_traversals(70) == time_traversals(0) + 2 * 70);
    CHECK(time_traversals(70, 2) == time_traversals(70) + 15 * 2);
    // A traversal's start cold (the box test's cold call): once a traversal too.
    CHECK(time_traversals(70, 0, 40) == time_traversals(70) + 2 * 40);
}

TEST_CASE("A host pays its fitted cost for each misprediction of its predictor",
          "[host][systemc][branch]") {
    // 400 one-ray box tests, passing at random: branches no predictor learns.
    auto time_random = [](const HwConfig& host) {
        SystemcTiming timing({host}, shape());
        std::mt19937 rng(3);
        const uint32_t id = 0;
        TilePass pass;
        pass.slot_count = 64;
        timing.begin_pass(pass);
        for (int i = 0; i < 400; ++i) {
            const uint8_t passed = rng() & 1;
            StreamOp op;
            op.kind = OpKind::box_test;
            op.stage = OpStage::traversal;
            op.object = uint32_t(rng() % 64);
            op.length = 1;
            op.pass_count = passed;
            op.slots = &id;
            op.passed = &passed;
            timing.op(op);
        }
        timing.end_pass(pass);
        return timing.timing(0);
    };
    OpCostConfig box = cost("box_test", 10, 4, 0, 0, 0);
    box.one_lane_cycles = 5;
    HwConfig host = host_with({box});
    CHECK(host.branch_predictor.kind == "none");  // not fitted: no branch priced
    const FrameTiming none = time_random(host);
    CHECK(none.branch_mispredictions == 0);
    host.branch_predictor.kind = "tage";
    host.branch_predictor.mispredict_cycles = 50;
    const FrameTiming tage = time_random(host);
    CHECK(tage.branch_mispredictions > 100);
    CHECK(tage.branch_cycles == 50 * tage.branch_mispredictions);
    const auto busy = [](const FrameTiming& t) {
        return t.stages[0][size_t(OpStage::traversal)].busy_cycles;
    };
    CHECK(busy(tage) == busy(none) + tage.branch_cycles);
    // Every op is a one-ray stream's: the one-ray loop's prediction holds them all.
    CHECK(tage.traversal_loop_branch_cycles[size_t(TraversalLoop::one_ray)] == tage.branch_cycles);
    CHECK(none.traversal_loop_branch_cycles[size_t(TraversalLoop::one_ray)] == 0);
    // A box test's misprediction at its loop's cost where one is fitted; another loop's
    // (negative: not fitted) leaves the pooled cost.
    host.branch_predictor.one_ray_mispredict_cycles = 80;
    host.branch_predictor.stream_mispredict_cycles = 5;
    const FrameTiming by_loop = time_random(host);
    CHECK(by_loop.branch_mispredictions == tage.branch_mispredictions);
    CHECK(by_loop.branch_cycles == 80 * by_loop.branch_mispredictions);
    host.branch_predictor.one_ray_mispredict_cycles = -1;
    CHECK(time_random(host).branch_cycles == tage.branch_cycles);
    host.branch_predictor.one_ray_mispredict_cycles = 0;  // a fitted 0 is a cost
    CHECK(time_random(host).branch_cycles == 0);
    CHECK(HwConfig().branch_predictor.kind == "none");  // the paper's machine: no branches
    // The unseen-ops predictor: each of the frame's 400 box tests once, whatever its outcome,
    // at its loop's cost.
    host.branch_predictor.kind = "unseen_ops";
    host.branch_predictor.one_ray_mispredict_cycles = 30;
    const FrameTiming unseen = time_random(host);
    CHECK(unseen.branch_mispredictions == 400);
    CHECK(unseen.branch_cycles == 30 * 400);
    CHECK(busy(unseen) == busy(none) + 30 * 400);
}

TEST_CASE("The machine model times a host: measured costs, scene data beyond the L1D",
          "[host][systemc]") {
    const HwConfig host = host_with({cost("box_test", 10, 4, 0, 0, 8)});
    // One box test of 20 lanes (groups of 16 and 4) on node 3, first touched: the line comes
    // from DRAM (81 ns at 1 GHz, then 64 bytes at 25.6 B/cycle: ready at cycle 84), less the
    // L1D hit the measured cost already holds (1): the unit waits 83 cycles, then issues
    // 10 + 4 and 4 cycles, and the first lane pays 8 for its traversal record, not yet in the
    // L1D (the other 19 lie in the same 4 KiB page). A second pass finds the node and the
    // records in the L1D: 18 cycles.
    const FrameTiming one = time_boxes(host, 1, 20);
    CHECK(one.cycles == 83 + 18 + 8);
    CHECK(one.stalls.scene_memory == 83);
    CHECK(one.stages[0][size_t(OpStage::traversal)].scene_memory_cycles == 83);
    CHECK(one.stages[0][size_t(OpStage::traversal)].busy_cycles == 18 + 8);
    // A 20-lane box test runs in the stream loop: its wait is that loop's.
    CHECK(one.traversal_loop_memory_cycles[size_t(TraversalLoop::stream)] == 83);
    CHECK(one.traversal_loop_memory_cycles[size_t(TraversalLoop::one_ray)] == 0);
    const FrameTiming two = time_boxes(host, 2, 20);
    CHECK(two.cycles == 83 + 18 + 8 + 18);
    CHECK(two.stalls.scene_memory == 83);
    // Compress partitions inside the groups: no partition pass, no partition stall.
    CHECK(two.stalls.partition == 0);
    CHECK(two.actions.busy_cycles[size_t(HwUnit::partition)] == 0);
    // Slots 64 apart: each lane's record opens a page, 20 * 8 = 160 the first time.
    CHECK(time_boxes(host, 1, 20, 4096, 3, 64).cycles == 83 + 18 + 160);

    // A one-ray stream costs its one-lane cost.
    HwConfig one_lane = host;
    for (OpCostConfig& c : one_lane.op_costs)
        if (c.op == "box_test") c.one_lane_cycles = 7;
    CHECK(time_boxes(one_lane, 2, 1).cycles == 83 + 7 + 7);
    // And a few-ray stream its few-lane cost.
    for (OpCostConfig& c : one_lane.op_costs)
        if (c.op == "box_test") c.few_lane_cycles = 9;
    CHECK(time_boxes(one_lane, 2, 3).cycles == 83 + 9 + 9);

    // A CPU core's short loops wait for the measured share of the 83 cycles
    // (node_read_exposed_share), the stream loop for all of them.
    for (OpCostConfig& c : one_lane.op_costs)
        if (c.op == "box_test") c.node_read_exposed_share = 0.25;
    const FrameTiming short_loop = time_boxes(one_lane, 1, 1);
    CHECK(short_loop.cycles == 21 + 7);
    CHECK(short_loop.traversal_loop_memory_cycles[size_t(TraversalLoop::one_ray)] == 21);
    CHECK(time_boxes(one_lane, 1, 3).cycles == 21 + 9);
    CHECK(time_boxes(one_lane, 1, 20).cycles == 83 + 18 + 8);
    // The line is still on its way when a second pass reads it at cycle 28: that one waits a
    // quarter of the rest, 14 cycles.
    CHECK(time_boxes(one_lane, 2, 1).cycles == 21 + 7 + 14 + 7);
}

TEST_CASE("A host's ray buffers share its caches with the scene data", "[host][systemc]") {
    // Per pass: a box test on node 3, then a shading op over 1024 lanes whose slots the core
    // reads through the same caches (storage l1d). Slots of 330 bytes (330 KiB) flush the
    // 32 KiB L1D and the 256 KiB L2, so the next pass's box test reads node 3 from DRAM again;
    // slots of 8 bytes (8 KiB) leave it in the L1D.
    auto time_with_slots = [](uint32_t slot_bytes) {
        HwConfig host = host_with({cost("box_test", 10, 4, 0, 0, 0)});
        host.ray_buffer.slot_bytes = slot_bytes;
        SystemcTiming timing({host}, shape());
        std::vector<uint32_t> ids(1024);
        for (uint32_t i = 0; i < 1024; ++i) ids[i] = i;
        const std::vector<uint8_t> all(1024, 1), none(1024, 0);
        for (int p = 0; p < 2; ++p) {
            TilePass pass;
            pass.slot_count = 1024;
            timing.begin_pass(pass);
            timing.op({OpKind::box_test, OpStage::traversal, 0, 3, 20, 20, ids.data(), all.data()});
            timing.op({OpKind::miss_filter, OpStage::shading, 0, k_no_object, 1024, 0, ids.data(),
                       none.data()});
            timing.end_pass(pass);
        }
        return timing.timing(0);
    };
    const FrameTiming fat = time_with_slots(330), thin = time_with_slots(8);
    CHECK(thin.stalls.scene_memory == 83);      // node 3 from DRAM once (the test above)
    CHECK(fat.stalls.scene_memory == 83 + 83);  // and again after the slots flushed it
    CHECK(fat.stages[0][size_t(OpStage::traversal)].scene_memory_cycles == 2 * 83);
}

TEST_CASE(
    "A lane pays for ray data beyond the L1D where its caches do not hold its line and it "
    "opens a page",
    "[host][systemc]") {
    // Box tests of 1024 lanes on slots 0-1023: their traversal records, 64 bytes each, fill
    // 64 KiB in 16 pages. At 8 cycles a paying lane and 4 a group (64 groups), a pass costs
    // 256 cycles, and 16 * 8 = 128 more wherever the L1D does not hold the records.
    auto passes = [](uint32_t l1d_kib, uint32_t count) {
        HwConfig host = host_with({cost("box_test", 0, 4, 0, 0, 8)});
        host.scene_memory.caches[0].kib = l1d_kib;
        return time_boxes(host, count, 1024, 1024).stages[0][size_t(OpStage::traversal)];
    };
    // A 32 KiB L1D holds half the records: each pass finds none of its lanes' lines (LRU
    // over a cycle longer than it), so every pass pays for its 16 pages.
    CHECK(passes(32, 2).busy_cycles == 2 * (256 + 128));
    // A 128 KiB L1D keeps them: only the first pass pays.
    CHECK(passes(128, 2).busy_cycles == 2 * 256 + 128);
    // The other 1008 lanes of such a pass are in a page the lane before opened, each on the
    // line after the lane before's: a lane that skips lines would pay 0.5 cycles more, these
    // pay nothing. On every other slot (1024 lines over 128 KiB, 32 pages) 992 lanes skip a
    // line each: 496 cycles more where the L1D does not hold their lines, nothing where it does.
    auto skipping = [](uint32_t l1d_kib, uint32_t stride) {
        OpCostConfig box = cost("box_test", 0, 4, 0, 0, 8);
        box.beyond_l1_skipping_per_lane_cycles = 0.5;
        HwConfig host = host_with({box});
        host.scene_memory.caches[0].kib = l1d_kib;
        return time_boxes(host, 2, 1024, 2048, 3, stride)
            .stages[0][size_t(OpStage::traversal)]
            .busy_cycles;
    };
    CHECK(skipping(32, 1) == 2 * (256 + 128));
    CHECK(skipping(32, 2) == 2 * (256 + 256 + 496));
    CHECK(skipping(128, 2) == 2 * 256 + 256 + 496);
    // A shading op reads its slot but the traversal record: 16 slots of 64 bytes lie in one
    // page, of 400 bytes (336 read) in two, so one lane more pays; of 330 bytes (266 read) the
    // 16 lanes all start in the first page.
    const HwConfig host = host_with({cost("emission_filter", 0, 0, 0, 0, 8)});
    HwConfig fat = host, tiny = host;
    fat.ray_buffer.slot_bytes = 400;
    tiny.ray_buffer.slot_bytes = 330;
    CHECK(time_surfaces(tiny).cycles == time_surfaces(host).cycles);
    CHECK(time_surfaces(fat).cycles == time_surfaces(host).cycles + 8);
    // The 336 bytes in 7 arrays of 48 bytes a slot: the 16 slots lie in one page of each.
    HwConfig arrays = fat;
    arrays.ray_buffer.slot_arrays = 7;
    CHECK(time_surfaces(arrays).cycles == time_surfaces(host).cycles);
}

TEST_CASE("A lane beyond the L2 as well pays for both levels where it opens a page",
          "[host][systemc]") {
    // The box tests above (1024 records, 64 KiB in 16 pages) at 8 cycles a paying lane beyond
    // the L1D and 5 more beyond the L2.
    auto passes = [](uint32_t l2_kib) {
        OpCostConfig box = cost("box_test", 0, 4, 0, 0, 8);
        box.beyond_l2_per_lane_cycles = 5;
        HwConfig host = host_with({box});
        host.scene_memory.caches[0].kib = 16;
        host.scene_memory.caches[1].kib = l2_kib;
        return time_boxes(host, 2, 1024, 1024).stages[0][size_t(OpStage::traversal)].busy_cycles;
    };
    // A 32 KiB L2 holds half the records: both passes pay for both levels.
    CHECK(passes(32) == 2 * (256 + 16 * (8 + 5)));
    // A 128 KiB L2 keeps them: the second pass pays for the L1D only.
    CHECK(passes(128) == 2 * 256 + 16 * (8 + 5) + 16 * 8);
}

TEST_CASE("A lane that opens a page beyond the DTLB's reach pays for it, in the L1D or not",
          "[host][systemc]") {
    // The box tests above (1024 records in 16 pages, 4 cycles a group, 64 groups) in passes of
    // 1024 slots of 330 bytes (330 KiB), 10 cycles a lane that opens a page beyond a DTLB of
    // `dtlb_pages`: of 16 pages, 64 KiB of the 330 are in its reach, and 16 lanes open a page.
    auto passes = [](uint32_t l1d_kib, uint32_t dtlb_pages) {
        OpCostConfig box = cost("box_test", 0, 4, 0, 0, 8);
        box.beyond_tlb_per_lane_cycles = 10;
        HwConfig host = host_with({box});
        host.scene_memory.caches[0].kib = l1d_kib;
        host.ray_buffer.slot_bytes = 330;
        host.ray_buffer.dtlb_pages = dtlb_pages;
        return time_boxes(host, 2, 1024, 1024).stages[0][size_t(OpStage::traversal)].busy_cycles;
    };
    const double beyond = 1.0 - 64.0 / 330.0;
    CHECK(beyond_tlb_fraction(1024, 330, 16) == Approx(beyond));
    // Not modelled, or a reach over the pass's 330 KiB: the L1D's terms alone (128 KiB holds
    // the records after the first pass).
    CHECK(passes(128, 0) == 2 * 256 + 128);
    CHECK(passes(128, 128) == 2 * 256 + 128);
    // Beyond it, both passes pay for their 16 lanes, though the L1D holds the second's lines.
    CHECK(double(passes(128, 16)) == Approx(2 * 256 + 128 + 2 * 16 * 10 * beyond).margin(1));
    CHECK(double(passes(32, 16)) == Approx(2 * (256 + 128) + 2 * 16 * 10 * beyond).margin(1));
    // The fit's share of a random stream: the lanes expected to open a page, times that share.
    CHECK(beyond_tlb_share(100, 1024, 330, 48, 16) ==
          Approx(beyond * expected_lanes_opening_pages(100, 1024, 48) / 100));
    CHECK(beyond_tlb_share(100, 1024, 330, 48, 0) == 0.0);
    CHECK(beyond_tlb_share(100, 256, 330, 48, 96) == 0.0);  // 83 KiB: within 96 pages
}

TEST_CASE("The set-up of the rays an op makes leaves their traversal records in the caches",
          "[host][systemc]") {
    // A shading op over slots 0-1023, then a box test over them (their records: 16 pages of
    // 64 KiB). After an op that makes the rays, whose set-up writes the records, the box test
    // finds them in a 128 KiB L1D; after one that makes none it pays 8 cycles for each page.
    auto box_after = [](OpKind shading) {
        HwConfig host = host_with({cost("box_test", 0, 4, 0, 0, 8)});
        host.scene_memory.caches[0].kib = 128;
        host.ray_buffer.slot_bytes = 330;
        SystemcTiming timing({host}, shape());
        std::vector<uint32_t> ids(1024);
        for (uint32_t i = 0; i < 1024; ++i) ids[i] = i;
        const std::vector<uint8_t> passed(1024, 1);
        TilePass pass;
        pass.slot_count = 1024;
        timing.begin_pass(pass);
        timing.op(
            {shading, OpStage::shading, 0, k_no_object, 1024, 1024, ids.data(), passed.data()});
        timing.op(
            {OpKind::box_test, OpStage::traversal, 1, 3, 1024, 1024, ids.data(), passed.data()});
        timing.end_pass(pass);
        return timing.timing(0).stages[1][size_t(OpStage::traversal)].busy_cycles;
    };
    CHECK(box_after(OpKind::lambertian_indirect) == 64 * 4);
    CHECK(box_after(OpKind::emission_filter) == 64 * 4 + 16 * 8);
}

TEST_CASE("Each host knob moves the prediction the way it should", "[host][systemc]") {
    const HwConfig base = host_with({cost("box_test", 10, 4, 1, 0, 8)});
    const uint64_t cycles = time_boxes(base, 3, 40, 4096).cycles;
    auto with = [&](auto change) {
        HwConfig c = base;
        change(c);
        return time_boxes(c, 3, 40, 4096).cycles;
    };
    CHECK(with([](HwConfig& c) { c.scene_memory.dram_latency_ns = 200; }) > cycles);
    CHECK(with([](HwConfig& c) { c.op_costs[0].per_lane_cycles = 2; }) > cycles);
    CHECK(with([](HwConfig& c) { c.simd.width = 8; }) > cycles);  // more groups
    CHECK(with([](HwConfig& c) { c.scene_memory.caches[0].hit_latency_ns = 3; }) < cycles);
}

TEST_CASE("A host needs a measured cost for every kind its workload runs", "[host]") {
    HwConfig host = host_hw_config(small_host(), {cost("box_test", 1, 1, 1, 0, 0)});
    CHECK_THROWS_WITH(SystemcTiming({host}, shape()), Catch::Contains("op_costs") &&
                                                          Catch::Contains("no measured cost"));
    CHECK_THROWS_WITH(check_machine_model_config(host_hw_config(small_host(), {})),
                      Catch::Contains("needs measured op costs"));
    HwConfig banked;  // gr08 with measured costs: the gathers would be priced twice
    banked.op_costs = {cost("box_test", 1, 1, 1, 0, 0)};
    CHECK_THROWS_WITH(check_machine_model_config(banked), Catch::Contains("storage l1d"));
    CHECK_NOTHROW(check_machine_model_config(host_with({})));
}

TEST_CASE("host.hw.yaml reads back with its host knobs", "[host]") {
    OpCostConfig box = cost("box_test", 1, 2, 3, 4, 5);
    box.beyond_l2_per_lane_cycles = 6.5;
    box.beyond_l1_skipping_per_lane_cycles = 0.75;
    box.beyond_tlb_per_lane_cycles = 2.25;
    box.one_lane_cycles = 6;
    box.few_lane_cycles = 4.5;
    box.per_minority_lane_cycles = 7;
    box.one_ray_entry_cycles = 8;
    box.few_ray_entry_cycles = 9.5;
    box.traversal_start_cycles = 41.25;
    box.cold_call_cycles = 77.5;
    box.node_read_exposed_share = 0.375;
    HostDescription host = small_host();
    host.slot_arrays = 7;
    host.dtlb = {{{8, 3.9}, {96, 3.9}, {104, 7.4}, {112, 9.1}}, 96};
    host.caches.push_back({3, "unified", 32768, 64, 16, true, "test"});
    host.latency_ns = {1.0, 5.0, 15.5, 81.0};
    host.last_level_chases = {{512, 15.5}, {1024, 16.0}, {2048, 98.4}, {4096, 130.5}};
    host.last_level_idle_chases = {{100.0, 15.5}, {1000.0, 140.0}};
    host.dram_span_latencies = {{2, 78.5}, {16, 155.5}, {256, 294.2}};
    host.pair_fill = {21.5, 148.0};  // the odd lines came from the L3: pairs
    host.branch_predictor.kind = "tage";
    host.branch_predictor.mispredict_cycles = 61.5;
    host.branch_predictor.one_ray_mispredict_cycles = 72.5;
    host.branch_predictor.stream_mispredict_cycles = 0;
    host.branch_predictor_fit = "test batches";
    const std::string yaml = host_hw_yaml(host, {box}, "test samples");
    const SeenLevel seen = last_level_seen(host);
    REQUIRE(seen.foreign_fill_per_us > 0.0);
    CHECK(yaml.find("kib: " + std::to_string(seen.kib) + ",") != std::string::npos);
    CHECK(yaml.find("cpuid: 32768 KiB") != std::string::npos);
    CHECK(yaml.find("chases over 0.5 MiB 15.5 ns, 1 MiB 16.0 ns, 2 MiB 98.4 ns, 4 MiB 130.5 ns; "
                    "over 0.5 MiB with steps of 100 ns 15.5 ns, 1000 ns 140.0 ns") !=
          std::string::npos);
    const HwConfig c = parse_hw_config(yaml, "host.hw.yaml");
    CHECK(c.ray_buffer.storage == "l1d");
    CHECK(c.ray_buffer.kib == 32);
    CHECK(c.ray_buffer.slot_arrays == 7);
    CHECK(c.partition.kind == "compress");
    CHECK(c.simd.width == 16);
    CHECK(c.simd.units == 1);
    CHECK(c.clock.core_mhz == Approx(1000));
    REQUIRE(c.scene_memory.caches.size() == 3);
    CHECK(c.scene_memory.caches[1].hit_latency_ns == Approx(5));
    CHECK(c.scene_memory.caches[2].kib == seen.kib);
    CHECK(c.scene_memory.caches[2].hit_latency_ns == Approx(15.5));
    CHECK(c.scene_memory.caches[2].foreign_fill_per_us ==
          Approx(seen.foreign_fill_per_us).epsilon(0.01));
    CHECK(c.scene_memory.caches[2].pair_fill);
    CHECK_FALSE(c.scene_memory.caches[1].pair_fill);
    CHECK(yaml.find("even lines 21.5 ns a load, from DRAM 148.0 ns") != std::string::npos);
    HostDescription unpaired = host;
    unpaired.pair_fill = {120.0, 148.0};  // the odd lines came from DRAM
    CHECK_FALSE(parse_hw_config(host_hw_yaml(unpaired, {box}, ""), "host.hw.yaml")
                    .scene_memory.caches[2]
                    .pair_fill);
    CHECK(c.scene_memory.dram_latency_ns == Approx(81));
    REQUIRE(c.scene_memory.dram_latency_by_span.size() == 3);
    CHECK(c.scene_memory.dram_latency_by_span[1].span_mib == Approx(16));
    CHECK(c.scene_memory.dram_latency_by_span[1].latency_ns == Approx(155.5));
    CHECK(yaml.find("first pass of a random chase") != std::string::npos);
    REQUIRE(c.op_costs.size() == 1);
    CHECK(c.op_costs[0].beyond_l1_per_lane_cycles == Approx(5));
    CHECK(c.op_costs[0].beyond_l2_per_lane_cycles == Approx(6.5));
    CHECK(c.op_costs[0].beyond_l1_skipping_per_lane_cycles == Approx(0.75));
    CHECK(c.op_costs[0].beyond_tlb_per_lane_cycles == Approx(2.25));
    CHECK(c.ray_buffer.dtlb_pages == 96);
    CHECK(yaml.find("3.9 TSC ticks a load at 8 pages, 3.9 at 96, 7.4 at 104") != std::string::npos);
    CHECK(c.op_costs[0].one_lane_cycles == Approx(6));
    CHECK(c.op_costs[0].few_lane_cycles == Approx(4.5));
    CHECK(c.op_costs[0].per_minority_lane_cycles == Approx(7));
    CHECK(c.op_costs[0].one_ray_entry_cycles == Approx(8));
    CHECK(c.op_costs[0].few_ray_entry_cycles == Approx(9.5));
    CHECK(c.op_costs[0].traversal_start_cycles == Approx(41.25));
    CHECK(c.op_costs[0].cold_call_cycles == Approx(77.5));
    CHECK(c.op_costs[0].node_read_exposed_share == Approx(0.375));
    CHECK(c.branch_predictor.kind == "tage");
    CHECK(c.branch_predictor.mispredict_cycles == Approx(61.5));
    CHECK(c.branch_predictor.one_ray_mispredict_cycles == Approx(72.5));
    CHECK(c.branch_predictor.few_ray_mispredict_cycles == -1);  // not fitted: not written
    CHECK(c.branch_predictor.stream_mispredict_cycles == 0);
    CHECK(yaml.find("few_ray_mispredict_cycles") == std::string::npos);
    CHECK(yaml.find("fitted: test batches") != std::string::npos);
    // The few-ray loop's costs taken from another back end's file: the file says whose.
    HostDescription taken = host;
    taken.branch_predictor.few_ray_mispredict_cycles = 88.5;
    taken.few_ray_source = "host-avx2.hw.yaml";
    const std::string taken_yaml = host_hw_yaml(taken, {box}, "");
    CHECK(parse_hw_config(taken_yaml, "host.hw.yaml").branch_predictor.few_ray_mispredict_cycles ==
          Approx(88.5));
    CHECK(taken_yaml.find("few_ray_mispredict_cycles: 88.5  # as host-avx2.hw.yaml gives it") !=
          std::string::npos);
    CHECK(host_hw_yaml(small_host(), {box}, "").find("branch_predictor") == std::string::npos);
    // A host file written before one-lane costs were measured: the formula for every op.
    CHECK(parse_hw_config("version: 1\nop_costs:\n  - {op: box_test, per_op_cycles: 3}\n",
                          "old.hw.yaml")
              .op_costs[0]
              .one_lane_cycles < 0);
    // And before the short loops' node reads were: each waits for its node.
    CHECK(parse_hw_config("version: 1\nop_costs:\n  - {op: box_test, per_op_cycles: 3}\n",
                          "old.hw.yaml")
              .op_costs[0]
              .node_read_exposed_share == 1.0);
    CHECK_THROWS_AS(parse_hw_config("version: 1\nop_costs:\n  - {op: box_test, "
                                    "node_read_exposed_share: 1.5}\n",
                                    "bad.hw.yaml"),
                    InputError);
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

TEST_CASE("The last level's size and others' fills come from this core's chases", "[host]") {
    HostDescription host = small_host();  // L2 of 256 KiB at 5 ns
    host.caches.push_back({3, "unified", 520192, 64, 16, true, "test"});
    host.latency_ns = {1.0, 5.0, 16.0, 180.0};
    // No chases: cpuid's size, the level's latency, no others' fills.
    SeenLevel seen = last_level_seen(host);
    CHECK(seen.kib == 520192);
    CHECK(seen.latency_ns == Approx(16));
    CHECK(seen.foreign_fill_per_us == 0.0);
    CHECK_FALSE(seen.cut);
    // Chases that lose their lines between 6400 and 7744 KiB (the midpoint of 16 and 144 ns
    // halfway, in log size, at 7040 KiB), and over 2 MiB with steps of 300 ns.
    host.last_level_chases = {
        {2048, 16.0}, {4096, 16.0}, {6400, 16.0}, {7744, 144.0}, {16384, 144.0}};
    host.last_level_idle_chases = {{100.0, 16.0}, {250.0, 16.0}, {360.0, 144.0}, {1000.0, 144.0}};
    seen = last_level_seen(host);
    CHECK(seen.latency_ns == Approx(16));
    CHECK(seen.cut);
    // Both crossings sit on the LRU stack's edge: S (1 + r t) = C, the size chase's with steps
    // of the level's latency, the spaced-out chase's (2 MiB: 32768 lines) with steps of 300 ns.
    const double r = seen.foreign_fill_per_us / 1000.0, lines = seen.kib * 1024.0 / 64;
    CHECK(7040.0 * 16 * (1 + r * 16) == Approx(lines).epsilon(1e-3));
    CHECK(32768.0 * (1 + r * 300) == Approx(lines).epsilon(1e-3));
    CHECK(r > 0.0);
    // One interrupted spaced-out chase, far slower than an evicted line, moves nothing.
    host.last_level_idle_chases.push_back({2000.0, 600.0});
    CHECK(last_level_seen(host).kib == seen.kib);
    CHECK(last_level_seen(host).foreign_fill_per_us == seen.foreign_fill_per_us);
    host.last_level_idle_chases.pop_back();
    HwConfig c = host_hw_config(host, {});
    CHECK(c.scene_memory.caches.back().kib == seen.kib);
    CHECK(c.scene_memory.caches.back().foreign_fill_per_us == seen.foreign_fill_per_us);
    CHECK(c.scene_memory.caches.back().hit_latency_ns == Approx(16));
    CHECK(c.scene_memory.dram_latency_ns == Approx(180));
    // Spacing the loads out loses nothing the size did not: the level ends at the size's
    // crossing, with no others' fills.
    host.last_level_idle_chases = {{100.0, 16.0}, {1000.0, 17.0}};
    seen = last_level_seen(host);
    CHECK(seen.kib == 7040);
    CHECK(seen.foreign_fill_per_us == 0.0);
    // Every size chase kept its lines and only spacing lost them: an evicted line reads as
    // the three most spaced-out chases' median, so the level is at least the largest chase
    // and others fill it.
    host.last_level_chases = {{2048, 16.0}, {16384, 17.0}};
    host.last_level_idle_chases = {
        {100.0, 16.0}, {1000.0, 140.0}, {2000.0, 144.0}, {4000.0, 900.0}};
    seen = last_level_seen(host);
    CHECK(seen.kib == 16384);
    CHECK(seen.foreign_fill_per_us > 0.0);
    // No chase ever slower than twice the first: nothing is lost, cpuid's size.
    host.last_level_chases = {{2048, 16.0}, {4096, 20.0}, {8192, 30.0}, {16384, 31.9}};
    host.last_level_idle_chases.clear();
    seen = last_level_seen(host);
    CHECK(seen.kib == 520192);
    CHECK_FALSE(seen.cut);
    CHECK(seen.foreign_fill_per_us == 0.0);
    // A 20-way level (the Intel Xeon VM's, family 6 model 0xCF): the size its chases cross at
    // is rounded to whole sets, which the model's cache is built from.
    host.caches.back() = {3, "unified", 266240, 64, 20, true, "test"};
    host.last_level_chases = {
        {2048, 16.0}, {4096, 16.0}, {6400, 16.0}, {7744, 144.0}, {16384, 144.0}};
    host.last_level_idle_chases = {{100.0, 16.0}, {1000.0, 17.0}};
    seen = last_level_seen(host);
    CHECK(seen.kib == 7040);  // 5632 sets
    host.last_level_chases = {
        {2048, 16.0}, {4096, 16.0}, {6400, 16.0}, {7900, 144.0}, {16384, 144.0}};
    CHECK(last_level_seen(host).kib % 5 == 0);
    CHECK_NOTHROW(SetAssociativeCache(host_hw_config(host, {}).scene_memory.caches.back()));
}

TEST_CASE("A level's latency is chased over twice the level before it, not half its own",
          "[host]") {
    auto level = [](uint32_t kib) {
        HostCacheLevel l;
        l.kib = kib;
        return l;
    };
    // An AMD Zen 5 core: 48 KiB L1D, 1 MiB L2 (which loses lines well below its size), L3.
    const std::vector<HostCacheLevel> zen5 = {level(48), level(1024), level(32768)};
    CHECK(latency_chase_kib(zen5, 0) == 24);
    CHECK(latency_chase_kib(zen5, 1) == 96);
    CHECK(latency_chase_kib(zen5, 2) == 2048);  // as the last level's first chase
    // A level behind one more than a quarter its size: at most half its own.
    CHECK(latency_chase_kib({level(64), level(192)}, 1) == 96);
}

TEST_CASE("The host's caches and clock are read from the CPU", "[host]") {
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
    // A description whose memory comes from another file measures none: no chases.
    const HostDescription h = describe_host(1, "scalar", false);
    CHECK(h.caches.size() == caches.size());
    CHECK(h.core_mhz > 0.0);
    CHECK(h.latency_ns.empty());
    CHECK(h.last_level_chases.empty());
    CHECK(h.last_level_idle_chases.empty());
}

TEST_CASE("The host's microarchitecture: vendor, family and model from cpuid", "[host]") {
    // Known leaf-1 signatures: AMD EPYC 7B12 (Zen 2, family 0x17 model 0x31), an Intel Xeon
    // Skylake-SP (family 6 model 0x55), an Ice Lake-SP (family 6 model 0x6A), Zen 4 (0x19 0x11).
    CpuSignature s = decode_cpu_signature(0x00830F10);
    CHECK(s.family == 0x17);
    CHECK(s.model == 0x31);
    CHECK(s.stepping == 0);
    s = decode_cpu_signature(0x00050654);
    CHECK(s.family == 6);
    CHECK(s.model == 0x55);
    CHECK(s.stepping == 4);
    s = decode_cpu_signature(0x000606A6);
    CHECK(s.family == 6);
    CHECK(s.model == 0x6A);
    s = decode_cpu_signature(0x00A10F11);
    CHECK(s.family == 0x19);
    CHECK(s.model == 0x11);
    CHECK(vendor_short_name("AuthenticAMD") == "amd");
    CHECK(vendor_short_name("GenuineIntel") == "intel");
    CHECK(vendor_short_name("Hygon Genuine") == "hygongenuine");
    // This CPU: a vendor every x86-64 CPU gives, and the host file names it.
    const Microarchitecture m = read_microarchitecture();
    CHECK(m.vendor.size() == 12);
    CHECK(m.signature.family > 0);
    HostDescription h = small_host();
    h.microarchitecture = m;
    CHECK_THAT(host_hw_yaml(h, {}, "test"),
               Catch::Contains("# Microarchitecture (cpuid): " + m.vendor + " family 0x"));
}

TEST_CASE("A host file can take its scene memory from another of the same machine", "[host]") {
    HostDescription h = small_host();
    const HwConfig own = host_hw_config(h, {});
    h.memory = own.scene_memory;
    h.memory.caches.back().kib = 12288;
    h.memory.caches.back().foreign_fill_per_us = 3.5;
    h.memory.dram_latency_ns = 150;
    h.memory.dram_latency_by_span = {{4, 90.0}, {64, 180.0}};
    h.memory_source = "out/host-scalar.hw.yaml";
    const HwConfig c = host_hw_config(h, {});
    CHECK(c.scene_memory.caches.back().kib == 12288);
    CHECK(c.scene_memory.caches.back().foreign_fill_per_us == 3.5);
    CHECK(c.scene_memory.dram_latency_ns == 150);
    CHECK(c.clock.core_mhz == own.clock.core_mhz);  // the rest is this description's
    CHECK(c.simd.width == own.simd.width);
    // The file says where its memory came from, on every level, and reads back the same.
    const std::string yaml = host_hw_yaml(h, {}, "test");
    CHECK_THAT(yaml, Catch::Contains("foreign_fill_per_us: 3.50}  # as out/host-scalar.hw.yaml "
                                     "describes it"));
    CHECK_THAT(yaml, Catch::Contains("dram_latency_ns: 150.00  # as out/host-scalar.hw.yaml"));
    CHECK_THAT(yaml, !Catch::Contains("pointer chase"));
    const HwConfig back = parse_hw_config(yaml, "host.hw.yaml");
    REQUIRE(back.scene_memory.caches.size() == c.scene_memory.caches.size());
    CHECK(back.scene_memory.caches.back().kib == 12288);
    CHECK(back.scene_memory.dram_latency_ns == Approx(150));
    REQUIRE(back.scene_memory.dram_latency_by_span.size() == 2);
    CHECK(back.scene_memory.dram_latency_by_span[1].latency_ns == Approx(180));
}

TEST_CASE("DRAM's latency is measured by span, from the first pass after the caches are evicted",
          "[host]") {
    // A read from DRAM takes tens of nanoseconds at least; an L1D or L2 hit, which a chase
    // whose caches were not evicted would time, takes a few.
    const double tsc_mhz = measure_tsc_mhz();
    const double ns = measure_dram_first_pass_ns(uint64_t(2) << 20, tsc_mhz, 1);
    CHECK(ns > 20.0);
    CHECK(ns < 5000.0);
}

TEST_CASE("The DTLB's reach is where a chase of one line a page steps up for good", "[host]") {
    // A step at 104 pages; a lone slow count before it (a descheduled run) is not one.
    CHECK(dtlb_reach(
              {{8, 3.9}, {16, 3.9}, {24, 6.0}, {32, 3.9}, {96, 4.0}, {104, 7.4}, {112, 9.1}}) ==
          96);
    CHECK(dtlb_reach({{8, 3.9}, {16, 4.1}, {512, 4.2}}) == 0);  // no step
    CHECK(dtlb_reach({}) == 0);
    // On this host: 8 to 256 pages by 8, each a load's ticks; a reach, if any, among them.
    const DtlbReading r = measure_dtlb_pages(256);
    REQUIRE(r.chases.size() == 32);
    CHECK(r.chases.front().first == 8);
    CHECK(r.chases.back().first == 256);
    for (const auto& [pages, ticks] : r.chases) CHECK(ticks > 0.0);
    CHECK(r.pages == dtlb_reach(r.chases));
    CHECK(r.pages < 256);
}

TEST_CASE("A stream's lanes pay for slots beyond the L1D only where they open a page", "[host]") {
    // Slots of 1,000 bytes: slots 0-4 start in page 0, 5-8 in page 1, 9-12 in page 2.
    const std::vector<uint32_t> dense = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    CHECK(lanes_opening_pages(dense.data(), 0, 10, 1000) == 3);
    CHECK(lanes_opening_pages(dense.data(), 0, 5, 1000) == 1);  // the stream's first lane
    CHECK(lanes_opening_pages(dense.data(), 5, 5, 1000) == 2);  // slot 5 opens page 1
    CHECK(lanes_opening_pages(dense.data(), 6, 3, 1000) == 0);  // 6-8: page 1, after slot 5
    const std::vector<uint32_t> sparse = {0, 9, 33, 34, 200};
    CHECK(lanes_opening_pages(sparse.data(), 0, 5, 1000) == 4);  // 33 and 34: page 8

    // Expected of random streams: every page of a full stream, every lane of a one-lane one,
    // and in between the pages' share touched (one page of k slots: 1 - C(S - k, n) / C(S, n)).
    CHECK(expected_lanes_opening_pages(4096, 4096, 330) ==
          Approx(4096.0 * 330 / 4096).epsilon(0.01));
    CHECK(expected_lanes_opening_pages(1, 4096, 330) == Approx(1.0));
    CHECK(expected_lanes_opening_pages(2, 4, 2048) == Approx(2 * (1.0 - 1.0 / 6.0)));
    CHECK(expected_lanes_opening_pages(0, 64, 330) == 0.0);
    // The share that pays: none within the L1D; beyond it, nearly every lane of a sparse
    // stream and about one in twelve of a dense one (a shading op: slots of 330 bytes).
    CHECK(beyond_cache_share(64, 64, 330, 330, 48) == 0.0);
    const double f = beyond_cache_fraction(4096, 330, 48);
    CHECK(beyond_cache_share(16, 4096, 330, 330, 48) == Approx(f).epsilon(0.03));
    CHECK(beyond_cache_share(4096, 4096, 330, 330, 48) == Approx(f * 330 / 4096).epsilon(0.02));
    // A box test reads the traversal records, 64 to a page: a dense stream opens one page in
    // 64 lanes, a sparse one of 16 lanes in 4096 slots (64 pages) still nearly every lane.
    CHECK(lane_ray_bytes(OpStage::traversal, 330) == 64);
    CHECK(lane_ray_bytes(OpStage::intersection, 330) == 64);
    CHECK(lane_ray_bytes(OpStage::shading, 330) == 330 - 64);  // the record is the traversal's
    CHECK(beyond_cache_share(4096, 4096, 330, 64, 48) == Approx(f / 64).epsilon(0.01));
    CHECK(beyond_cache_share(16, 4096, 330, 64, 48) == Approx(f * 14.3 / 16).epsilon(0.03));
    // A shading lane's 266 bytes in 7 arrays of 38: a dense stream opens a page of one about
    // once in 108 lanes, a seventh as often as a page of one array of 266 bytes; 16 random
    // lanes of 4096 slots (38 pages of 108) still open 13.2 pages (37.9 (1 - (1 - 108 /
    // 4096)^16)), against 15.6 pages of one array of 266 bytes.
    CHECK(lane_page_bytes(OpStage::traversal, 330, 7) == 64);
    CHECK(lane_page_bytes(OpStage::shading, 330, 1) == 266);
    CHECK(lane_page_bytes(OpStage::shading, 330, 7) == 38);
    CHECK(beyond_cache_share(4096, 4096, 330, 38, 48) == Approx(f * 38 / 4096).epsilon(0.02));
    CHECK(beyond_cache_share(16, 4096, 330, 38, 48) == Approx(f * 13.2 / 16).epsilon(0.02));
    // Of the rest, in a page the lane before opened, those that skip lines past the lane
    // before's: none of a stream of every slot (38 bytes a slot: the next slot starts on the
    // same line or the next), every lane on every third slot of 64-byte records, nearly all of
    // a sparse stream's lanes in an opened page; none within the L1D.
    const std::vector<uint32_t> thirds = {0, 3, 6, 9};
    CHECK_FALSE(lane_skips_lines(thirds.data(), 0, 64));  // the first lane opens the page
    CHECK(lane_skips_lines(thirds.data(), 1, 64));        // line 3 after line 0
    CHECK_FALSE(lane_skips_lines(dense.data(), 1, 38));   // bytes 38-75 after 0-37
    CHECK_FALSE(lane_skips_lines(dense.data(), 2, 64));   // line 2 after line 1
    CHECK(expected_lanes_skipping_lines(4096, 4096, 38) == 0.0);
    CHECK(expected_lanes_skipping_lines(1, 4096, 38) == 0.0);
    CHECK(beyond_cache_skipping_share(4096, 4096, 330, 38, 48) == 0.0);
    // 16 random lanes of 4096 slots: 16 - 13.2 in an opened page, their lane before about 270
    // slots back: nearly all skip (some 7 % of them lie within two slots of it).
    CHECK(beyond_cache_skipping_share(16, 4096, 330, 38, 48) ==
          Approx(f * (16 - 13.2) / 16).epsilon(0.1));
    // 1024 of 4096 (the lane before 1 to 3 slots back in 58 % of lanes, 38 to 114 bytes, the
    // next line mostly): about 40 % skip, fewer than are in an opened page.
    const double quarter = expected_lanes_skipping_lines(1024, 4096, 38) / 1024;
    CHECK(quarter == Approx(0.405).epsilon(0.02));
    CHECK(quarter < 1.0 - expected_lanes_opening_pages(1024, 4096, 38) / 1024);
    CHECK(beyond_cache_skipping_share(64, 64, 330, 38, 48) == 0.0);
    CHECK(beyond_cache_skipping_share(0, 64, 330, 38, 48) == 0.0);
    // A stream's lanes beyond the L1D open a page, skip lines in an opened one, or neither.
    for (const uint32_t lanes : {1u, 16u, 200u, 1024u})
        CHECK(beyond_cache_share(lanes, 1024, 330, 38, 48) +
                  beyond_cache_skipping_share(lanes, 1024, 330, 38, 48) <=
              beyond_cache_fraction(1024, 330, 48) + 1e-12);
}

TEST_CASE("A filter's branch misses the rarer outcome's lanes, or one a change of outcome in runs",
          "[host]") {
    // No order (alternating): every change is a lane of the rarer outcome or a neighbour's.
    const uint8_t alternating[8] = {1, 0, 1, 0, 0, 0, 1, 0};
    CHECK(outcome_changes(alternating, 8) == 5);
    CHECK(mispredicted_lanes(3, 8, outcome_changes(alternating, 8)) == 3);
    // Runs: a block of passing lanes, then failing ones, costs one change, however many pass.
    const uint8_t runs[8] = {1, 1, 1, 1, 0, 0, 0, 0};
    CHECK(outcome_changes(runs, 8) == 1);
    CHECK(mispredicted_lanes(4, 8, outcome_changes(runs, 8)) == 1);
    // All alike: nothing to miss either way.
    const uint8_t same[4] = {1, 1, 1, 1};
    CHECK(outcome_changes(same, 4) == 0);
    CHECK(mispredicted_lanes(4, 4, 0) == 0);
    CHECK(outcome_changes(same, 0) == 0);
    // Without the lanes' order, the rarer outcome's (the closed form's counts-only traces).
    CHECK(mispredicted_lanes(3, 8, 8) == 3);
}

TEST_CASE("A CPU core's material filters after a generation's first cost nothing: its tracer "
          "sorted their lanes at the first",
          "[host][systemc]") {
    CHECK(placed_by_material_sort(OpKind::material_filter, OpKind::lambertian_direct));
    CHECK_FALSE(placed_by_material_sort(OpKind::material_filter, OpKind::depth_filter));
    CHECK_FALSE(placed_by_material_sort(OpKind::lambertian_choice, OpKind::material_filter));
    const HwConfig host = host_with({cost("material_filter", 10, 4, 1, 0, 0),
                                     cost("lambertian_choice", 10, 4, 1, 0, 0),
                                     cost("depth_filter", 10, 4, 1, 0, 0)});
    std::vector<uint32_t> ids(16);
    for (uint32_t i = 0; i < 16; ++i) ids[i] = i;
    const std::vector<uint8_t> all(16, 1), half = {1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};
    // The depth filter, then the first material's filter (the sort), its stack's op and, with
    // `second`, the next material's filter over what is left; `first` drops the first filter.
    auto ops = [&](bool first, bool second) {
        std::vector<StreamOp> o = {
            {OpKind::depth_filter, OpStage::shading, 0, k_no_object, 16, 16, ids.data(), all.data()}};
        if (first)
            o.push_back({OpKind::material_filter, OpStage::shading, 0, 0, 16, 8, ids.data(),
                         half.data()});
        o.push_back(
            {OpKind::lambertian_choice, OpStage::shading, 0, k_no_object, 8, 8, ids.data(), all.data()});
        if (second)
            o.push_back({OpKind::material_filter, OpStage::shading, 0, 1, 8, 4, ids.data() + 8,
                         half.data()});
        return o;
    };
    auto cycle_level = [&](const std::vector<StreamOp>& o) { return cycle_level_cycles(host, o); };
    auto closed_form = [&](const std::vector<StreamOp>& o) { return closed_form_cycles(host, o); };
    for (auto timed : {std::function<uint64_t(const std::vector<StreamOp>&)>(cycle_level),
                       std::function<uint64_t(const std::vector<StreamOp>&)>(closed_form)}) {
        // The first filter is priced over its lanes (10 + 4 + 16: one group of 16 lanes), and
        // waits for its material's record...
        CHECK(timed(ops(true, false)) >= timed(ops(false, false)) + 10 + 4 + 16);
        // ... the second is placed by the sort and adds nothing.
        CHECK(timed(ops(true, true)) == timed(ops(true, false)));
    }
}

TEST_CASE(
    "Both timing models charge a shading filter's call cold once, none to a material filter "
    "the sort placed",
    "[host][systemc]") {
    auto host = [](double cold) {
        std::vector<OpCostConfig> costs = {cost("material_filter", 10, 4, 1, 0, 0),
                                           cost("lambertian_choice", 10, 4, 1, 0, 0),
                                           cost("depth_filter", 10, 4, 1, 0, 0)};
        for (OpCostConfig& c : costs) c.cold_call_cycles = cold;
        return host_with(costs);
    };
    std::vector<uint32_t> ids(16);
    for (uint32_t i = 0; i < 16; ++i) ids[i] = i;
    const std::vector<uint8_t> all(16, 1), half = {1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};
    // The depth filter, a stack's op and a material filter after it (placed by the sort), none
    // of which reads the scene (a material filter after the depth filter waits for its
    // material's record, which can hide what the ops before it took).
    const std::vector<StreamOp> ops = {
        {OpKind::depth_filter, OpStage::shading, 0, k_no_object, 16, 16, ids.data(), all.data()},
        {OpKind::lambertian_choice, OpStage::shading, 0, k_no_object, 16, 8, ids.data(),
         half.data()},
        {OpKind::material_filter, OpStage::shading, 0, 1, 8, 4, ids.data() + 8, half.data()}};
    CHECK(cycle_level_cycles(host(50), ops) == cycle_level_cycles(host(0), ops) + 2 * 50);
    CHECK(closed_form_cycles(host(50), ops) == closed_form_cycles(host(0), ops) + 2 * 50);
    OpProfile p;
    p.cost.cold_call_cycles = 50;
    CHECK(p.cold_call_cycles() == 0);  // instruction-priced: no cold call
    p.measured = true;
    CHECK(p.cold_call_cycles() == 50);
}

TEST_CASE("Both timing models price a triangle op's failed candidates", "[host][systemc]") {
    OpCostConfig triangle = cost("triangle_test", 10, 4, 1, 20, 0);
    triangle.per_failed_candidate_cycles = 30;
    const HwConfig host = host_with({triangle});
    std::vector<uint32_t> ids(16);
    for (uint32_t i = 0; i < 16; ++i) ids[i] = i;
    const std::vector<uint8_t> some = {1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    // A triangle test of 16 lanes, 2 passing and `failed` of the other 14 failed candidates.
    auto op = [&](uint32_t failed) {
        return StreamOp{OpKind::triangle_test,
                        OpStage::intersection,
                        1,
                        0,
                        16,
                        2,
                        ids.data(),
                        some.data(),
                        failed};
    };
    // Priced as the same cycles spread over the op's lanes: 6 * 30 / 16 a lane more.
    OpCostConfig dearer_lanes = triangle;
    dearer_lanes.per_failed_candidate_cycles = 0;
    dearer_lanes.per_lane_cycles += 6 * 30 / 16.0;
    const HwConfig same = host_with({dearer_lanes});
    auto cycle_level = [](const HwConfig& host, const StreamOp& o) {
        return cycle_level_cycles(host, {o});
    };
    auto closed_form = [](const HwConfig& host, const StreamOp& o) {
        return closed_form_cycles(host, {o});
    };
    // The cycle level waits for the triangle's line, then issues: 6 * 30 more.
    CHECK(cycle_level(host, op(6)) == cycle_level(host, op(0)) + 6 * 30);
    CHECK(cycle_level(host, op(6)) == cycle_level(same, op(0)));
    CHECK(closed_form(host, op(6)) > closed_form(host, op(0)));
    CHECK(closed_form(host, op(6)) == closed_form(same, op(0)));
}

TEST_CASE("Both timing models price a one-lane triangle op by its lane's outcome",
          "[host][systemc]") {
    OpCostConfig triangle = cost("triangle_test", 10, 4, 1, 20, 0);
    triangle.one_lane_cycles = 60;
    triangle.one_lane_pass_cycles = 90;
    triangle.one_lane_failed_candidate_cycles = 70;
    const HwConfig host = host_with({triangle});
    // The same mean price on every lane: a failing lane at 60 + (90 + 70) / 2.
    OpCostConfig flat = triangle;
    flat.one_lane_cycles = 60 + (90 + 70) / 2.0;
    flat.one_lane_pass_cycles = flat.one_lane_failed_candidate_cycles = 0;
    const HwConfig same = host_with({flat});
    const uint32_t id = 0;
    const uint8_t pass = 1, fail = 0;
    auto op = [&](bool passed, uint32_t failed) {
        return StreamOp{OpKind::triangle_test,
                        OpStage::intersection,
                        1,
                        0,
                        1,
                        passed ? 1u : 0u,
                        &id,
                        passed ? &pass : &fail,
                        failed};
    };
    const uint64_t failing = cycle_level_cycles(host, {op(false, 0)});
    CHECK(cycle_level_cycles(host, {op(true, 0)}) == failing + 90);
    CHECK(cycle_level_cycles(host, {op(false, 1)}) == failing + 70);
    // One passing and one failed candidate cost what two lanes at the mean do; the closed
    // form prices them from its bucket's means.
    const std::vector<StreamOp> both = {op(true, 0), op(false, 1)};
    const std::vector<StreamOp> neither = {op(false, 0), op(false, 0)};
    CHECK(cycle_level_cycles(host, both) == cycle_level_cycles(same, neither));
    CHECK(closed_form_cycles(host, both) == closed_form_cycles(same, neither));
    CHECK(closed_form_cycles(host, both) > closed_form_cycles(host, neither));
}
