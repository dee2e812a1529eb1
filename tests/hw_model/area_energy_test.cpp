// Technology tables (strict parsing) and the area/energy evaluator: linearity in the counts,
// the table's scaling rules, monotonicity in units, and a hand-computed small machine.

#include "hw_model/area_energy.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "base/input_error.h"

using namespace sfx;

namespace {

// Round numbers, so the hand-computed example below can be checked by eye.
const char* k_test_table = R"(version: 1
name: test
node_nm: 90
vdd_v: 1.2
gate_delay_vs_90nm: 1
sram:
  ref_kib: 16
  area_mm2: 0.25
  area_exponent: 1.0
  read_pj: 10
  read_exponent: 0.5
  write_pj: 8
  write_exponent: 0.5
  leakage_mw: 2
  leakage_exponent: 1.0
  port_area_factor: 2
  port_energy_factor: 1.5
  port_leakage_factor: 1
cache:
  ref_kib: 32
  area_mm2: 1.0
  area_exponent: 1.0
  lookup_pj: 100
  lookup_exponent: 0.5
  fill_pj: 200
  fill_exponent: 0.5
  leakage_mw: 4
  leakage_exponent: 1.0
logic:
  fp32_add_pj: 1
  fp32_add_um2: 1000
  fp32_mul_pj: 3
  fp32_mul_um2: 2000
  int32_add_pj: 0.5
  int32_add_um2: 100
  int32_mul_pj: 2
  int32_mul_um2: 1500
  compare32_pj: 0.25
  compare32_um2: 50
  register32_pj: 0.5
  register32_um2: 200
  leakage_mw_per_mm2: 10
dram_pj_per_bit: 10
idle_leakage_fraction: 0.5
)";

// 1-based line of the first line of `text` containing `needle`.
std::string line_of(const std::string& text, const std::string& needle) {
    const size_t at = text.find(needle);
    return std::to_string(1 + std::count(text.begin(), text.begin() + long(at), '\n'));
}

const UnitCost& unit(const AreaEnergy& r, const std::string& name) {
    for (const UnitCost& u : r.units)
        if (u.unit == name) return u;
    FAIL("no unit " << name);
    return r.units.front();
}

ActionCounts some_counts(uint64_t k) {
    ActionCounts a;
    a.bank_reads = 1000 * k;
    a.bank_writes = 300 + k;
    a.agu_addresses = 77 * k;
    a.simd_instructions[size_t(OpKind::box_test)] = 5 * k;
    a.simd_lane_ops[size_t(OpKind::box_test)] = 60 * k;
    a.simd_lane_ops[size_t(OpKind::triangle_test)] = 13 + k;
    a.partition_compares = 9 * k;
    a.partition_moves = 4 * k;
    a.scratchpad_accesses = 31 * k;
    a.interconnect_word_hops = 400 * k;
    a.cache_accesses = {50 * k, 20 * k, 5 * k};
    a.cache_fills = {20 * k, 5 * k, 2 * k};
    a.dram_bytes = 128 * k;
    for (uint32_t u = 0; u < k_hw_unit_count; ++u) a.busy_cycles[u] = 100 * k + u;
    return a;
}

}  // namespace

TEST_CASE("Shipped technology tables parse, and every number is required", "[hw_model][energy]") {
    for (const std::string& name : builtin_tech_names()) {
        const TechTable t = resolve_tech_table(name);
        CHECK(t.name == name);
        CHECK(t.sram.read_pj > 0);
        CHECK(t.logic.fp32_mul_pj > t.logic.fp32_add_pj);
    }
    CHECK(default_tech_table().node_nm == 90);  // the paper's node
    // The scaled node spends less per operation and per um2.
    const TechTable t90 = resolve_tech_table("90nm"), t45 = resolve_tech_table("45nm");
    CHECK(t45.logic.fp32_add_pj < t90.logic.fp32_add_pj);
    CHECK(t45.sram.area_mm2 < t90.sram.area_mm2);
}

TEST_CASE("Bad technology tables name file, line and key", "[hw_model][energy]") {
    const std::string good = k_test_table;
    auto message = [](const std::string& text) {
        try {
            parse_tech_table(text, "t.tech.yaml");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(message(good) == "no error");
    std::string unknown = good;
    unknown.replace(unknown.find("  read_pj: 10"), 13, "  read_pJ: 10");
    // The allowed keys are listed, so the right spelling is in the message.
    CHECK_THAT(message(unknown), Catch::StartsWith("t.tech.yaml:" + line_of(good, "read_pj") +
                                                   ": sram.read_pJ: unknown key (allowed: ") &&
                                     Catch::Contains(" read_pj,"));
    std::string missing = good;
    missing.erase(missing.find("dram_pj_per_bit: 10\n"), 20);
    CHECK(message(missing).find("t.tech.yaml: dram_pj_per_bit: missing") == 0);
    std::string missing_nested = good;
    missing_nested.erase(missing_nested.find("  fill_pj: 200\n"), 15);
    // A missing key in a group: the line where the group's mapping starts.
    CHECK(message(missing_nested)
              .find("t.tech.yaml:" + line_of(good, "ref_kib: 32") + ": cache.fill_pj: missing") ==
          0);
    std::string range = good;
    range.replace(range.find("idle_leakage_fraction: 0.5"), 26, "idle_leakage_fraction: 2");
    CHECK(message(range).find("t.tech.yaml:" + line_of(good, "idle_leakage") +
                              ": idle_leakage_fraction: value 2 is outside") == 0);
    std::string type = good;
    type.replace(type.find("fp32_add_pj: 1\n"), 15, "fp32_add_pj: one\n");
    CHECK(message(type) == "t.tech.yaml:" + line_of(good, "fp32_add_pj") +
                               ": logic.fp32_add_pj: expected a finite number");
    std::string bank_rule = good;  // more banks must never mean less area
    bank_rule.replace(bank_rule.find("area_exponent: 1.0"), 18, "area_exponent: 1.1");
    CHECK(message(bank_rule).find("t.tech.yaml:" + line_of(good, "area_exponent") +
                                  ": sram.area_exponent: value 1.1 is outside") == 0);
    CHECK_THROWS_WITH(resolve_tech_table("no_such_table"), Catch::Contains("--tech"));
    CHECK_THROWS_AS(load_tech_table("/no/such/file.tech.yaml"), InputError);
}

TEST_CASE("Energy is linear in the action counts", "[hw_model][energy]") {
    const TechTable t = resolve_tech_table("90nm");
    const HwConfig c;
    const ActionCounts a = some_counts(3), b = some_counts(7);
    ActionCounts sum = a;
    sum += b;
    const AreaEnergy ea = evaluate_area_energy(c, a, 10000, t),
                     eb = evaluate_area_energy(c, b, 20000, t),
                     esum = evaluate_area_energy(c, sum, 30000, t);
    for (size_t i = 0; i < esum.units.size(); ++i) {
        INFO(esum.units[i].unit);
        CHECK(esum.units[i].dynamic_mj == Approx(ea.units[i].dynamic_mj + eb.units[i].dynamic_mj));
        CHECK(esum.units[i].leakage_mj == Approx(ea.units[i].leakage_mj + eb.units[i].leakage_mj));
    }
    ActionCounts twice;
    twice.add_scaled(a, 2.0);
    CHECK(evaluate_area_energy(c, twice, 20000, t).total_energy_mj() ==
          Approx(2 * ea.total_energy_mj()));
    // Subtraction undoes addition (timing_between of two snapshots).
    ActionCounts back = sum;
    back -= b;
    CHECK(back == a);
    CHECK(evaluate_area_energy(c, ActionCounts{}, 0, t).total_energy_mj() == 0.0);
}

TEST_CASE("Doubling a bank's size raises its area and access energy by the table's rule",
          "[hw_model][energy]") {
    for (const std::string& name : builtin_tech_names()) {
        const TechTable t = resolve_tech_table(name);
        HwConfig small, large;
        large.ray_buffer.kib = 2 * small.ray_buffer.kib;  // same banks: each bank doubles
        ActionCounts reads;
        reads.bank_reads = 1000;
        ActionCounts writes;
        writes.bank_writes = 1000;
        auto rb = [&](const HwConfig& c, const ActionCounts& n) {
            return unit(evaluate_area_energy(c, n, 0, t), "ray_buffer");
        };
        INFO(name);
        CHECK(rb(large, reads).area_mm2 / rb(small, reads).area_mm2 ==
              Approx(std::pow(2.0, t.sram.area_exponent)));
        CHECK(rb(large, reads).dynamic_mj / rb(small, reads).dynamic_mj ==
              Approx(std::pow(2.0, t.sram.read_exponent)));
        CHECK(rb(large, writes).dynamic_mj / rb(small, writes).dynamic_mj ==
              Approx(std::pow(2.0, t.sram.write_exponent)));
        CHECK(rb(large, reads).area_mm2 > rb(small, reads).area_mm2);
        CHECK(rb(large, reads).dynamic_mj > rb(small, reads).dynamic_mj);
        // The reference bank is priced at the table's own numbers.
        HwConfig ref;
        ref.ray_buffer.kib = uint32_t(t.sram.ref_kib) * ref.ray_buffer.banks;
        CHECK(rb(ref, reads).dynamic_mj == Approx(1000 * t.sram.read_pj * 1e-9));
        CHECK(rb(ref, reads).area_mm2 ==
              Approx(t.sram.area_mm2 * ref.ray_buffer.banks * ref.ray_buffer.buffers));
    }
}

TEST_CASE("More lanes or units never mean less area", "[hw_model][energy]") {
    for (const std::string& name : builtin_tech_names()) {
        const TechTable t = resolve_tech_table(name);
        INFO(name);
        auto area = [&](const HwConfig& c) { return area_per_unit(c, t).total_area_mm2(); };
        auto grows = [&](auto set, std::initializer_list<uint32_t> values) {
            double previous = 0;
            for (uint32_t v : values) {
                HwConfig c;
                set(c, v);
                INFO("value " << v);
                CHECK(area(c) >= previous);
                previous = area(c);
            }
        };
        grows([](HwConfig& c, uint32_t v) { c.simd.width = v; }, {1, 2, 4, 8, 12, 16, 32, 64});
        grows([](HwConfig& c, uint32_t v) { c.agu.count = v; }, {1, 2, 8, 32, 128});
        grows([](HwConfig& c, uint32_t v) { c.agu.addresses_per_cycle = v; }, {1, 2, 4});
        grows([](HwConfig& c, uint32_t v) { c.ray_buffer.banks = v; },
              {1, 2, 4, 8, 16, 32, 64, 128});
        grows([](HwConfig& c, uint32_t v) { c.ray_buffer.buffers = v; }, {2, 3, 4});
        grows([](HwConfig& c, uint32_t v) { c.ray_buffer.kib = v; }, {128, 256, 512, 1024});
        grows([](HwConfig& c, uint32_t v) { c.partition.comparators_per_lane = v; }, {1, 2, 4});
        grows([](HwConfig& c, uint32_t v) { c.simd.units = v; }, {1, 2, 4, 8});
        grows([](HwConfig& c, uint32_t v) { c.cores.count = v; }, {1, 2, 4});
        grows([](HwConfig& c, uint32_t v) { c.scratchpad.ports = v; }, {1, 2, 3, 4});
        grows([](HwConfig& c, uint32_t v) { c.scratchpad.kib = v; }, {16, 32, 64, 128});
        grows([](HwConfig& c, uint32_t v) { c.interconnect.width_words = v; }, {4, 8, 16, 32});
        grows([](HwConfig& c, uint32_t v) { c.interconnect.mux_levels = v; }, {1, 2, 3, 4});
        grows([](HwConfig& c, uint32_t v) { c.scene_memory.caches[2].kib = v; },
              {512, 1024, 2048, 4096});
    }
}

TEST_CASE("A small machine's area and energy equal a hand computation", "[hw_model][energy]") {
    const TechTable t = parse_tech_table(k_test_table, "test.tech.yaml");
    HwConfig c;
    c.clock.core_mhz = 500;  // 2 ns a cycle
    c.ray_buffer.kib = 32;   // 2 banks of 16 KiB (the reference size), 2 buffers: 4 macros
    c.ray_buffer.banks = 2;
    c.ray_buffer.buffers = 2;
    c.agu.count = 2;
    c.agu.addresses_per_cycle = 1;
    c.simd.width = 4;
    c.simd.units = 1;
    c.datapath.issue = "programmable";  // an instruction a cycle: one FPU per lane
    c.cores.count = 1;
    c.partition.comparators_per_lane = 1;  // 4 comparators
    c.scratchpad.kib = 64;                 // 4x the reference, two ports
    c.scratchpad.ports = 2;
    c.interconnect.width_words = 4;
    c.interconnect.mux_levels = 2;
    c.scene_memory.caches.resize(1);
    c.scene_memory.caches[0].name = "l1";
    c.scene_memory.caches[0].kib = 128;  // 4x the reference
    c.scene_memory.caches[0].line_bytes = 64;
    c.scene_memory.caches[0].ways = 8;

    ActionCounts n;
    n.bank_reads = 1000;
    n.bank_writes = 500;
    n.agu_addresses = 100;
    n.simd_lane_ops[size_t(OpKind::box_test)] = 10;
    n.partition_compares = 20;
    n.scratchpad_accesses = 40;
    n.interconnect_word_hops = 60;
    n.cache_accesses[0] = 7;
    n.cache_fills[0] = 3;
    n.dram_bytes = 64;
    n.busy_cycles = {600, 200, 400,
                     100, 50,  1000};  // ray_buffer agu simd partition scratchpad interconnect
    const AreaEnergy r = evaluate_area_energy(c, n, 1000, t);

    // Areas (mm2).
    CHECK(unit(r, "ray_buffer").area_mm2 == Approx(4 * 0.25));
    CHECK(unit(r, "agu").area_mm2 == Approx(2 * (100 + 200) * 1e-6));
    CHECK(unit(r, "simd").area_mm2 == Approx(4 * (1000 + 2000) * 1e-6));
    CHECK(unit(r, "partition").area_mm2 == Approx(4 * 50 * 1e-6));
    CHECK(unit(r, "scratchpad").area_mm2 == Approx(0.25 * 4 * 2));  // 4x the size, 2 ports
    CHECK(unit(r, "interconnect").area_mm2 == Approx(4 * 2 * 200 * 1e-6));
    CHECK(unit(r, "cache_l1").area_mm2 == Approx(1.0 * 4));
    CHECK(unit(r, "dram").area_mm2 == 0);
    CHECK(r.total_area_mm2() == Approx(7.0144));

    // Dynamic energy (pJ -> mJ: 1e-9).
    CHECK(unit(r, "ray_buffer").dynamic_mj == Approx((1000 * 10 + 500 * 8) * 1e-9));
    CHECK(unit(r, "agu").dynamic_mj == Approx(100 * 0.5 * 1e-9));
    CHECK(unit(r, "simd").dynamic_mj == Approx(10 * (1 + 3) * 1e-9));
    CHECK(unit(r, "partition").dynamic_mj == Approx(20 * 0.25 * 1e-9));
    // 64 KiB, 2 ports: read 10 x 2 x 1.5 = 30 pJ, write 8 x 2 x 1.5 = 24 pJ; half of each.
    CHECK(unit(r, "scratchpad").dynamic_mj == Approx(40 * (30 + 24) / 2.0 * 1e-9));
    CHECK(unit(r, "interconnect").dynamic_mj == Approx(60 * 0.5 * 1e-9));
    CHECK(unit(r, "cache_l1").dynamic_mj == Approx((7 * 200 + 3 * 400) * 1e-9));  // x sqrt(4)
    CHECK(unit(r, "dram").dynamic_mj == Approx(64 * 8 * 10 * 1e-9));

    // Leakage: mW x (busy + 0.5 idle) cycles x 2 ns; caches leak the whole frame.
    CHECK(unit(r, "ray_buffer").leakage_mj == Approx(4 * 2 * (600 + 0.5 * 400) * 2e-9));
    CHECK(unit(r, "simd").leakage_mj == Approx(0.012 * 10 * (400 + 0.5 * 600) * 2e-9));
    CHECK(unit(r, "scratchpad").leakage_mj == Approx(2 * 4 * (50 + 0.5 * 950) * 2e-9));
    CHECK(unit(r, "interconnect").leakage_mj == Approx(0.0016 * 10 * 1000 * 2e-9));
    CHECK(unit(r, "cache_l1").leakage_mj == Approx(4 * 4 * 1000 * 2e-9));
    CHECK(unit(r, "dram").leakage_mj == 0);
    CHECK(r.leakage_mj() == Approx(5.34094e-5));
    CHECK(r.total_energy_mj() == Approx(2.2925e-5 + 5.34094e-5));

    // A cluster (datapath.issue: cluster): every function unit as wide as the SIMD unit; an
    // FPU an adder and a multiplier, an ALU an integer adder, a multiplier an integer one.
    HwConfig cluster = c;
    cluster.datapath.issue = "cluster";
    cluster.datapath.fpu_units = 3;
    cluster.datapath.alu_units = 2;
    cluster.datapath.mul_units = 1;
    const AreaEnergy rc = evaluate_area_energy(cluster, n, 1000, t);
    CHECK(unit(rc, "simd").area_mm2 == Approx(4 * (3 * (1000 + 2000) + 2 * 100 + 1 * 1500) * 1e-6));
    CHECK(unit(rc, "simd").dynamic_mj == Approx(unit(r, "simd").dynamic_mj));
    cluster.datapath.alu_units = 3;
    CHECK(unit(evaluate_area_energy(cluster, n, 1000, t), "simd").area_mm2 >
          unit(rc, "simd").area_mm2);

    // Two cores: every unit twice but a shared cache level; the same work over twice the
    // capacity leaks more idle cycles.
    HwConfig two = c;
    two.cores.count = 2;
    two.scene_memory.caches[0].shared = true;
    const AreaEnergy r2 = evaluate_area_energy(two, n, 1000, t);
    CHECK(unit(r2, "ray_buffer").area_mm2 == Approx(2 * 4 * 0.25));
    CHECK(unit(r2, "simd").area_mm2 == Approx(2 * 0.012));
    CHECK(unit(r2, "cache_l1").area_mm2 == Approx(4.0));
    CHECK(unit(r2, "ray_buffer").dynamic_mj == Approx(unit(r, "ray_buffer").dynamic_mj));
    // 4 macros of 2 mW per core, over the cores' 600 busy and 1400 idle core-cycles.
    CHECK(unit(r2, "ray_buffer").leakage_mj == Approx(4 * 2 * (600 + 0.5 * 1400) * 2e-9));
}
