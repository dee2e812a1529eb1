// Explore files: strict parsing (file, line and dotted key for every section), the numbering of
// configurations, points whose keys are a sweep's (so either reuses the other's rows), the
// combination over workloads, constraints and the Pareto front; every shipped explore parses.

#include <catch2/catch.hpp>

#include <filesystem>

#include "base/input_error.h"
#include "sweeps/explore.h"

using namespace sfx;

namespace {

const std::string k_presets = SFX_SOURCE_DIR "/hw_model/presets";

ExploreSpec parse(const std::string& text, const std::vector<std::string>& sets = {}) {
    return parse_explore(text, "t.yaml", k_presets, sets);
}

const char* const k_good =
    "version: 1\n"                                  // 1
    "name: t\n"                                     // 2
    "hw: gr08.hw.yaml\n"                            // 3
    "workload: {res: 16x16, spp: 1, tile: 8}\n"     // 4
    "workloads:\n"                                  // 5
    "  - {scene: cornell, weight: 3}\n"             // 6
    "  - {scene: furnace}\n"                        // 7
    "knobs:\n"                                      // 8
    "  hw.simd.width: [4, 8, 16]\n"                 // 9
    "  hw.simd.units: [1, 2]\n"                     // 10
    "objectives: {fps: maximize, area_mm2: minimize}\n"  // 11
    "constraints: {area_mm2: {max: 50}, fps: {min: 1}}\n"  // 12
    "budget: {evaluations: 4}\n";                   // 13

// The file with line `n` (1-based) replaced by `line` (empty: removed).
std::string with_line(int n, const std::string& line) {
    std::string out, text = k_good;
    int i = 1;
    size_t start = 0;
    while (start < text.size()) {
        const size_t end = text.find('\n', start);
        const std::string l = text.substr(start, end - start);
        if (i == n) {
            if (!line.empty()) out += line + "\n";
        } else {
            out += l + "\n";
        }
        start = end + 1;
        ++i;
    }
    return out;
}

}  // namespace

TEST_CASE("An explore file parses into its space, objectives, constraints and budget", "[sweeps]") {
    const ExploreSpec s = parse(k_good);
    CHECK(s.name == "t");
    REQUIRE(s.workloads.size() == 2);
    CHECK(s.workloads[0].weight == 3);
    CHECK(s.workloads[1].weight == 1);
    CHECK(s.knob_count() == 2);
    CHECK(s.configurations() == 6);
    CHECK(s.budget_evaluations == 4);
    REQUIRE(s.objectives.size() == 2);
    CHECK((s.objectives[0].metric == "fps" && s.objectives[0].maximize));
    CHECK((s.objectives[1].metric == "area_mm2" && !s.objectives[1].maximize));
    REQUIRE(s.constraints.size() == 2);
    CHECK((s.constraints[0].has_max && s.constraints[0].max == 50 && !s.constraints[0].has_min));
    CHECK(s.screen == Fidelity::analytic);
    CHECK(s.confirm == Fidelity::sampled);
    CHECK(s.sampler == "tpe");
    // The last knob moves fastest; positions and numbers convert both ways.
    for (size_t c = 0; c < s.configurations(); ++c) CHECK(s.config_of(s.knob_positions(c)) == c);
    CHECK(s.knob_positions(3) == std::vector<size_t>{1, 1});
    const auto knobs = s.knob_values(3);
    REQUIRE(knobs.size() == 2);
    CHECK(knobs[0] == std::make_pair(std::string("hw.simd.width"), std::string("8")));
    CHECK(knobs[1] == std::make_pair(std::string("hw.simd.units"), std::string("2")));
    // Points: the workload's scene, the knobs' values, the fidelity asked for.
    const SweepPoint p = s.point(1, 3, Fidelity::sampled);
    CHECK(p.workload.scene == "furnace");
    CHECK(p.hw.simd.width == 8);
    CHECK(p.hw.simd.units == 2);
    CHECK(p.fidelity == Fidelity::sampled);
    CHECK(p.key == point_key(point_config_yaml(p.hw, p.workload, p.fidelity)));
    CHECK(s.point(1, 3, Fidelity::analytic).key != p.key);
    // A budget above the space is the space; --set changes the base, and the fingerprint.
    CHECK(parse(with_line(13, "budget: {evaluations: 100}")).budget_evaluations == 6);
    const ExploreSpec big = parse(k_good, {"workload.res=32x32"});
    CHECK(big.point(0, 0, Fidelity::analytic).workload.width == 32);
    CHECK(big.fingerprint() != s.fingerprint());
    CHECK(parse(k_good).fingerprint() == s.fingerprint());
    // A larger budget goes on with the same search; other constraints or weights start anew.
    CHECK(parse(with_line(13, "budget: {evaluations: 5}")).fingerprint() == s.fingerprint());
    CHECK(parse(with_line(12, "constraints: {area_mm2: {max: 40}}")).fingerprint() != s.fingerprint());
    CHECK(parse(with_line(7, "  - {scene: furnace, weight: 2}")).fingerprint() != s.fingerprint());
}

TEST_CASE("An explore configuration's point has the key a sweep of the same values gives", "[sweeps]") {
    // So a point either ran is reused by the other, never run twice.
    const ExploreSpec e = parse(k_good);
    const Sweep sweep = parse_sweep(
        "version: 1\nhw: gr08.hw.yaml\nworkload: {scene: cornell, res: 16x16, spp: 1, tile: 8}\n"
        "fidelity: analytic\naxes:\n  workload.scene: [cornell, furnace]\n"
        "  hw.simd.width: [4, 8, 16]\n  hw.simd.units: [1, 2]\n",
        "t.sweep.yaml", k_presets);
    std::set<std::string> sweep_keys;
    for (const SweepPoint& p : sweep.all_points()) sweep_keys.insert(p.key);
    std::set<std::string> explore_keys;
    for (size_t w = 0; w < 2; ++w)
        for (size_t c = 0; c < e.configurations(); ++c) explore_keys.insert(e.point(w, c, Fidelity::analytic).key);
    CHECK(explore_keys == sweep_keys);
}

TEST_CASE("Bad explore files name file, line and key", "[sweeps]") {
    struct Case {
        std::string text;
        int line;
        std::string key, what;
    };
    const std::vector<Case> cases = {
        {with_line(2, "nmae: t"), 2, "nmae", "unknown key"},
        {with_line(11, ""), 1, "objectives", "missing"},
        {with_line(6, "  - scene"), 6, "workloads[0]", "expected a mapping"},
        {with_line(6, "  - {weight: 2}"), 6, "workloads[0].scene", "missing"},
        {with_line(6, "  - {scene: cornel}"), 6, "workloads[0].scene", "no such scene"},
        {with_line(7, "  - {scene: furnace, weight: 0}"), 7, "workloads[1].weight", "positive"},
        {with_line(7, "  - {scene: cornell}"), 7, "workloads[1].scene", "twice"},
        {with_line(9, "  hw.simd.widht: [4, 8]"), 9, "knobs.hw.simd.widht", "no such hardware parameter"},
        {with_line(9, "  workload.spp: [1, 2]"), 9, "knobs.workload.spp", "hardware path"},
        {with_line(9, "  hw.simd.width: [4, 100]"), 9, "knobs.hw.simd.width", "outside"},
        {with_line(11, "objectives: {fps: maximise}"), 11, "objectives.fps", "maximize, minimize"},
        {with_line(11, "objectives: {speed: maximize}"), 11, "objectives.speed", "unknown key"},
        {with_line(12, "constraints: {area_mm2: {most: 50}}"), 12, "constraints.area_mm2.most", "unknown key"},
        {with_line(12, "constraints: {area_mm2: {max: lots}}"), 12, "constraints.area_mm2.max", "a number"},
        {with_line(12, "constraints: {fps: {min: 5, max: 1}}"), 12, "constraints.fps.max", "below min"},
        {with_line(13, "budget: {evaluations: 0}"), 13, "budget.evaluations", "outside"},
        {with_line(13, "budget: {}"), 13, "budget", "evaluations, host_seconds"},
        {with_line(13, "budget: {evaluations: 4}\nfidelity: {screen: fast}"), 14, "fidelity.screen", "analytic"},
        {with_line(13, "budget: {evaluations: 4}\nsearch: {sampler: grid}"), 14, "search.sampler", "tpe, nsga2, random"},
        {with_line(13, "budget: {evaluations: 4}\nsearch: {batch: -1}"), 14, "search.batch", "whole number"},
        {with_line(4, "workload: {scene: cornell, res: 16x16}"), 4, "workload.scene", "unknown key"},
    };
    for (const Case& c : cases) {
        INFO(c.text);
        try {
            parse(c.text);
            FAIL("no InputError");
        } catch (const InputError& e) {
            INFO(e.what());
            CHECK(e.file() == "t.yaml");
            CHECK(e.line() == c.line);
            CHECK(e.key().rfind(c.key, 0) == 0);
            CHECK(std::string(e.what()).find(c.what) != std::string::npos);
        }
    }
}

TEST_CASE("Scores combine over workloads by weight, constraints and the front follow them", "[sweeps]") {
    const ExploreSpec s = parse(k_good);  // weights 3 and 1
    const std::vector<std::map<std::string, double>> numbers = {
        {{"fps", 10}, {"energy.total_per_frame_mj", 2}, {"area.total_mm2", 40}, {"error.relative", 0.05}},
        {{"fps", 40}, {"energy.total_per_frame_mj", 6}, {"area.total_mm2", 40}, {"error.relative", 0.1}}};
    const ExploreScore x = combine_workloads(s, numbers);
    CHECK(x.fps == Approx(4.0 / (3.0 / 10 + 1.0 / 40)));  // total weight over weighted frame time
    CHECK(x.energy_mj == Approx((3 * 2 + 6) / 4.0));
    CHECK(x.power_w == Approx(x.energy_mj * 1e-3 * x.fps));
    CHECK(x.area_mm2 == 40);
    CHECK(x.fps_per_mm2 == Approx(x.fps / 40));
    CHECK(x.fps_error == Approx(0.1));
    auto unknown = numbers;
    unknown[1]["error.relative"] = -1;
    CHECK(combine_workloads(s, unknown).fps_error == -1);

    // Constraints: area <= 50, fps >= 1 (scaled by the bound; <= 0 met).
    ExploreScore a;
    a.fps = 3, a.area_mm2 = 45;
    CHECK(feasible(s, a));
    const std::vector<double> c = constraint_values(s, a);
    CHECK(c[0] == Approx(-0.1));
    CHECK(c[1] == Approx(-2.0));
    ExploreScore too_big = a;
    too_big.area_mm2 = 55;
    CHECK(!feasible(s, too_big));
    CHECK(constraint_values(s, too_big)[0] == Approx(0.1));

    // Front of (fps max, area min): b dominates d; e is infeasible though fastest; f is slower
    // than a but smaller.
    ExploreScore b = a, d = a, e = a, f = a;
    b.fps = 5, b.area_mm2 = 48;
    d.fps = 4, d.area_mm2 = 49;
    e.fps = 50, e.area_mm2 = 60;
    f.fps = 2, f.area_mm2 = 44;
    CHECK(pareto_front(s, {a, b, d, e, f}) == std::vector<size_t>{0, 1, 4});
    CHECK(objective_values(s, b) == std::vector<double>{5, 48});
}

TEST_CASE("Every shipped explore file parses", "[sweeps]") {
    size_t found = 0;
    for (const char* dir : {"/sweeps", "/bench"})
        for (const auto& entry : std::filesystem::directory_iterator(SFX_SOURCE_DIR + std::string(dir))) {
            const std::string name = entry.path().filename().string();
            if (name.rfind("explore-", 0) != 0 || entry.path().extension() != ".yaml") continue;
            INFO(entry.path());
            const ExploreSpec s = load_explore(entry.path().string());
            CHECK(s.configurations() >= 100);
            ++found;
        }
    CHECK(found >= 3);
}
