// Sweep files: strict parsing with file, line and dotted path; expansion (cross product, zip,
// ranges), grouping by render, point YAML round trips and keys; every shipped sweep expands.

#include <catch2/catch.hpp>

#include <filesystem>
#include <set>

#include "sweeps/sha256.h"
#include "sweeps/sweep.h"
#include "base/input_error.h"

using namespace sfx;

namespace {

const std::string k_presets = SFX_SOURCE_DIR "/hw_model/presets";

Sweep parse(const std::string& text, const std::vector<std::string>& sets = {}) {
    return parse_sweep(text, "t.sweep.yaml", k_presets, sets);
}

// The InputError a bad sweep throws (failing the test if none).
InputError error_of(const std::string& text, const std::vector<std::string>& sets = {}) {
    try {
        parse(text, sets);
    } catch (const InputError& e) {
        return e;
    }
    FAIL("no InputError for:\n" << text);
    return InputError("", 0, "", "");
}

const char* const k_head =
    "version: 1\n"
    "hw: gr08.hw.yaml\n"
    "workload: {scene: cornell, res: 16x16, spp: 1, tile: 8}\n"
    "fidelity: analytic\n";

std::string value_of(const SweepPoint& p, const std::string& axis) {
    for (const auto& [k, v] : p.axis_values)
        if (k == axis) return v;
    return "";
}

}  // namespace

TEST_CASE("SHA-256 matches the FIPS 180-4 test vectors", "[sweeps]") {
    // FIPS 180-4's examples, then lengths around the padding boundary (values from coreutils'
    // sha256sum): the point keys stay what the stores already hold.
    const std::vector<std::pair<std::string, const char*>> vectors = {
        {"", "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"},
        {"abc", "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"},
        {"abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq",
         "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"},
        {std::string(1000000, 'a'), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0"},
        {std::string(55, 'x'), "d5e285683cd4efc02d021a5c62014694958901005d6f71e89e0989fac77e4072"},
        {std::string(56, 'x'), "04c26261370ee7541549d16dee320c723e3fd14671e66a099afe0a377c16888e"},
        {std::string(63, 'x'), "75220b47218278e656f2013bb8f0c455a25eaf01e86c64924e9d48d89776d6f2"},
        {std::string(64, 'x'), "7ce100971f64e7001e8fe5a51973ecdfe1ced42befe7ee8d5fd6219506b5393c"},
        {std::string(65, 'x'), "9537c5fdf120482f7d58d25e9ed583f52c02b4e304ea814db1633ad565aed7e9"},
    };
    for (const auto& [text, hex] : vectors) {
        INFO("length " << text.size());
        CHECK(sha256_hex(text) == hex);
    }
}

TEST_CASE("Axes expand as a cross product, last axis fastest, zip groups move together", "[sweeps]") {
    const Sweep s = parse(std::string(k_head) +
                          "axes:\n"
                          "  hw.simd.width: [4, 8]\n"
                          "  workload.tile: [8, 16, 32]\n"
                          "  hw.ray_buffer.kib: {values: [256, 512, 1024]}\n"
                          "zip:\n"
                          "  - [workload.tile, hw.ray_buffer.kib]\n");
    REQUIRE(s.point_count == 6);
    CHECK(s.name == "t");
    CHECK(s.axes == std::vector<std::string>{"hw.simd.width", "workload.tile", "hw.ray_buffer.kib"});
    CHECK(s.all_points()[0].hw.simd.width == 4);
    CHECK(s.all_points()[0].workload.tile == 8);
    CHECK(s.all_points()[0].hw.ray_buffer.kib == 256);
    CHECK(s.all_points()[2].workload.tile == 32);
    CHECK(s.all_points()[2].hw.ray_buffer.kib == 1024);
    CHECK(s.all_points()[3].hw.simd.width == 8);
    CHECK(s.all_points()[3].workload.tile == 8);
    CHECK(value_of(s.all_points()[4], "hw.ray_buffer.kib") == "512");
    for (size_t i = 0; i < s.point_count; ++i) CHECK(s.all_points()[i].index == i);
    // One render per tile: both widths of a tile share it.
    REQUIRE(s.groups.size() == 3);
    for (const PointGroup& g : s.groups) {
        REQUIRE(g.points.size() == 2);
        CHECK(s.point(g.points[0]).workload == s.point(g.points[1]).workload);
        CHECK(s.point(g.points[0]).hw.simd.width != s.point(g.points[1]).hw.simd.width);
    }
}

TEST_CASE("Ranges, overrides, command-line sets and the scene's depth", "[sweeps]") {
    const Sweep s = parse(std::string(k_head) +
                          "hw_overrides:\n"
                          "  ray_buffer.banks: 16\n"
                          "  clock.core_mhz: 250\n"
                          "axes:\n"
                          "  hw.ray_buffer.kib: {from: 128, to: 512, step: 128}\n"
                          "  hw.scene_memory.dram_bandwidth_gbps: {from: 0.5, to: 1.5, step: 0.5}\n",
                          {"workload.spp=2", "hw.scene_memory.caches[0].kib=64"});
    REQUIRE(s.point_count == 12);
    CHECK(s.all_points()[0].hw.ray_buffer.kib == 128);
    CHECK(s.all_points()[11].hw.ray_buffer.kib == 512);
    CHECK(value_of(s.all_points()[1], "hw.scene_memory.dram_bandwidth_gbps") == "1");
    CHECK(s.all_points()[2].hw.scene_memory.dram_bandwidth_gbps == 1.5);
    CHECK(s.all_points()[5].hw.ray_buffer.banks == 16);
    CHECK(s.all_points()[5].hw.clock.core_mhz == 250.0);
    CHECK(s.all_points()[5].hw.scene_memory.caches[0].kib == 64);
    CHECK(s.all_points()[5].workload.spp == 2);
    CHECK(s.all_points()[5].workload.depth == 3);  // cornell's own
    CHECK(s.groups.size() == 1);              // tile fixed: one render for all
}

TEST_CASE("tile: auto resolves per point from its buffer, points group by the resolved tile", "[sweeps]") {
    const Sweep s = parse("version: 1\nhw: gr08.hw.yaml\n"
                          "workload: {scene: cornell, res: 16x16, spp: 1, tile: auto}\n"
                          "axes:\n"
                          "  hw.ray_buffer.kib: [128, 512, 512]\n"
                          "  hw.simd.width: [8, 16]\n");
    CHECK(s.duplicates == 2);  // the repeated 512 KiB points
    REQUIRE(s.point_count == 4);
    CHECK(s.all_points()[0].workload.tile < s.all_points()[2].workload.tile);
    CHECK(s.groups.size() == 2);
    for (const PointGroup& g : s.groups) CHECK(g.points.size() == 2);
    CHECK(s.all_points()[0].fidelity == Fidelity::full);  // the default
}

TEST_CASE("Expansion is lazy: 10^5 points are checked and grouped, each made on demand", "[sweeps]") {
    const Sweep s = parse(std::string(k_head) +
                          "axes:\n  workload.seed: {from: 0, to: 1562, step: 1}\n"
                          "  hw.simd.width: {from: 1, to: 64, step: 1}\n");
    CHECK(s.point_count == 100032);
    CHECK(s.duplicates == 0);
    REQUIRE(s.groups.size() == 1563);  // one render per seed, the widths share it
    const PointGroup& g = s.groups[987];
    REQUIRE(g.points.size() == 64);
    CHECK(g.workload.seed == 987);
    // A point made from its index is the one the odometer would reach: the last axis fastest.
    const SweepPoint p = s.point(g.points[17]);
    CHECK(p.index == 987 * 64 + 17);
    CHECK(p.workload == g.workload);
    CHECK(p.hw.simd.width == 18);
    CHECK(p.key == point_key(p.config_yaml));
    CHECK(s.axis_values(p.index) == p.axis_values);
    // The same point from a sweep of one point has the same key and YAML.
    const Sweep one = parse(std::string(k_head) + "hw_overrides: {simd.width: 18}\n"
                            "axes:\n  workload.seed: [987]\n");
    CHECK(one.all_points()[0].config_yaml == p.config_yaml);
}

TEST_CASE("The expansion guard is the caller's: more points or values than max_points are refused", "[sweeps]") {
    const std::string text = std::string(k_head) + "axes:\n  workload.seed: {from: 0, to: 99, step: 1}\n"
                                                   "  hw.simd.width: [4, 8]\n";
    CHECK(parse_sweep(text, "t.sweep.yaml", k_presets, {}, 200).point_count == 200);
    try {
        parse_sweep(text, "t.sweep.yaml", k_presets, {}, 199);
        FAIL("199 points allowed 200");
    } catch (const InputError& e) {
        CHECK(e.line() == 6);
        CHECK(e.key() == "axes");
        CHECK_THAT(e.message(), Catch::Contains("more than 199 points") && Catch::Contains("--max-points"));
    }
    try {
        parse_sweep(text, "t.sweep.yaml", k_presets, {}, 50);
        FAIL("an axis of 100 values allowed at 50");
    } catch (const InputError& e) {
        CHECK(e.key() == "axes.workload.seed");
        CHECK_THAT(e.message(), Catch::Contains("more than 50 values"));
    }
}

TEST_CASE("Equal values spelled differently are one point, duplicates are dropped per render", "[sweeps]") {
    const Sweep s = parse(std::string(k_head) +
                          "axes:\n  workload.seed: [1, 2]\n  hw.clock.core_mhz: [500, 500.0, 5e2, 250]\n");
    CHECK(s.duplicates == 4);  // per seed: 500.0 and 5e2 are 500
    CHECK(s.point_count == 4);
    std::set<std::string> keys;
    for (const SweepPoint& p : s.all_points()) keys.insert(p.key);
    CHECK(keys.size() == 4);
}

TEST_CASE("Point YAML round-trips and its key depends on values and nothing else", "[sweeps]") {
    const Sweep s = parse(std::string(k_head) + "axes:\n  hw.simd.width: [8, 12]\n  workload.seed: [0, 7]\n");
    REQUIRE(s.point_count == 4);
    std::set<std::string> keys;
    for (const SweepPoint& p : s.all_points()) {
        keys.insert(p.key);
        CHECK(p.key.size() == 64);
        CHECK(p.key == point_key(p.config_yaml));
        const ParsedPoint back = parse_point_config(p.config_yaml, "row");
        CHECK(dump_hw_config(back.hw) == dump_hw_config(p.hw));
        CHECK(back.workload == p.workload);
        CHECK(back.fidelity == p.fidelity);
        CHECK(point_config_yaml(back.hw, back.workload, back.fidelity) == p.config_yaml);
    }
    CHECK(keys.size() == 4);
    // The same point from another spelling of the sweep has the same key.
    const Sweep t = parse("version: 1\nhw: gr08.hw.yaml\nfidelity: analytic\n"
                          "workload:\n  seed: 7\n  tile: 8\n  width: 16\n  height: 16\n  spp: 1\n  scene: cornell\n"
                          "hw_overrides: {simd.width: 12}\n");
    REQUIRE(t.point_count == 1);
    CHECK(t.all_points()[0].key == s.all_points()[3].key);
    // A point with fewer cache levels keeps exactly those.
    HwConfig two;
    two.scene_memory.caches.pop_back();
    const std::string yaml = point_config_yaml(two, s.all_points()[0].workload, Fidelity::full);
    CHECK(parse_point_config(yaml, "row").hw.scene_memory.caches.size() == 2);
}

TEST_CASE("A point's workload YAML keeps its text (stored keys stay valid)", "[sweeps]") {
    const Sweep s = parse(std::string(k_head) + "axes:\n  workload.seed: [7]\n");
    REQUIRE(s.point_count == 1);
    const std::string yaml = s.all_points()[0].config_yaml;
    const std::string workload =
        "workload:\n  scene: \"cornell\"\n  width: 16\n  height: 16\n  spp: 1\n  depth: 3\n"
        "  tile: 8\n  seed: 7\nfidelity: analytic\n";
    REQUIRE(yaml.size() > workload.size());
    CHECK(yaml.substr(yaml.size() - workload.size()) == workload);
}

TEST_CASE("Bad sweeps name file, line and dotted path", "[sweeps]") {
    struct Case {
        std::string text;
        int line;
        std::string key;
        std::string what;
    };
    const std::string h = k_head;  // lines 1-4
    const std::vector<Case> cases = {
        {h + "axis: {}\n", 5, "axis", "unknown key"},
        {h + "axes:\n  hw.simd.widht: [4]\n", 6, "axes.hw.simd.widht",
         "no such hardware parameter"},
        {h + "axes:\n  hw.simd.width: [4,\n    0]\n", 7, "axes.hw.simd.width", "outside"},
        {h + "axes:\n  hw.ray_buffer.layout: [soa, diagonal]\n", 6, "axes.hw.ray_buffer.layout",
         "not an allowed value"},
        {h + "axes:\n  workload.tiles: [8]\n", 6, "axes.workload.tiles", "no such workload field"},
        {h + "axes:\n  simd.width: [8]\n", 6, "axes.simd.width", "starts with hw."},
        {h + "axes:\n  workload.scene: [cornell, nowhere_scene]\n", 6, "axes.workload.scene",
         "no such scene"},
        {h + "axes:\n  hw.simd.width: {from: 8, to: 4, step: 1}\n", 6, "axes.hw.simd.width.to",
         "below"},
        {h + "axes:\n  hw.simd.width: {from: 4, to: '8', step: 1}\n", 6, "axes.hw.simd.width.to",
         "expected a number"},
        {h + "axes:\n  hw.clock.core_mhz: {from: 0x10, to: 20, step: 1}\n", 6,
         "axes.hw.clock.core_mhz.from", "expected a number"},
        {h + "axes:\n  hw.simd.width: []\n", 6, "axes.hw.simd.width", "at least one"},
        {h + "axes:\n  hw.simd.width: [4, 8]\n  workload.tile: [8]\nzip:\n  - [hw.simd.width, "
             "workload.tile]\n",
         9, "zip[0].workload.tile", "equal lengths"},
        {h + "axes:\n  hw.simd.width: [4, 8]\nzip:\n  - [hw.simd.width, hw.simd.lanes]\n", 8,
         "zip[0].hw.simd.lanes", "not an axis"},
        {h + "axes:\n  hw.ray_buffer.banks: [32, 48]\n", 6, "hw.ray_buffer.banks", "do not divide"},
        {h + "fidelity: fast\n", 5, "fidelity", "duplicate key"},
        {"version: 1\nhw: gr08.hw.yaml\nworkload: {scene: cornell, res: 16x16, spp: 1, tile: 64}\n"
         "hw_overrides: {ray_buffer.kib: 64, ray_buffer.banks: 16}\n",
         3, "workload.tile", "needs"},
        {"version: 2\n", 1, "version", "only version 1"},
        {"hw: gr08.hw.yaml\n", 1, "version", "missing"},
        {"version: 1\nhw: nowhere.hw.yaml\nworkload: {scene: cornell}\n", 2, "hw", "no such file"},
        {"version: 1\nhw: nowhere_preset\nworkload: {scene: cornell}\n", 2, "hw",
         "no such file or preset"},
        {"version: 1\nhw: gr08.hw.yaml\nworkload: {scene: cornell, res: 16x16, width: 8}\n", 3,
         "workload.res", "not both"},
        {"version: 1\nhw: gr08.hw.yaml\nworkload: {scene: cornell, res: 16by16}\n", 3,
         "workload.res", "WxH"},
        {"version: 1\nhw: gr08.hw.yaml\nworkload: {scene: cornell, tile: 0}\n", 3, "workload.tile",
         "[1, 4096]"},
        {"version: 1\nhw: gr08.hw.yaml\nfidelity: fast\nworkload: {scene: cornell}\n", 3,
         "fidelity", "analytic, sampled or full"},
        {"version: 1\nhw: gr08.hw.yaml\nworkload: {scene: cornell}\nhw_overrides: {simd.width: "
         "100}\n",
         4, "hw_overrides.simd.width", "outside"},
    };
    for (const Case& c : cases) {
        const InputError e = error_of(c.text);
        INFO(c.text << "\n-> " << e.what());
        CHECK(e.file() == "t.sweep.yaml");
        CHECK(e.line() == c.line);
        CHECK(e.key() == c.key);
        CHECK(std::string(e.what()).find(c.what) != std::string::npos);
    }
    // Command-line sets are checked too and named as such.
    const InputError e = error_of(std::string(k_head), {"workload.spp=0"});
    CHECK(e.file() == "command line");
    CHECK(e.key() == "--set workload.spp");
    const InputError f = error_of(std::string(k_head), {"hw.simd.lanes=4"});
    CHECK(f.key() == "--set hw.simd.lanes");
}

TEST_CASE("A sweep's hw may name a preset, as the command line does", "[sweeps]") {
    // Parsed from sweeps/, where no file is called gr08: the name is the shipped preset.
    const Sweep s = parse_sweep("version: 1\nhw: gr08\nworkload: {scene: cornell, res: 16x16}\n",
                                "t.sweep.yaml", SFX_SOURCE_DIR "/sweeps");
    REQUIRE(s.point_count == 1);
    CHECK(dump_hw_config(s.all_points()[0].hw) == dump_hw_config(load_hw_config("gr08")));
}

TEST_CASE("Every shipped sweep validates and expands", "[sweeps]") {
    const std::map<std::string, size_t> expected = {{"quickstart", 48},
                                                    {"quickstart-buffer", 16},
                                                    {"paper-table6", 18},
                                                    {"buffer-size", 16},
                                                    {"width-scan", 192},
                                                    {"nodes", 14}};
    size_t found = 0;
    for (const auto& entry : std::filesystem::directory_iterator(SFX_SOURCE_DIR "/sweeps")) {
        const std::string name = entry.path().filename().string();
        if (name.size() < 11 || name.substr(name.size() - 11) != ".sweep.yaml") continue;
        INFO(name);
        const Sweep s = load_sweep(entry.path().string());
        CHECK(s.point_count > 0);
        auto it = expected.find(s.name);
        if (it != expected.end()) {
            ++found;
            CHECK(s.point_count == it->second);
        }
    }
    CHECK(found == expected.size());
    const Sweep q = load_sweep(SFX_SOURCE_DIR "/sweeps/quickstart.sweep.yaml");
    CHECK(q.groups.size() == 12);  // scenes x tiles x fidelities; the widths share renders
    std::set<std::string> scenes;
    for (const SweepPoint& p : q.all_points()) scenes.insert(p.workload.scene);
    CHECK(scenes.size() == 2);
    // The buffer sweep: tile auto gives each buffer size its own tile, so its own render.
    const Sweep b = load_sweep(SFX_SOURCE_DIR "/sweeps/quickstart-buffer.sweep.yaml");
    CHECK(b.groups.size() == 8);
    std::set<uint32_t> tiles;
    for (const SweepPoint& p : b.all_points()) tiles.insert(p.workload.tile);
    CHECK(tiles == std::set<uint32_t>{36, 52, 73, 104});
}
