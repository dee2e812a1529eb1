// Technology nodes: the tables below 45 nm against Stillmaker & Baas's factors computed by hand,
// the chain 90 -> 45 -> 7 nm, each node's clock (G&R 3.3's critical paths), the node as a
// configuration key, a sweep axis and an explore knob, and one configuration at 90 and 7 nm.

#include <catch2/catch.hpp>
#include <cmath>
#include <functional>

#include "base/input_error.h"
#include "hw_model/area_energy.h"
#include "hw_model/node_clock.h"
#include "hw_model/tech_table.h"
#include "kernels/bvh.h"
#include "sweeps/explore.h"
#include "sweeps/point_group.h"
#include "sweeps/sweep.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

// [SB17]'s fits evaluated by hand (hw_model/tech/scale_tech.py holds the coefficients):
//   delay 90 nm at 1.2 V: -60.34 x 1.728 + 262.5 x 1.44 - 384.2 x 1.2 + 210.9 = 23.59
//   delay HP 7 nm at 0.7 V: -28.58 x 0.343 + 76.6 x 0.49 - 70.26 x 0.7 + 24.69 = 3.239
//   energy 90 nm at 1.2 V: 4.762 x 1.44 - 4.781 x 1.2 + 2.092 = 3.212
//   energy LP 45 nm at 0.9 V: 1.103 x 0.81 - 0.362 x 0.9 + 0.2767 = 0.8443
//   energy HP 7 nm at 0.7 V: 0.1776 x 0.49 - 0.09097 x 0.7 + 0.02447 = 0.04782
//   area 45 -> 7 nm: 0.059, 90 -> 7 nm: 0.021 (two significant figures)
constexpr double k_delay_90 = 23.59, k_delay_7 = 3.239;
constexpr double k_energy_90 = 3.212, k_energy_45 = 0.8443, k_energy_7 = 0.04782;

HwConfig at_node(const std::string& node) {
    HwConfig c;
    c.tech.node = node;
    resolve_node_clocks(c);
    return c;
}

// gr08 on a small cornell frame at 90 and 7 nm: the node as a sweep axis.
Sweep node_sweep() {
    return parse_sweep("version: 1\nhw: gr08\nworkload: {scene: cornell, res: 32x32, spp: 1, tile: 16}\n"
                       "fidelity: full\naxes:\n  hw.tech.node: [90nm, 7nm]\n",
                       "n.sweep.yaml", SFX_SOURCE_DIR "/sweeps");
}

InputError error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e;
    }
    FAIL("no InputError");
    return InputError("", 0, "", "");
}

}  // namespace

TEST_CASE("Every shipped technology table loads, 90 nm to 7 nm", "[tech]") {
    const std::vector<std::string> expected = {"90nm", "45nm", "32nm", "22nm",
                                               "14nm", "10nm", "7nm"};
    CHECK(builtin_tech_names() == expected);
    double previous_area = 1e9;
    for (const std::string& name : expected) {
        INFO(name);
        const TechTable& t = tech_table_for(name);
        CHECK(t.name == name);
        CHECK(t.logic.fp32_add_um2 < previous_area);  // logic shrinks at every node
        previous_area = t.logic.fp32_add_um2;
    }
}

TEST_CASE("The 7 nm table is the 45 nm table times hand-computed [SB17] factors", "[tech]") {
    const TechTable &t45 = tech_table_for("45nm"), &t7 = tech_table_for("7nm");
    // Four significant figures in the tables: 1e-3 relative.
    const double energy = k_energy_7 / k_energy_45;  // 0.05663
    CHECK(t7.logic.fp32_add_pj / t45.logic.fp32_add_pj == Approx(energy).epsilon(1e-3));
    CHECK(t7.sram.read_pj / t45.sram.read_pj == Approx(energy).epsilon(1e-3));
    CHECK(t7.cache.lookup_pj / t45.cache.lookup_pj == Approx(energy).epsilon(1e-3));
    CHECK(t7.sram.leakage_mw / t45.sram.leakage_mw == Approx(energy).epsilon(1e-3));
    CHECK(t7.logic.fp32_mul_um2 / t45.logic.fp32_mul_um2 == Approx(0.059).epsilon(1e-3));
    CHECK(t7.logic.leakage_mw_per_mm2 / t45.logic.leakage_mw_per_mm2 ==
          Approx(energy / 0.059).epsilon(1e-3));
    // SRAM from published bit cells: TSMC N7 0.027 um2 over Intel 45 nm 0.346 um2.
    CHECK(t7.sram.area_mm2 / t45.sram.area_mm2 == Approx(0.027 / 0.346).epsilon(1e-3));
    CHECK(t7.cache.area_mm2 / t45.cache.area_mm2 == Approx(0.027 / 0.346).epsilon(1e-3));
    CHECK(t7.gate_delay_vs_90nm == Approx(k_delay_7 / k_delay_90).epsilon(1e-3));
    CHECK(t7.sram.area_exponent == t45.sram.area_exponent);  // organisation kept
}

TEST_CASE("Chaining the tables 90 -> 45 -> 7 nm reproduces [SB17]'s direct factors", "[tech]") {
    const TechTable &t90 = tech_table_for("90nm"), &t45 = tech_table_for("45nm"),
                    &t7 = tech_table_for("7nm");
    auto chained = [](double a90, double a45, double a7) { return (a45 / a90) * (a7 / a45); };
    // Energy: the fits are exact functions, so the chain is exact up to the tables' rounding
    // (the 90 nm table's 3.42 pJ is 0.9 x 3.804 rounded): 0.5 %.
    CHECK(chained(t90.logic.fp32_add_pj, t45.logic.fp32_add_pj, t7.logic.fp32_add_pj) ==
          Approx(k_energy_7 / k_energy_90).epsilon(5e-3));
    // Area: [SB17] prints 2.8 (45 -> 90) and 0.059 (45 -> 7) and, directly, 0.021 (90 -> 7),
    // each to two significant figures: 0.021 stands for [0.0205, 0.0215].
    const double area =
        chained(t90.logic.fp32_add_um2, t45.logic.fp32_add_um2, t7.logic.fp32_add_um2);
    CHECK(area >= 0.0205);
    CHECK(area <= 0.0215);
    CHECK(chained(t90.gate_delay_vs_90nm, t45.gate_delay_vs_90nm, t7.gate_delay_vs_90nm) ==
          Approx(k_delay_7 / k_delay_90).epsilon(1e-3));
}

TEST_CASE("A configuration's clocks follow its node unless written", "[tech]") {
    // G&R 3.3: partitioning units and interconnect at 500 MHz at 90 nm bind both domains.
    const HwConfig c90 = at_node("90nm");
    CHECK(c90.clock.core_mhz == 500.0);  // exactly: gr08's predictions at 90 nm do not move
    CHECK(c90.clock.interconnect_mhz == 500.0);
    const HwConfig c7 = at_node("7nm");
    const double scale = 1.0 / tech_table_for("7nm").gate_delay_vs_90nm;  // 7.28
    CHECK(c7.clock.core_mhz == Approx(500 * scale));
    CHECK(c7.clock.interconnect_mhz == Approx(500 * scale));
    CHECK(std::string(node_clock("core_mhz", tech_table_for("7nm")).path->name) ==
          "partitioning units");
    // The execution units' path (1 GHz at 130 nm) never binds: 1355 MHz at 90 nm.
    for (const ClockPath& p : clock_paths())
        if (std::string(p.name) == "address fetch and execution units")
            CHECK(p.mhz * p.gate_delay_vs_90nm == Approx(1355));

    // A written clock is kept: below its node's clock silently, above it with a warning
    // that names the path.
    HwConfig slow = load_hw_config("gr08");
    set_hw_param(slow, "tech.node", "7nm");
    set_hw_param(slow, "clock.core_mhz", "1000");
    CHECK(resolve_node_clocks(slow).empty());
    CHECK(slow.clock.core_mhz == 1000.0);
    CHECK(slow.clock.interconnect_mhz == Approx(500 * scale));  // not written: follows

    HwConfig fast = parse_hw_config("clock:\n  core_mhz: 800\n  interconnect_mhz: 600\n", "f.hw.yaml");
    const std::vector<std::string> warnings = resolve_node_clocks(fast);
    REQUIRE(warnings.size() == 2);
    CHECK_THAT(warnings[0], Catch::Contains("clock.core_mhz 800 MHz is above the 500 MHz") &&
                                Catch::Contains("partitioning units"));
    CHECK_THAT(warnings[1], Catch::Contains("flexible interconnect"));
    CHECK(fast.clock.core_mhz == 800.0);
    // A CPU core's clock is measured: G&R's paths are not its paths.
    fast.op_costs.push_back(OpCostConfig{});
    CHECK(resolve_node_clocks(fast).empty());
}

TEST_CASE("A bad node is an input error naming file, line and key", "[tech]") {
    const InputError file = error_of([] { parse_hw_config("version: 1\ntech:\n  node: 5nm\n", "bad.hw.yaml"); });
    CHECK(file.file() == "bad.hw.yaml");
    CHECK(file.line() == 3);
    CHECK(file.key() == "tech.node");
    CHECK_THAT(file.message(), Catch::Contains("'5nm' is neither a built-in technology") &&
                                   Catch::Contains("7nm"));
    const InputError typed = error_of([] { parse_hw_config("tech:\n  node: [7nm]\n", "bad.hw.yaml"); });
    CHECK(typed.key() == "tech.node");
    const InputError axis = error_of([] {
        parse_sweep("version: 1\nhw: gr08\nworkload: {scene: cornell, res: 8x8}\naxes:\n"
                    "  hw.tech.node: [7nm, 3nm]\n",
                    "n.sweep.yaml", SFX_SOURCE_DIR "/sweeps");
    });
    CHECK(axis.file() == "n.sweep.yaml");
    CHECK(axis.line() == 5);
    CHECK(axis.key() == "hw.tech.node");
    const InputError flag = error_of([] { tech_table_for("5nm", "--tech"); });
    CHECK(flag.key() == "--tech");
}

TEST_CASE("The node is a sweep axis: each point's clocks follow its node", "[tech][sweeps]") {
    const std::vector<SweepPoint> points = node_sweep().all_points();
    REQUIRE(points.size() == 2);
    CHECK(points[0].hw.clock.core_mhz == 500.0);
    CHECK(points[1].hw.tech.node == "7nm");
    CHECK(points[1].hw.clock.core_mhz == Approx(500 / tech_table_for("7nm").gate_delay_vs_90nm));
    CHECK(points[0].key != points[1].key);
    // The stored point is fully resolved: a worker re-reading it keeps its clocks.
    CHECK(parse_point_config(points[1].config_yaml, "p.yaml").hw.clock.core_mhz ==
          points[1].hw.clock.core_mhz);
    // A written clock above the node's is said once, not per point.
    const Sweep fast = parse_sweep("version: 1\nhw: gr08\nhw_overrides: {clock.core_mhz: 2000}\n"
                                   "workload: {scene: cornell, res: 8x8}\naxes:\n"
                                   "  hw.tech.node: [90nm, 45nm, 7nm]\n  hw.simd.width: [8, 16]\n",
                                   "f.sweep.yaml", SFX_SOURCE_DIR "/sweeps");
    CHECK(fast.warnings.size() == 2);  // above at 90 and 45 nm, not at 7 nm
}

TEST_CASE("The shipped 7 nm explore is built at 7 nm, at the node's clocks", "[tech][explore]") {
    const ExploreSpec e = load_explore(SFX_SOURCE_DIR "/sweeps/explore-7nm.yaml");
    CHECK(e.nodes() == std::vector<std::string>{"7nm"});
    CHECK(e.configurations() == 192 * 27);
    const SweepPoint p = e.point(0, 0, e.screen);
    CHECK(p.hw.clock.core_mhz == Approx(500 / tech_table_for("7nm").gate_delay_vs_90nm));
    CHECK(e.space.warnings.empty());
}

TEST_CASE("The same configuration at 7 nm: less area, less energy per frame, more fps than at "
          "90 nm",
          "[tech][sweeps]") {
    const std::vector<SweepPoint> points = node_sweep().all_points();
    REQUIRE(points.size() == 2);
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    const PointGroupResult r = run_point_group(scene, bvh, points[0].workload.render_settings(2),
                                               {points[0].hw, points[1].hw}, Fidelity::full);
    auto stat = [](const Prediction& p, const std::string& name) {
        for (const Stat& s : p.stats())
            if (s.name == name) return s.value;
        FAIL("no stat " << name);
        return 0.0;
    };
    const Prediction &p90 = r.predictions[0], &p7 = r.predictions[1];
    CHECK(stat(p90, "tech.node_nm") == 90);
    CHECK(stat(p7, "tech.node_nm") == 7);
    CHECK(stat(p7, "area.total_mm2") < stat(p90, "area.total_mm2"));
    CHECK(stat(p7, "energy.total_per_frame_mj") < stat(p90, "energy.total_per_frame_mj"));
    CHECK(p7.fps() > p90.fps());
    // Static power is reported apart from dynamic power, per unit; the parts sum to the whole.
    double parts = 0;
    for (const Stat& s : p7.stats())
        if (s.name.rfind("power.", 0) == 0 && s.name.find('.', 6) != std::string::npos) parts += s.value;
    CHECK(parts == Approx(stat(p7, "power.w")));
    CHECK(stat(p7, "power.ray_buffer.static_w") > 0);
    CHECK(stat(p7, "power.ray_buffer.dynamic_w") > 0);
}
