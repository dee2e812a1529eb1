// The hardware model on crafted passes (exact cycles) and on real traces (invariants).

#include <array>
#include <catch2/catch.hpp>
#include <cstring>
#include <set>
#include <string>

#include "hw_model/analytic_model.h"
#include "hw_model/host_description.h"
#include "tests/hw_model/test_hosts.h"
#include "hw_model/pass_buffer.h"
#include "hw_model/systemc/accelerator.h"
#include "hw_model/systemc/systemc_timing.h"
#include "kernels/bvh.h"
#include "kernels/stream/stream_tracer.h"
#include "sweeps/point_group.h"
#include "base/input_error.h"
#include "workloads/ray_layout.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {


struct CraftedOp {
    OpKind kind = OpKind::box_test;
    std::vector<uint32_t> slots;
    std::vector<uint8_t> passed;
    uint32_t object = k_no_object;
};

StreamOp to_stream_op(const CraftedOp& c) {
    StreamOp op;
    op.kind = c.kind;
    op.stage = stage_of(c.kind);
    op.generation = 1;
    op.object = c.object;
    op.length = uint32_t(c.slots.size());
    op.slots = c.slots.data();
    op.passed = c.passed.data();
    for (uint8_t p : c.passed) op.pass_count += p;
    return op;
}

// Times crafted passes (each a list of ops) on a fresh accelerator and returns the frame.
FrameTiming time_passes(const HwConfig& config, const std::vector<std::vector<CraftedOp>>& passes) {
    SystemcTiming timing({config}, triangle_shape(64));
    for (const auto& ops : passes) {
        TilePass pass;
        pass.slot_count = 64 * 64;
        timing.begin_pass(pass);
        for (const CraftedOp& c : ops) timing.op(to_stream_op(c));
        timing.end_pass(pass);
    }
    return timing.timing(0);
}

FrameTiming time_one(const HwConfig& config, OpKind kind, const std::vector<uint32_t>& slots,
                     const std::vector<uint8_t>& passed, uint32_t object = k_no_object) {
    return time_passes(config, {{CraftedOp{kind, slots, passed, object}}});
}

std::vector<uint32_t> consecutive(uint32_t n, uint32_t stride = 1, uint32_t first = 0) {
    std::vector<uint32_t> v(n);
    for (uint32_t i = 0; i < n; ++i) v[i] = first + i * stride;
    return v;
}

// A 32x32 x 2 spp frame in 16x16 tiles on two threads: small enough for every invariant test.
RenderSettings small_frame(const Scene& scene) {
    RenderSettings settings;
    settings.width = settings.height = 32;
    settings.spp = 2;
    settings.tile = 16;
    settings.max_depth = scene.max_depth;
    settings.threads = 2;
    return settings;
}

HwConfig with_width(uint32_t width, uint32_t units = 1) {
    HwConfig c;
    c.simd.width = width;
    c.simd.units = units;
    c.name = "w" + std::to_string(width);
    return c;
}

// The instruction-per-cycle issue these crafted cases were first written for: they keep their
// exact cycles (the cluster issue's own cases follow them).
HwConfig programmable(HwConfig c) {
    c.datapath.issue = "programmable";
    return c;
}

}  // namespace

TEST_CASE("One group of one op: exact cycles and where they went", "[hw_model][systemc]") {
    // Width 16, one unit, a box test of 16 consecutive slots, no node (no scene fetch), no lane
    // passing. Cycle 0 dispatch; ids 1 line -> 1; 112 addresses on 32 AGUs from cycle 1, word w
    // ready at 1 + (w + 1) / 2, so words issue at 2..8, conflict-free; the last leaves its bank
    // at 8 + 2 and crosses 2 mux levels -> data at 12. 34 instructions issue 12..46 (the 9-step
    // chain at 2 cycles, 18, is hidden); the mask passes the scratchpad by 47; the partition
    // compares 16 lanes in 1 cycle: the pass ends at 48.
    const FrameTiming t = time_one(programmable(with_width(16)), OpKind::box_test, consecutive(16),
                                   std::vector<uint8_t>(16, 0));
    CHECK(t.cycles == 48);
    CHECK(t.stages[1][0].busy_cycles == 34);
    CHECK(t.stalls.pipeline_fill == 12 + 2);
    CHECK(t.stalls.total() + 34 == 48);
    CHECK(t.stalls.bank_conflict == 0);
}

TEST_CASE("One group of one op on the cluster: II and schedule length, exact cycles",
          "[hw_model][systemc]") {
    // As above to cycle 12 (data at the unit). The box test's body {26 FPU, 8 ALU} on 84 units
    // of each class starts one group a cycle (II 1: the unit is busy 1 cycle); its chain of 7
    // FPU steps at 7 cycles and 2 ALU steps at 1 gives its mask 51 cycles after it starts, at
    // 63; the scratchpad by 64; the partition's compare ends the pass at 65.
    const HwConfig config = with_width(16);
    REQUIRE(config.datapath.issue == "cluster");
    const OpCostTable table(RayRecordLayout(triangle_shape(64).features), config.datapath);
    const OpProfile& p = table[OpKind::box_test];
    CHECK(p.schedule.ii == 1);
    CHECK(p.schedule.length == 7 * 7 + 2 * 1);
    const FrameTiming t =
        time_one(config, OpKind::box_test, consecutive(16), std::vector<uint8_t>(16, 0));
    CHECK(t.cycles == 65);
    CHECK(t.stages[1][0].busy_cycles == 1);
    CHECK(t.stalls.pipeline_fill == 12 + (65 - 13));
    CHECK(t.stalls.total() + 1 == 65);
    // Four groups on one unit: a group a cycle, the last mask 3 cycles after the first.
    const FrameTiming four =
        time_one(config, OpKind::box_test, consecutive(64), std::vector<uint8_t>(64, 0));
    CHECK(four.stages[1][0].busy_cycles == 4);
}

TEST_CASE("Modulo schedule: the resource bound and the recurrence bound, exactly",
          "[hw_model]") {
    DatapathConfig d;
    d.fpu_units = 4;
    d.alu_units = 2;
    d.mul_units = 1;
    d.fpu_latency_cycles = 7;
    d.alu_latency_cycles = 1;
    d.mul_latency_cycles = 3;
    // Resource-bound: 10 FPU instructions on 4 FPUs need 3 cycles, 5 ALU on 2 need 3, 2
    // multiplies on 1 need 2: II 3. Chain: 3 FPU, 2 ALU, 1 multiply: 21 + 2 + 3 = 26.
    ModuloSchedule r = modulo_schedule({10, 5, 2}, {3, 2, 1}, {}, d);
    CHECK(r.resource_ii == 3);
    CHECK(r.recurrence_ii == 0);
    CHECK(r.ii == 3);
    CHECK(r.length == 26);
    // Recurrence-bound: the same body carrying an FPU step and an ALU step from group to group
    // (a running sum and its select): 7 + 1 = 8 > 3.
    ModuloSchedule c = modulo_schedule({10, 5, 2}, {3, 2, 1}, {1, 1, 0}, d);
    CHECK(c.resource_ii == 3);
    CHECK(c.recurrence_ii == 8);
    CHECK(c.ii == 8);
    CHECK(c.length == 26);
    // A schedule is never shorter than its II; an empty body still takes a cycle.
    CHECK(modulo_schedule({1, 0, 0}, {0, 0, 0}, {0, 2, 0}, d).length == 2);
    CHECK(modulo_schedule({}, {}, {}, d).ii == 1);
    // Through the op table: issue_cycles is the II, result_cycles the schedule length.
    DatapathConfig gr08;
    const OpCostTable table(RayRecordLayout(triangle_shape(64).features), gr08);
    const OpProfile& tri = table[OpKind::triangle_test];
    CHECK(tri.body.total() == tri.compute_instructions);
    CHECK(tri.chain.total() == tri.chain_steps);
    CHECK(tri.issue_cycles(gr08, 16, 0, 16, 0, true, 0.0) == double(tri.schedule.ii));
    CHECK(tri.result_cycles(gr08, 1.0) == double(tri.schedule.length));
}

TEST_CASE("More function units never slow a filter", "[hw_model][systemc]") {
    // Every op kind's II and schedule length, and the cycles of a pass of several kinds, as
    // the units of one class or of all classes grow.
    const RayRecordLayout layout(triangle_shape(64).features);
    const std::vector<CraftedOp> ops = {
        {OpKind::box_test, consecutive(48), std::vector<uint8_t>(48, 1)},
        {OpKind::triangle_test, consecutive(40), std::vector<uint8_t>(40, 0)},
        {OpKind::lambertian_direct, consecutive(33), std::vector<uint8_t>(33, 1)},
        {OpKind::ambient, consecutive(20), std::vector<uint8_t>(20, 1)}};
    for (uint32_t which = 0; which < 4; ++which) {
        uint64_t last_cycles = ~uint64_t(0);
        std::array<ModuloSchedule, k_op_kind_count> last{};
        for (uint32_t units : {1u, 2u, 3u, 5u, 8u, 13u, 27u, 84u, 200u}) {
            HwConfig c = with_width(16);
            if (which == 0 || which == 3) c.datapath.fpu_units = units;
            if (which == 1 || which == 3) c.datapath.alu_units = units;
            if (which == 2 || which == 3) c.datapath.mul_units = units;
            const OpCostTable table(layout, c.datapath);
            for (uint32_t k = 0; k < k_op_kind_count; ++k) {
                const ModuloSchedule s = table[OpKind(k)].schedule;
                if (units > 1) {
                    CHECK(s.ii <= last[k].ii);
                    CHECK(s.length <= last[k].length);
                }
                last[k] = s;
            }
            const uint64_t cycles = time_passes(c, {ops}).cycles;
            INFO("class " << which << ", " << units << " units: " << cycles << " cycles");
            CHECK(cycles <= last_cycles);
            last_cycles = cycles;
        }
    }
}

TEST_CASE("A stream whose ids all hit one bank queues on that bank", "[hw_model][systemc]") {
    const HwConfig config = with_width(16);
    // Slots 32 apart share a bank for every field word: each of the 7 words waits for 16
    // grants from its bank. The words' banks differ, so they queue side by side: 15 cycles.
    const std::vector<uint8_t> none(16, 0);
    const FrameTiming hot = time_one(config, OpKind::box_test, consecutive(16, 32), none);
    const FrameTiming clean = time_one(config, OpKind::box_test, consecutive(16), none);
    CHECK(clean.stalls.bank_conflict == 0);
    CHECK(hot.stalls.bank_conflict == 15);
    CHECK(hot.cycles - clean.cycles == 15);
}

TEST_CASE("Two SIMD units hitting one bank serialize", "[hw_model][systemc]") {
    // 32 lanes whose words all sit in one bank per word: one group per unit. Unit 0 issues its
    // 7 words at 2..8 and each bank grants its 16 requests in turn: its last grant is 23, 15
    // late. Unit 1's addresses come from the same 32 AGUs after unit 0's 112 (cycle 4.5), so its
    // words issue at 5..11 and queue behind unit 0's 16 in each bank: last grant 39, 28 late.
    const std::vector<uint8_t> none(32, 0);
    const FrameTiming spread = time_one(with_width(16, 2), OpKind::box_test, consecutive(32), none);
    const FrameTiming hot =
        time_one(with_width(16, 2), OpKind::box_test, consecutive(32, 32), none);
    const FrameTiming one_unit_hot =
        time_one(with_width(16, 1), OpKind::box_test, consecutive(32, 32), none);
    CHECK(spread.stalls.bank_conflict == 0);
    CHECK(hot.stalls.bank_conflict == 15 + 28);
    CHECK(hot.cycles - spread.cycles == 28);
    CHECK(one_unit_hot.cycles >= hot.cycles);  // a second unit never hurts
}

TEST_CASE("An AGU queue of depth 1 against 8 on a long stream", "[hw_model][systemc]") {
    // A compute-heavy op (4 triangle-test groups, 96 instructions each) followed by an op that
    // computes little but gathers slowly (ambient on 128 lanes that all share a bank per word:
    // 8 groups, each about 16 cycles of gathers and 6 of compute). Neither partitions, so the
    // access side may run ahead into the second op while the first computes: with depth 8 it
    // fetches every ambient group in that time; with depth 1 it fetches one, and the unit then
    // waits on every other fetch.
    HwConfig deep = programmable(with_width(16)), shallow = programmable(with_width(16));
    deep.agu.queue_depth = 8;
    shallow.agu.queue_depth = 1;
    const std::vector<CraftedOp> ops = {
        {OpKind::triangle_test, consecutive(64), std::vector<uint8_t>(64, 0)},
        {OpKind::ambient, consecutive(128, 32), std::vector<uint8_t>(128, 0)}};
    const FrameTiming a = time_passes(deep, {ops});
    const FrameTiming b = time_passes(shallow, {ops});
    INFO("depth 8: " << a.cycles << " cycles, depth 1: " << b.cycles);
    CHECK(b.cycles - a.cycles >= 7 * (16 - 6));
    CHECK(a.stages[1][1].busy_cycles == 4 * 96);
    CHECK(a.stages[1][1].busy_cycles == b.stages[1][1].busy_cycles);  // same work either way
}

TEST_CASE("Prefetch hides a scene-memory latency exactly", "[hw_model][systemc]") {
    // A box test, then a triangle test that waits for its partition. Without prefetch the
    // triangle's cold vertices are requested when it dispatches, after the partition, and the
    // unit waits for them; with depth 1 they are requested with the box test's node and have
    // arrived by then. The difference in cycles is exactly the difference in that stall.
    HwConfig none = with_width(16), one = with_width(16);
    one.scene_memory.prefetch_depth = 1;
    const std::vector<CraftedOp> ops = {
        {OpKind::box_test, consecutive(16), std::vector<uint8_t>(16, 1), 3},
        {OpKind::triangle_test, consecutive(16), std::vector<uint8_t>(16, 0), 90}};
    const FrameTiming a = time_passes(none, {ops});
    const FrameTiming b = time_passes(one, {ops});
    INFO("scene stalls " << a.stalls.scene_memory << " / " << b.stalls.scene_memory);
    CHECK(a.stalls.scene_memory > b.stalls.scene_memory);
    CHECK(a.cycles - b.cycles == a.stalls.scene_memory - b.stalls.scene_memory);
}

TEST_CASE("Two cores share the L3 and the DRAM channel", "[hw_model][systemc]") {
    // Two passes that fetch the same node. One core: the second pass finds it in L1. Two
    // cores: both passes run at once; the second core misses its own L1 and L2 and finds the
    // first core's line in the shared L3.
    HwConfig one = with_width(16), two = with_width(16);
    two.cores.count = 2;
    const std::vector<CraftedOp> pass = {
        {OpKind::box_test, consecutive(16), std::vector<uint8_t>(16, 1), 7}};
    const FrameTiming a = time_passes(one, {pass, pass});
    const FrameTiming b = time_passes(two, {pass, pass});
    CHECK(a.passes == 2);
    CHECK(b.passes == 2);
    CHECK(a.cache_hits[0] == 1);  // core 0's L1, second pass
    CHECK(b.cache_hits[0] == 0);  // two private L1s, one cold fetch each
    CHECK(b.cache_hits[2] == 1);  // the shared L3
    CHECK(b.dram_reads == 1);
    CHECK(b.cycles >= a.cycles);  // the second core waits 7 cycles where one core waited 1
}

TEST_CASE("Widths that do not divide the buffer line stall on alignment", "[hw_model][systemc]") {
    // Two units, one group each, nothing to hide the fetch behind. 16-word lines: at width 16
    // the second group starts on a line; at width 12 it starts at word 12 and spans two lines
    // (and a realignment), at width 8 it starts mid-line.
    auto alignment = [](uint32_t width) {
        const std::vector<uint8_t> none(2 * width, 0);
        return time_one(with_width(width, 2), OpKind::box_test, consecutive(2 * width), none)
            .stalls.alignment;
    };
    CHECK(alignment(16) == 0);
    CHECK(alignment(12) == 2);
    CHECK(alignment(8) == 1);
}

TEST_CASE("Unpipelined banks hold each request for the access latency", "[hw_model][systemc]") {
    const std::vector<uint8_t> none(16, 0);
    HwConfig pipelined = with_width(16), serial = with_width(16);
    serial.ray_buffer.pipelined = false;
    // Slots 32 apart: 16 requests per bank, 1 cycle each pipelined, 2 each not.
    const FrameTiming a = time_one(pipelined, OpKind::box_test, consecutive(16, 32), none);
    const FrameTiming b = time_one(serial, OpKind::box_test, consecutive(16, 32), none);
    CHECK(b.cycles - a.cycles == 15 * 2 - 15);
}

TEST_CASE("Partition and scene-memory stalls are charged where they occur", "[hw_model][systemc]") {
    std::vector<uint8_t> alternate(32);
    for (uint32_t i = 0; i < 32; ++i) alternate[i] = i % 2;
    // Two box tests: the second's stream depends on the first's partition.
    const std::vector<CraftedOp> ops = {{OpKind::box_test, consecutive(32), alternate, 4},
                                        {OpKind::box_test, consecutive(16), alternate, 5}};
    const FrameTiming t = time_passes(with_width(16), {ops});
    // Comparators: 32 lanes at 16 per cycle = 2; moves: a stable partition of 0101.. moves every
    // id (passing ids to the front, failing ones behind them): 32 ids at 16 per cycle = 2.
    CHECK(t.stalls.partition == 2 + 32 / 16);
    CHECK(t.stalls.scene_memory > 0);
    CHECK(t.dram_reads == 1);  // nodes 4 and 5 share a 64-byte line
    // Intersection tests scatter for passing lanes only and never partition.
    const FrameTiming i =
        time_one(with_width(16), OpKind::triangle_test, consecutive(32), alternate, 5);
    CHECK(i.stalls.partition == 0);
    // 7 gathered words; 5 scattered (t_max, primitive, t, u, v); 2 groups.
    CHECK(i.mix.scatter_gather == 2 * 7 + 2 * 5);
}

TEST_CASE("The pass buffer knows each lane's hit primitive where an op reads it",
          "[hw_model]") {
    // Slots 0..15 hit triangle 7; slots 0..7 then hit triangle 50 closer; slot 3's ray is then
    // replaced by a pushed one (no hit yet). The emission filter reads its lanes' hits; a depth
    // filter does not.
    PassBuffer buffer;
    TilePass pass;
    pass.slot_count = 64;
    buffer.begin_pass(pass);
    const std::vector<CraftedOp> ops = {
        {OpKind::triangle_test, consecutive(16), std::vector<uint8_t>(16, 1), 7},
        {OpKind::triangle_test, consecutive(8), std::vector<uint8_t>(8, 1), 50},
        {OpKind::lambertian_indirect, {3}, {1}, 0},
        {OpKind::emission_filter, consecutive(16), std::vector<uint8_t>(16, 0)},
        {OpKind::depth_filter, consecutive(16), std::vector<uint8_t>(16, 0)}};
    for (const CraftedOp& c : ops) buffer.op(to_stream_op(c));
    buffer.end_pass(pass);
    REQUIRE(buffer.lane_hits(3) != nullptr);
    CHECK(buffer.lane_hits(4) == nullptr);
    CHECK(buffer.lane_hits(0) == nullptr);
    for (uint32_t i = 0; i < 16; ++i) {
        INFO("lane " << i);
        CHECK(buffer.lane_hits(3)[i] == (i == 3 ? k_no_object : i < 8 ? 50u : 7u));
    }
}

TEST_CASE("A surface group waits for its slowest lane's hit primitive", "[hw_model][systemc]") {
    // No caches: every scene read goes to DRAM. A triangle test (the hits), a miss filter whose
    // partition the emission filter waits for, then the emission filter over the 16 hits. Its
    // one group waits for its lanes' vertices beyond its ray data, on DRAM alone: 50 ns more
    // DRAM latency adds exactly 25 cycles (500 MHz) to that wait.
    auto config = [](double dram_ns) {
        HwConfig c = with_width(16);
        c.scene_memory.caches.clear();
        c.scene_memory.dram_latency_ns = dram_ns;
        return c;
    };
    const std::vector<CraftedOp> ops = {
        {OpKind::triangle_test, consecutive(16), std::vector<uint8_t>(16, 1), 7},
        {OpKind::miss_filter, consecutive(16), std::vector<uint8_t>(16, 0)},
        {OpKind::emission_filter, consecutive(16), std::vector<uint8_t>(16, 0)}};
    const FrameTiming near = time_passes(config(200), {ops});
    const FrameTiming far = time_passes(config(250), {ops});
    const uint64_t shading_near = near.stages[1][uint32_t(OpStage::shading)].scene_memory_cycles;
    const uint64_t shading_far = far.stages[1][uint32_t(OpStage::shading)].scene_memory_cycles;
    INFO("shading scene-memory stall " << shading_near << " / " << shading_far);
    CHECK(shading_near > 0);
    CHECK(shading_far == shading_near + 25);
    // The op mix: one group gathers the triangle's 9 vertex words (an address vector each).
    const FrameTiming depth_only = time_passes(
        config(200), {{ops[0], ops[1], {OpKind::depth_filter, consecutive(16),
                                        std::vector<uint8_t>(16, 0)}}});
    CHECK(depth_only.stages[1][uint32_t(OpStage::shading)].scene_memory_cycles == 0);
    // The op mix: the emission filter's one group gathers its ray words and the triangle's 9
    // vertex words (an address vector each); the depth filter's gathers its ray words.
    const OpCostTable table(RayRecordLayout(triangle_shape(64).features), config(200));
    REQUIRE(table[OpKind::emission_filter].lane_scene_words == 9);
    CHECK(near.mix.scatter_gather - depth_only.mix.scatter_gather ==
          table[OpKind::emission_filter].gather_words.size() + 9 -
              table[OpKind::depth_filter].gather_words.size());
}

TEST_CASE("A group's mask is stored when any lane passed (G&R Fig. 5)", "[hw_model][systemc]") {
    // A box test of 48 lanes at width 16: the first group passes none, the second one lane,
    // the third all. Two mask stores; the stable partition moves the 17 passing ids forward
    // and the first group's 16 failing ones back (33 ids: 3 move cycles).
    std::vector<uint8_t> passed(48, 0);
    passed[20] = 1;
    for (uint32_t i = 32; i < 48; ++i) passed[i] = 1;
    const FrameTiming t = time_one(with_width(16), OpKind::box_test, consecutive(48), passed);
    const uint32_t moved = stable_partition_moves(passed.data(), 48);
    CHECK(t.mix.store == 2 + (moved + 15) / 16);
}

// A parent box test on 32 rays (node 1), 16 passing; its front child on those 16 (node 20;
// half pass, so its own passing stream is a new one); the back child on the parent's 16 again
// (node 40): the back child's stream comes from the parent, not from the front child.
// A box test on node 1, then its children's on nodes `front` and `back`.
std::vector<CraftedOp> parent_and_children(uint32_t front = 20, uint32_t back = 40) {
    const std::vector<uint32_t> all = consecutive(32), half = consecutive(16);
    std::vector<uint8_t> parent_pass(32, 0), child_pass(16, 0);
    for (uint32_t i = 0; i < 16; ++i) parent_pass[i] = 1;
    for (uint32_t i = 0; i < 16; i += 2) child_pass[i] = 1;
    return {{OpKind::box_test, all, parent_pass, 1},
            {OpKind::box_test, half, child_pass, front},
            {OpKind::box_test, half, child_pass, back}};
}

TEST_CASE("An op window releases an op once the partition that produced its stream is done",
          "[hw_model][systemc]") {
    const std::vector<CraftedOp> ops = parent_and_children();
    PassBuffer buffer;
    buffer.begin_pass(TilePass{});
    for (const CraftedOp& c : ops) buffer.op(to_stream_op(c));
    CHECK(buffer.producer(0) == -1);
    CHECK(buffer.producer(1) == 0);
    CHECK(buffer.producer(2) == 0);

    buffer.end_pass(TilePass{});
    REQUIRE(buffer.consumers_end(0) - buffer.consumers_begin(0) == 2);
    CHECK(buffer.consumers_begin(0)[0] == 1);
    CHECK(buffer.consumers_begin(0)[1] == 2);
    CHECK(buffer.consumers_end(1) == buffer.consumers_begin(1));

    HwConfig in_order, window;
    window.cores.op_window = 2;
    const FrameTiming a = time_passes(in_order, {ops}), b = time_passes(window, {ops});
    // In order, the back child waits for the front child's partition; with a window of two it
    // starts once the parent's is done, and hides the front child's latency.
    CHECK(b.cycles < a.cycles);
    CHECK(b.stalls.pipeline_fill < a.stalls.pipeline_fill);
    // Never slower, and the same work.
    CHECK(b.mix.total() == a.mix.total());
}

TEST_CASE("A chain of dependent ops has nothing for the window or the other unit to hide",
          "[hw_model][systemc]") {
    // Each op's stream is the one its predecessor's partition produced (16, 8, then 4 lanes:
    // one group each). The op window overlaps only ops whose streams come from partitions
    // already done, and the other SIMD unit only another group: here there is neither, so the
    // latency between the ops is exposed whole whatever the window and the units.
    std::vector<uint8_t> first(16, 0), second(8, 0), third(4, 0);
    for (uint32_t i = 0; i < 8; ++i) first[i] = 1;
    for (uint32_t i = 0; i < 4; ++i) second[i] = 1;
    const std::vector<CraftedOp> chain = {{OpKind::box_test, consecutive(16), first, 1},
                                          {OpKind::box_test, consecutive(8), second, 2},
                                          {OpKind::box_test, consecutive(4), third, 3}};
    HwConfig base = with_width(16), window = with_width(16), units = with_width(16, 2);
    window.cores.op_window = 16;
    const FrameTiming a = time_passes(base, {chain});
    const FrameTiming b = time_passes(window, {chain});
    const FrameTiming c = time_passes(units, {chain});
    CHECK(b.cycles == a.cycles);
    CHECK(c.cycles == a.cycles);
    // Three ops of one group each, about the 65 cycles of a group's fetch, schedule and
    // partition apiece: 3 busy cycles, the rest stalled, most of it on that latency.
    CHECK(a.cycles >= 3 * 60);
    CHECK(a.stalls.total() + 3 == a.cycles);
    CHECK(double(a.stalls.pipeline_fill) >= 0.85 * double(a.cycles));
}

TEST_CASE("An intersection op's cycles go to the loop of the box test that reached its leaf",
          "[hw_model][systemc]") {
    // A 16-lane box test (stream loop) passes 3 rays; their 3-lane box test (few-ray loop) passes
    // one, whose leaf's triangle test is the few-ray loop's leaf code even at one lane; a 16-lane
    // box test that passes 8 reaches a leaf in the stream loop; a 1-lane stream from another
    // 16-lane box test (one-ray loop) reaches one there.
    std::vector<uint8_t> three(16, 0), eight(16, 0), one(16, 0);
    three[0] = three[1] = three[2] = 1;
    for (uint32_t i = 0; i < 8; ++i) eight[i] = 1;
    one[0] = 1;
    const std::vector<CraftedOp> ops = {
        {OpKind::box_test, consecutive(16), three, 1},
        {OpKind::box_test, consecutive(3), {1, 0, 0}, 2},
        {OpKind::triangle_test, consecutive(1), {1}, 0},
        {OpKind::box_test, consecutive(16, 1, 16), eight, 3},
        {OpKind::triangle_test, consecutive(8, 1, 16), std::vector<uint8_t>(8, 0), 1},
        {OpKind::triangle_test, consecutive(8, 1, 16), std::vector<uint8_t>(8, 1), 2},
        {OpKind::box_test, consecutive(16, 1, 32), one, 4},
        {OpKind::box_test, consecutive(1, 1, 32), {1}, 5},
        {OpKind::triangle_test, consecutive(1, 1, 32), {0}, 3}};
    const auto leaves = [](const FrameTiming& t) {
        return std::array<uint64_t, 3>{t.intersection_loop_cycles[0], t.intersection_loop_cycles[1],
                                       t.intersection_loop_cycles[2]};
    };
    const FrameTiming wide = time_passes(with_width(16), {ops});
    for (const uint64_t c : leaves(wide)) CHECK(c > 0);
    // Without the few-ray loop (four lanes) the 3-lane stream is the stream loop's, and so is
    // its leaf; the leaf below the 1-lane stream stays the one-ray loop's.
    const FrameTiming narrow = time_passes(with_width(4), {ops});
    CHECK(leaves(narrow)[size_t(TraversalLoop::few_ray)] == 0);
    CHECK(leaves(narrow)[size_t(TraversalLoop::one_ray)] > 0);
    CHECK(leaves(narrow)[size_t(TraversalLoop::stream)] > 0);
    for (const FrameTiming* t : {&wide, &narrow}) {
        const StageTiming& intersection = t->stages[1][size_t(OpStage::intersection)];
        CHECK(t->intersection_loop_cycles[0] + t->intersection_loop_cycles[1] +
                  t->intersection_loop_cycles[2] <=
              intersection.busy_cycles + intersection.stall_cycles);
    }
}

TEST_CASE("A box test's cycles go to the tracer loop its stream entered", "[hw_model][systemc]") {
    // A 16-lane op (stream loop) passes 3 rays: their stream (3 lanes) and the 1-lane stream
    // below it run in the few-ray loop on a back end of k_few_ray_min_width lanes or more; a
    // 1-lane stream from another 16-lane op runs in the one-ray loop.
    std::vector<uint8_t> three(16, 0), one(16, 0);
    three[0] = three[1] = three[2] = 1;
    one[0] = 1;
    const std::vector<CraftedOp> ops = {{OpKind::box_test, consecutive(16), three, 1},
                                        {OpKind::box_test, consecutive(3), {1, 0, 0}, 2},
                                        {OpKind::box_test, consecutive(1), {1}, 3},
                                        {OpKind::box_test, consecutive(16, 1, 16), one, 4},
                                        {OpKind::box_test, consecutive(1, 1, 16), {0}, 5}};
    const auto loops = [](const FrameTiming& t) {
        return std::array<uint64_t, 3>{t.traversal_loop_cycles[0], t.traversal_loop_cycles[1],
                                       t.traversal_loop_cycles[2]};
    };
    const FrameTiming wide = time_passes(with_width(16), {ops});
    const FrameTiming narrow = time_passes(with_width(4), {ops});
    CHECK(loops(wide)[size_t(TraversalLoop::one_ray)] > 0);
    CHECK(loops(wide)[size_t(TraversalLoop::few_ray)] > 0);
    CHECK(loops(wide)[size_t(TraversalLoop::stream)] > 0);
    // Four lanes run 2-4-ray streams in the stream loop: the 1-lane stream below them is the
    // one-ray loop's.
    CHECK(loops(narrow)[size_t(TraversalLoop::few_ray)] == 0);
    CHECK(loops(narrow)[size_t(TraversalLoop::one_ray)] >
          loops(wide)[size_t(TraversalLoop::one_ray)]);
    for (const FrameTiming* t : {&wide, &narrow}) {
        const StageTiming& traversal = t->stages[1][size_t(OpStage::traversal)];
        CHECK(t->traversal_loop_cycles[0] + t->traversal_loop_cycles[1] +
                  t->traversal_loop_cycles[2] <=
              traversal.busy_cycles + traversal.stall_cycles);
    }
    // No intersection op: no leaf code's cycles.
    for (const uint64_t c : wide.intersection_loop_cycles) CHECK(c == 0);
    CHECK(traversal_loop(1, 16, TraversalLoop::stream) == TraversalLoop::one_ray);
    CHECK(traversal_loop(k_few_ray_lanes, 16, TraversalLoop::stream) == TraversalLoop::few_ray);
    CHECK(traversal_loop(k_few_ray_lanes + 1, 16, TraversalLoop::stream) ==
          TraversalLoop::stream);
    CHECK(traversal_loop(1, 16, TraversalLoop::few_ray) == TraversalLoop::few_ray);
    CHECK(traversal_loop(3, 4, TraversalLoop::stream) == TraversalLoop::stream);
}

TEST_CASE(
    "Prefetching an op's children requests the back child's node before the front child "
    "dispatches, once the parent's node, which holds its index, has arrived",
    "[hw_model][systemc]") {
    // Every node first read from DRAM. Node 1's left child is node 2 (left_child_index): its
    // address follows from the parent's; node 40's is read from the parent's record.
    const std::vector<CraftedOp> ops = parent_and_children(2, 40);
    HwConfig next_op, children;
    for (HwConfig* c : {&next_op, &children})
        c->scene_memory.dram_latency_ns = 2000;  // 1000 cycles: longer than any op here
    next_op.scene_memory.prefetch_depth = 1;
    children.scene_memory.prefetch_children = true;
    const FrameTiming a = time_passes(next_op, {ops}), b = time_passes(children, {ops});
    // Both request the front child's node as the parent dispatches; the children's prefetch
    // requests the back child's node as the parent's arrives, not when the front child
    // dispatches.
    CHECK(b.stalls.scene_memory < a.stalls.scene_memory);
    CHECK(b.cycles < a.cycles);
    // One child: the left one's node arrives with its parent's; a right one's, requested once
    // the parent's has arrived, a DRAM latency later.
    auto first_child = [&](uint32_t node) {
        std::vector<CraftedOp> two = parent_and_children(node, 40);
        two.pop_back();
        return time_passes(children, {two});
    };
    const FrameTiming left = first_child(2), right = first_child(20);
    CHECK(right.cycles >= left.cycles + 900);
    CHECK(right.stalls.scene_memory >= left.stalls.scene_memory + 900);
}

TEST_CASE("More units, more cores, deeper queues are never slower on the same trace",
          "[hw_model][systemc]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = small_frame(scene);
    std::vector<HwConfig> configs;
    auto add = [&](uint32_t units, uint32_t cores, uint32_t depth) {
        HwConfig c;
        c.simd.units = units;
        c.cores.count = cores;
        c.agu.queue_depth = depth;
        c.name =
            "u" + std::to_string(units) + "c" + std::to_string(cores) + "q" + std::to_string(depth);
        configs.push_back(c);
    };
    add(1, 1, 1);
    add(1, 1, 8);
    add(2, 1, 8);
    add(4, 1, 8);
    add(4, 2, 8);
    configs.push_back(configs.back());  // and a window across ops
    configs.back().cores.op_window = 4;
    configs.back().name += "w4";
    const PointGroupResult r = run_point_group(scene, bvh, settings, configs, Fidelity::full);
    for (size_t i = 1; i < r.predictions.size(); ++i) {
        INFO(configs[i - 1].name << " -> " << configs[i].name);
        CHECK(r.predictions[i].frame_cycles() <= r.predictions[i - 1].frame_cycles() * 1.001);
    }
}

TEST_CASE("The rate with every stall hidden is never below the prediction", "[hw_model][systemc]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = small_frame(scene);
    std::vector<HwConfig> configs(5);
    configs[1].datapath.issue = "programmable";
    configs[2].datapath.issue = "pipelined";
    configs[3].simd.width = 8;
    configs[3].datapath.fpu_units = configs[3].datapath.alu_units = 4;
    configs[4].simd.units = 1;
    configs[4].cores.op_window = 4;
    for (size_t i = 0; i < configs.size(); ++i) configs[i].name = "c" + std::to_string(i);
    PointGroupResult r = run_point_group(scene, bvh, settings, configs, Fidelity::full);
    // The analytic level's busy cycles are its own: the same bounds hold.
    for (Prediction& p :
         run_point_group(scene, bvh, settings, configs, Fidelity::analytic).predictions)
        r.predictions.push_back(std::move(p));
    for (const Prediction& p : r.predictions) {
        double stall_free = 0, full_lanes = 0;
        for (const Stat& s : p.stats()) {
            if (s.name == "fps_stall_free") stall_free = s.value;
            if (s.name == "fps_stall_free_full_lanes") full_lanes = s.value;
        }
        INFO(p.config.name << ": fps " << p.fps() << ", stalls hidden " << stall_free
                           << ", lanes full " << full_lanes);
        CHECK(p.fps() > 0.0);
        CHECK(stall_free >= p.fps());
        CHECK(full_lanes >= stall_free);
        // Busy cycles only: the frame's cycles less its stalls, per unit (at the analytic level
        // too: its causes fill the calibrated cycles its work leaves).
        const double busy = p.frame_cycles() - double(p.timing.stalls.total()) /
                                                   double(p.config.simd.units * p.config.cores.count);
        CHECK(stall_free == Approx(p.fps() * p.frame_cycles() / busy).epsilon(1e-3));  // causes rounded
    }
}

TEST_CASE("A configuration's prediction does not depend on the group it is timed in",
          "[hw_model][systemc]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = small_frame(scene);
    HwConfig w8, three_cores, queue1;
    std::vector<OpCostConfig> costs = costs_for_every_kind({});
    for (OpCostConfig& c : costs) {
        c.per_op_cycles = 10;
        c.per_group_cycles = 4;
        c.per_lane_cycles = 1;
        c.beyond_l1_per_lane_cycles = 2;
    }
    const HwConfig host = host_hw_config(small_host(), costs);
    w8.simd.width = 8;
    three_cores.cores.count = 3;
    three_cores.cores.op_window = 2;
    queue1.agu.queue_depth = 1;
    queue1.simd.units = 4;
    const std::vector<HwConfig> configs = {HwConfig{}, w8, three_cores, queue1, host};
    const PointGroupResult group = run_point_group(scene, bvh, settings, configs, Fidelity::full);
    // Timed beside an identical copy of itself and in reverse order, too: processes due in the
    // same cycle must resume in an order of their accelerator's own making.
    const std::vector<HwConfig> reversed(configs.rbegin(), configs.rend());
    const PointGroupResult back = run_point_group(scene, bvh, settings, reversed, Fidelity::full);
    for (size_t i = 0; i < configs.size(); ++i) {
        const PointGroupResult alone =
            run_point_group(scene, bvh, settings, {configs[i], configs[i]}, Fidelity::full);
        const std::vector<Stat> a = alone.predictions[0].stats(), b = alone.predictions[1].stats(),
                                g = group.predictions[i].stats(),
                                r = back.predictions[configs.size() - 1 - i].stats();
        REQUIRE(a.size() == g.size());
        for (size_t k = 0; k < a.size(); ++k) {
            if (a[k].name == "host_seconds") continue;
            INFO("configuration " << i << " " << a[k].name);
            CHECK(a[k].value == b[k].value);
            CHECK(a[k].value == g[k].value);
            CHECK(a[k].value == r[k].value);
        }
    }
}

TEST_CASE(
    "The hardware model never changes the image, more banks never slower, more lanes "
    "never more instructions",
    "[hw_model][systemc]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const RenderSettings settings = small_frame(scene);
    std::vector<HwConfig> configs;
    for (uint32_t banks : {4u, 8u, 16u, 32u, 64u}) {
        HwConfig c;
        c.ray_buffer.banks = banks;
        c.agu.count = banks;
        c.name = "banks" + std::to_string(banks);
        configs.push_back(c);
    }
    const WorkloadShape shape = workload_shape(scene, bvh, settings);
    const RenderResult plain = render_stream(scene, bvh, settings, nullptr);
    {
        SystemcTiming timing(configs, shape);
        const RenderResult timed = render_stream(scene, bvh, settings, &timing);
        REQUIRE(plain.image.pixels.size() == timed.image.pixels.size());
        CHECK(std::memcmp(plain.image.pixels.data(), timed.image.pixels.data(),
                          plain.image.pixels.size() * sizeof(Vec3)) == 0);
        for (size_t i = 1; i < configs.size(); ++i)
            CHECK(timing.timing(i).cycles <= timing.timing(i - 1).cycles);
        CHECK(timing.timing(0).stalls.bank_conflict > timing.timing(4).stalls.bank_conflict);
    }
    {
        // A CPU core (the host's knobs: buffers behind the L1D, compress, measured costs, the
        // op window) beside the paper's machine: the image is still the same bytes.
        OpCostConfig cost;
        cost.per_group_cycles = 10;
        cost.per_lane_cycles = 2;
        std::vector<OpCostConfig> costs;
        for (const OpKindInfo& k : k_op_kinds) {
            cost.op = k.name;
            costs.push_back(cost);
        }
        HwConfig host = host_hw_config(small_host(), costs);
        host.cores.op_window = 4;
        SystemcTiming timing({HwConfig(), host}, shape);
        const RenderResult timed = render_stream(scene, bvh, settings, &timing);
        CHECK(std::memcmp(plain.image.pixels.data(), timed.image.pixels.data(),
                          plain.image.pixels.size() * sizeof(Vec3)) == 0);
        CHECK(timing.timing(1).cycles > 0);
    }
    std::vector<HwConfig> widths;
    for (uint32_t w : {1u, 2u, 4u, 8u, 12u, 16u, 32u, 64u}) widths.push_back(with_width(w));
    const PointGroupResult r = run_point_group(scene, bvh, settings, widths, Fidelity::full);
    for (size_t i = 1; i < r.predictions.size(); ++i)
        CHECK(r.predictions[i].timing.mix.compute <= r.predictions[i - 1].timing.mix.compute);
}

TEST_CASE("Analytic fidelity is within 15% of full on small scenes", "[hw_model]") {
    for (const char* name : {"cornell", "furnace"}) {
        const Scene scene = load_scene(name);
        const Bvh bvh(scene);
        RenderSettings settings;
        settings.width = settings.height = 64;
        settings.spp = 2;
        settings.tile = 32;
        settings.max_depth = std::min(scene.max_depth, 8u);
        const std::vector<HwConfig> configs = {with_width(8), with_width(12), with_width(16)};
        const PointGroupResult full =
            run_point_group(scene, bvh, settings, configs, Fidelity::full);
        const PointGroupResult analytic =
            run_point_group(scene, bvh, settings, configs, Fidelity::analytic);
        for (size_t i = 0; i < configs.size(); ++i) {
            const double ratio = analytic.predictions[i].fps() / full.predictions[i].fps();
            INFO(name << " width " << configs[i].simd.width << " analytic/full fps " << ratio);
            CHECK(ratio == Approx(1.0).margin(0.15));
        }
    }
}

TEST_CASE("Tile auto is the largest stream that fits, a tile that does not fit is an error",
          "[hw_model]") {
    FeatureSet all;
    all.triangles = all.spheres = all.lambertian = all.dielectric = all.glossy = true;
    all.light_count = 2;
    REQUIRE(ray_record_bytes(all) == 96);
    HwConfig big, small;
    small.ray_buffer.kib = 256;
    CHECK(largest_fitting_tile(all, {big}) == 73);  // 73^2 * 96 = 511,584 <= 524,288
    CHECK(largest_fitting_tile(all, {big, small}) == 52);
    CHECK_NOTHROW(check_tile_fits(64, all, {big}, "--tile"));  // the paper: 384 KiB of rays
    CHECK_THROWS_AS(check_tile_fits(64, all, {small}, "--tile"), InputError);
}

TEST_CASE("Calibrated analytic fidelity lies within its interval of cycle level at non-default "
          "settings",
          "[hw_model]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    RenderSettings settings;
    settings.width = settings.height = 64;
    settings.spp = 4;
    settings.tile = 16;
    settings.max_depth = scene.max_depth;
    settings.threads = 2;
    HwConfig c;
    c.name = "nondefault";
    c.simd.units = 2;
    c.cores.count = 4;
    c.simd.width = 12;
    c.ray_buffer.kib = 256;
    c.scene_memory.prefetch_depth = 0;
    SamplingOptions options;
    options.calibration_fraction = 0.25;  // 16 of the 64 passes, a systematic sample
    const PointGroupResult full = run_point_group(scene, bvh, settings, {c}, Fidelity::full);
    const PointGroupResult analytic =
        run_point_group(scene, bvh, settings, {c}, Fidelity::analytic, options);
    const Prediction& a = analytic.predictions[0];
    const double error = a.frame_cycles() / full.predictions[0].frame_cycles() - 1.0;
    INFO("analytic/full - 1 = " << error << ", stated interval +-" << a.error_relative);
    REQUIRE(a.error_relative > 0.0);
    CHECK(std::abs(error) <= a.error_relative);
}

TEST_CASE("The core model counts each unit's actions", "[hw_model][systemc][energy]") {
    std::vector<uint8_t> alternate(32);
    for (uint32_t i = 0; i < 32; ++i) alternate[i] = i % 2;
    const HwConfig config = programmable(with_width(16));
    const ActionCounts a =
        time_one(config, OpKind::box_test, consecutive(32), alternate, 5).actions;
    // Box test: 32 id words and 7 gathered words per lane; a stable partition of 0101... moves
    // all 32 ids (each read and written); no scatters, no pushed rays.
    CHECK(a.bank_reads == 32 + 7 * 32 + 32);
    CHECK(a.bank_writes == 32);
    CHECK(a.agu_addresses == 7 * 32);
    const uint32_t instructions =
        OpCostTable(RayRecordLayout(triangle_shape(64).features), config.datapath)[OpKind::box_test]
            .compute_instructions;
    CHECK(a.simd_instructions[size_t(OpKind::box_test)] == 2 * instructions);  // 2 groups
    CHECK(a.simd_lane_ops[size_t(OpKind::box_test)] == 32 * instructions);
    CHECK(a.partition_compares == 32);
    CHECK(a.partition_moves == 32);
    CHECK(a.scratchpad_accesses == 2);  // one mask word per group
    CHECK(a.interconnect_word_hops == 7 * 32 * config.interconnect.mux_levels);
    // The cold node: one line looked up and filled at every level, 64 bytes from DRAM.
    for (int level = 0; level < 3; ++level) {
        CHECK(a.cache_accesses[level] == 1);
        CHECK(a.cache_fills[level] == 1);
    }
    CHECK(a.dram_bytes == 64);
    CHECK(a.busy_cycles[size_t(HwUnit::simd)] == 2 * instructions);
    // Triangle tests scatter 5 words for each of the 16 passing lanes.
    const ActionCounts t =
        time_one(config, OpKind::triangle_test, consecutive(32), alternate, 5).actions;
    CHECK(t.bank_writes == 16 * 5);
    CHECK(t.partition_compares == 0);
}

TEST_CASE("Analytic action counts agree with the cycle-level ones", "[hw_model][energy]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    RenderSettings settings;
    settings.width = settings.height = 32;
    settings.spp = 1;
    settings.max_depth = scene.max_depth;
    settings.tile = 16;
    const std::vector<HwConfig> configs = {with_width(16, 2)};
    const ActionCounts full =
        run_point_group(scene, bvh, settings, configs, Fidelity::full).predictions[0].timing.actions;
    const ActionCounts analytic = run_point_group(scene, bvh, settings, configs, Fidelity::analytic)
                                      .predictions[0]
                                      .timing.actions;
    // Lane work is exact in both; ids moved by partitions and scattered lanes are expected
    // values in the analytic model.
    CHECK(analytic.simd_lane_ops == full.simd_lane_ops);
    CHECK(analytic.simd_instructions == full.simd_instructions);
    CHECK(analytic.partition_compares == full.partition_compares);
    CHECK(analytic.bank_reads == Approx(double(full.bank_reads)).epsilon(0.1));
    CHECK(analytic.bank_writes == Approx(double(full.bank_writes)).epsilon(0.2));
    CHECK(analytic.agu_addresses == Approx(double(full.agu_addresses)).epsilon(0.1));
    CHECK(analytic.cache_accesses[0] > 0);
}

TEST_CASE("FrameTiming's counters: one visit, unique names with units, sums and differences",
          "[hw_model]") {
    FrameTiming a, b;
    a.cache_hits = a.cache_misses = {1, 2};
    b.cache_hits = b.cache_misses = {0, 0};
    uint64_t next = 1;
    std::set<std::string> names;
    FrameTiming::visit(a, a, [&](const CounterInfo& c, uint64_t& x, uint64_t&) {
        CHECK(names.insert(c.name()).second);  // every counter once, under its own name
        CHECK(std::string(c.unit) != "");
        CHECK(std::string(c.description) != "");
        x = next++;
    });
    CHECK(names.count("stalls.bank_conflict") == 1);
    CHECK(names.count("stages.secondary.shading.busy_cycles") == 1);
    CHECK(names.count("actions.simd_instructions.glossy") == 1);
    CHECK(names.count("op_cycles.glossy") == 1);
    CHECK(names.count("cache_misses.1") == 1);
    // b = a + a; b - a = a, counter by counter; scaling by 2 doubles each.
    b += a;
    b += a;
    const FrameTiming d = timing_between(a, b);
    FrameTiming twice;
    twice.add_scaled(a, 2.0);
    FrameTiming::visit(d, a, [&](const CounterInfo& c, const uint64_t& x, const uint64_t& y) {
        INFO(c.name());
        CHECK(x == y);
    });
    FrameTiming::visit(twice, b, [&](const CounterInfo& c, const uint64_t& x, const uint64_t& y) {
        INFO(c.name());
        CHECK(x == y);
    });
    CHECK(a.stalls.total() == a.stalls.bank_conflict + a.stalls.alignment + a.stalls.address_fetch +
                                  a.stalls.partition + a.stalls.scene_memory +
                                  a.stalls.interconnect + a.stalls.pipeline_fill +
                                  a.stalls.unit_idle);
}

TEST_CASE(
    "Prediction stats never take an input's prefix (the analysis reads workload.* and "
    "hw.* columns as the sweep's inputs)",
    "[hw]") {
    Prediction p;
    p.timing.cache_hits = {1, 2, 3};
    p.timing.cache_misses = {1, 1, 1};
    for (const Stat& s : p.stats()) {
        INFO(s.name);
        CHECK(s.name.rfind("workload.", 0) != 0);
        CHECK(s.name.rfind("hw.", 0) != 0);
        CHECK(s.name != "fidelity");
    }
}
