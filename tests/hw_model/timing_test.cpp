// The hardware model on crafted passes (exact cycles) and on real traces (invariants).

#include <catch2/catch.hpp>
#include <cstring>

#include "hw_model/analytic_model.h"
#include "hw_model/systemc/accelerator.h"
#include "hw_model/systemc/systemc_timing.h"
#include "kernels/bvh.h"
#include "kernels/stream/stream_tracer.h"
#include "sweeps/point_group.h"
#include "workloads/input_error.h"
#include "workloads/ray_layout.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

WorkloadShape triangle_shape(uint32_t tile) {
    WorkloadShape s;
    s.features.triangles = true;
    s.features.lambertian = true;
    s.features.light_count = 1;
    s.triangles = 100;
    s.bvh_nodes = 64;
    s.tile = tile;
    return s;
}

// Times one crafted op on a fresh accelerator and returns the frame.
FrameTiming time_one(const HwConfig& config, OpKind kind, const std::vector<uint32_t>& slots,
                     const std::vector<uint8_t>& passed, uint32_t object = k_no_object) {
    SystemcTiming timing({config}, triangle_shape(64));
    TilePass pass;
    pass.slot_count = 64 * 64;
    timing.begin_pass(pass);
    StreamOp op;
    op.kind = kind;
    op.stage = stage_of(kind);
    op.generation = 1;
    op.object = object;
    op.length = uint32_t(slots.size());
    op.slots = slots.data();
    op.passed = passed.data();
    for (uint8_t p : passed) op.pass_count += p;
    timing.op(op);
    timing.end_pass(pass);
    return timing.timing(0);
}

HwConfig with_width(uint32_t width) {
    HwConfig c;
    c.simd.width = width;
    c.name = "w" + std::to_string(width);
    return c;
}

}  // namespace

TEST_CASE("A stream whose ids all hit one bank costs a conflict per extra lane", "[hw_model][systemc]") {
    const HwConfig config = with_width(16);
    // Slot s of every field lives in bank (word * capacity + s) mod 32; slots 32 apart share it.
    std::vector<uint32_t> same_bank(16), spread(16);
    for (uint32_t i = 0; i < 16; ++i) {
        same_bank[i] = i * 32;
        spread[i] = i;
    }
    const std::vector<uint8_t> none(16, 0);
    const FrameTiming hot = time_one(config, OpKind::box_test, same_bank, none);
    const FrameTiming clean = time_one(config, OpKind::box_test, spread, none);
    // The box test gathers 7 words (origin, inverse direction, t_max): 15 extra cycles each.
    // (No scene object here: a node fetch would overlap, and hide, part of the gathers.)
    CHECK(clean.stalls.bank_conflict == 0);
    CHECK(hot.stalls.bank_conflict == 7 * 15);
    CHECK(hot.cycles - clean.cycles == 7 * 15);
    CHECK(hot.conflicted_accesses == 7);
    CHECK(clean.conflicted_accesses == 0);
}

TEST_CASE("Widths that do not divide the buffer line stall on alignment", "[hw_model][systemc]") {
    std::vector<uint32_t> slots(48);
    for (uint32_t i = 0; i < 48; ++i) slots[i] = i;
    const std::vector<uint8_t> none(48, 0);
    // 16-word lines: width 16 never straddles; width 12 groups start at 0, 12, 24, 36.
    CHECK(time_one(with_width(16), OpKind::box_test, slots, none).stalls.alignment == 0);
    CHECK(time_one(with_width(12), OpKind::box_test, slots, none).stalls.alignment == 5);
    CHECK(time_one(with_width(8), OpKind::box_test, slots, none).stalls.alignment == 3);
}

TEST_CASE("Pipelined bank access overlaps; unpipelined pays the latency per access",
          "[hw_model][systemc]") {
    std::vector<uint32_t> slots(16);
    for (uint32_t i = 0; i < 16; ++i) slots[i] = i;
    const std::vector<uint8_t> none(16, 0);
    HwConfig pipelined = with_width(16), serial = with_width(16);
    serial.ray_buffer.pipelined = false;
    const FrameTiming a = time_one(pipelined, OpKind::box_test, slots, none);
    const FrameTiming b = time_one(serial, OpKind::box_test, slots, none);
    // 7 gathers of one conflict-free group: 7 issue cycles + 1 fill pipelined, 7 x 2 serial.
    CHECK(b.cycles - a.cycles == 14 - (7 + 1));
}

TEST_CASE("Partition and scene-memory stalls are charged where they occur", "[hw_model][systemc]") {
    std::vector<uint32_t> slots(32);
    for (uint32_t i = 0; i < 32; ++i) slots[i] = i;
    std::vector<uint8_t> alternate(32);
    for (uint32_t i = 0; i < 32; ++i) alternate[i] = i % 2;
    const FrameTiming t = time_one(with_width(16), OpKind::box_test, slots, alternate, 5);
    // Comparators: 32 lanes at 16 per cycle = 2; moves: stable partition of 0101..: 30 ids.
    CHECK(t.stalls.partition == 2 + (30 + 15) / 16);
    // A cold node comes from DRAM (107 cycles + 1 transfer at 25.6 GB/s), overlapped with the
    // first group's id read (1) and 7 gathers (7).
    CHECK(t.stalls.scene_memory == 107 + 2 - 8);
    CHECK(t.dram_reads == 1);
    // Intersection tests scatter for passing lanes only and never partition.
    const FrameTiming i = time_one(with_width(16), OpKind::triangle_test, slots, alternate, 5);
    CHECK(i.stalls.partition == 0);
    // 7 gathered words; 5 scattered (t_max, primitive, t, u, v); 2 groups.
    CHECK(i.mix.scatter_gather == 2 * 7 + 2 * 5);
}

TEST_CASE("Only the units a scene needs are elaborated", "[hw_model][systemc]") {
    const HwConfig config;
    SystemcTiming timing({config}, triangle_shape(32));
    const SimdUnit& simd = timing.accelerator(0).simd();
    CHECK(simd.supports(OpKind::triangle_test));
    CHECK_FALSE(simd.supports(OpKind::sphere_test));
    CHECK_FALSE(simd.supports(OpKind::dielectric));
    CHECK_FALSE(simd.supports(OpKind::glossy));
}

TEST_CASE("The hardware model never changes the image; more banks never slower; more lanes "
          "never more instructions",
          "[hw_model][systemc]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    RenderSettings settings;
    settings.width = settings.height = 32;
    settings.spp = 2;
    settings.tile = 16;
    settings.max_depth = scene.max_depth;
    settings.threads = 2;
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
        const PointGroupResult full = run_point_group(scene, bvh, settings, configs, Fidelity::full);
        const PointGroupResult analytic =
            run_point_group(scene, bvh, settings, configs, Fidelity::analytic);
        for (size_t i = 0; i < configs.size(); ++i) {
            const double ratio = analytic.predictions[i].fps() / full.predictions[i].fps();
            INFO(name << " width " << configs[i].simd.width << " analytic/full fps " << ratio);
            CHECK(ratio == Approx(1.0).margin(0.15));
        }
    }
}

TEST_CASE("Tile auto is the largest stream that fits; a tile that does not fit is an error",
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
