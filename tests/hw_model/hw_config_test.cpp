// The hardware configuration: strict parsing with file, line and key; one source of truth.

#include "hw_model/hw_config.h"

#include <algorithm>
#include <catch2/catch.hpp>

#include "base/input_error.h"

using namespace sfx;

namespace {
// Parses and returns the InputError it throws (failing the test if none).
InputError parse_error(const std::string& text) {
    try {
        parse_hw_config(text, "bad.hw.yaml");
    } catch (const InputError& e) {
        return e;
    }
    FAIL("no InputError for:\n" << text);
    return InputError("", 0, "", "");
}
}  // namespace

TEST_CASE("The gr08 preset parses and is the in-class default", "[hw_config]") {
    const HwConfig preset = load_hw_config(SFX_SOURCE_DIR "/hw_model/presets/gr08.hw.yaml");
    const HwConfig defaults;
    CHECK(dump_hw_config(preset) == dump_hw_config(defaults));
    CHECK(preset.ray_buffer.bank_kib() == 16);
    CHECK(preset.simd.width == 16);
    CHECK(preset.scene_memory.caches.size() == 3);
    CHECK(preset.scene_memory.caches[2].ways == 16);
}

TEST_CASE("a preset is found by its name, an unknown name lists the presets", "[hw_config]") {
    CHECK(dump_hw_config(load_hw_config("gr08-w8")) ==
          dump_hw_config(load_hw_config(SFX_SOURCE_DIR "/hw_model/presets/gr08-w8.hw.yaml")));
    CHECK(load_hw_config("gr08-w8").simd.width == 8);
    const std::vector<std::string> names = builtin_preset_names();
    CHECK(std::find(names.begin(), names.end(), "gr08-256k") != names.end());
    try {
        load_hw_config("gr09");
        FAIL("no error for an unknown preset");
    } catch (const InputError& e) {
        CHECK_THAT(e.what(), Catch::Contains("gr09") && Catch::Contains("gr08-w12"));
    }
}

TEST_CASE("dump then parse gives the same configuration", "[hw_config]") {
    HwConfig c;
    c.simd.width = 12;
    c.ray_buffer.kib = 256;
    c.scene_memory.caches.pop_back();
    c.clock.core_mhz = 812.5;
    const std::string text = dump_hw_config(c);
    const HwConfig back = parse_hw_config(text, "dumped.hw.yaml");
    CHECK(dump_hw_config(back) == text);
    CHECK(back.simd.width == 12);
    CHECK(back.clock.core_mhz == 812.5);
    CHECK(back.scene_memory.caches.size() == 2);
}

TEST_CASE("Bad hardware values name file, line and dotted key", "[hw_config]") {
    const InputError width0 = parse_error("simd:\n  width: 0\n");
    CHECK(width0.file() == "bad.hw.yaml");
    CHECK(width0.line() == 2);
    CHECK(width0.key() == "simd.width");

    const InputError unknown = parse_error("ray_buffer:\n  kib: 512\n  bankz: 32\n");
    CHECK(unknown.line() == 3);
    CHECK(unknown.key() == "ray_buffer.bankz");

    const InputError banks = parse_error("ray_buffer:\n  kib: 512\n  banks: 24\n");
    CHECK(banks.line() == 3);
    CHECK(banks.key() == "ray_buffer.banks");

    const InputError spans = parse_error(
        "scene_memory:\n  dram_latency_by_span:\n    - {span_mib: 16, latency_ns: 150}\n"
        "    - {span_mib: 4, latency_ns: 100}\n");
    CHECK(spans.key() == "scene_memory.dram_latency_by_span[1].span_mib");
    CHECK(spans.line() == 4);

    const InputError type = parse_error("clock:\n  core_mhz: fast\n");
    CHECK(type.key() == "clock.core_mhz");

    const InputError negative = parse_error("agu:\n  count: -1\n");
    CHECK(negative.key() == "agu.count");

    const InputError ways = parse_error(
        "scene_memory:\n  caches:\n    - {name: l1, kib: 32, line_bytes: 64, ways: 7}\n");
    CHECK(ways.line() == 3);
    CHECK(ways.key() == "scene_memory.caches[0].ways");

    const InputError choice = parse_error("partition:\n  kind: bubble_sort\n");
    CHECK(choice.key() == "partition.kind");

    CHECK(parse_error("simd: [1, 2]\n").key() == "simd");
    CHECK(parse_error("simd:\n  width: 16\n  width: 8\n").line() > 0);
}

TEST_CASE("Hardware numbers follow the rules of every YAML reader (base/strict_yaml.h)", "[hw_config]") {
    // A quoted scalar is text, never a number or a boolean; numbers are plain decimal.
    for (const char* text : {"simd:\n  width: '16'\n", "simd:\n  width: 0x10\n",
                             "simd:\n  width: +16\n", "clock:\n  core_mhz: \"500\"\n",
                             "clock:\n  core_mhz: 0x1f4\n", "clock:\n  core_mhz: .inf\n",
                             "clock:\n  core_mhz: 1e999\n"}) {
        INFO(text);
        CHECK(parse_error(text).line() == 2);
    }
    CHECK(parse_error("simd:\n  width: '16'\n").message() == "expected a non-negative integer");
    CHECK(parse_hw_config("simd:\n  width: 8\n", "ok.hw.yaml").simd.width == 8);
    CHECK(parse_hw_config("clock:\n  core_mhz: 5e2\n", "ok.hw.yaml").clock.core_mhz == 500);
}

TEST_CASE("An unknown key lists the allowed ones, as every YAML reader does", "[hw_config]") {
    const InputError e = parse_error("simd:\n  lanes: 8\n");
    CHECK(e.line() == 2);
    CHECK(e.key() == "simd.lanes");
    // base/strict_yaml.h's check_keys: the same words for scenes and sweeps.
    CHECK_THAT(e.message(), Catch::StartsWith("unknown key (allowed: ") &&
                                Catch::Contains("units") && Catch::Contains("width"));
}

TEST_CASE("Parameters are flattened to dotted names and set by path", "[hw_config]") {
    HwConfig c;
    const std::vector<HwParamInfo> params = flatten_hw_config(c);
    bool saw_width = false, saw_cache = false;
    for (const HwParamInfo& p : params) {
        CHECK_FALSE(p.description.empty());
        if (p.path == "simd.width") {
            saw_width = true;
            CHECK(p.value == "16");
            CHECK(p.unit == "lanes");
        }
        if (p.path == "scene_memory.caches[1].kib") saw_cache = p.value == "256";
    }
    CHECK(saw_width);
    CHECK(saw_cache);
    set_hw_param(c, "simd.width", "12");
    CHECK(c.simd.width == 12);
    set_hw_param(c, "scene_memory.caches[0].ways", "4");
    CHECK(c.scene_memory.caches[0].ways == 4);
    CHECK_THROWS_AS(set_hw_param(c, "simd.widht", "12"), InputError);
    CHECK_THROWS_AS(set_hw_param(c, "simd.width", "65"), InputError);
    CHECK_THROWS_AS(set_hw_param(c, "ray_buffer.pipelined", "yes"), InputError);
}

TEST_CASE("Keys that are lists or maps, and second documents, are input errors", "[hw_config]") {
    const InputError list_key = parse_error("version: 1\n? [a]\n: 1\n");
    CHECK(list_key.line() == 2);
    CHECK(list_key.key() == "[a]");
    const InputError nested = parse_error("simd:\n  ? {x: 1}\n  : 2\n");
    CHECK(nested.line() == 2);
    CHECK(nested.key() == "simd.{x: 1}");
    const InputError second = parse_error("simd:\n  width: 8\n---\nsimd:\n  width: 4\n");
    CHECK(second.line() == 4);
    CHECK(std::string(second.what()).find("second YAML document") != std::string::npos);
}

TEST_CASE("Rows of several configurations are told apart: name, else file stem, and their differences",
          "[hw_config]") {
    HwConfig a, b, c;  // all named gr08, as copies of the preset with one knob changed are
    b.simd.width = 8;
    c.simd.width = 4;
    c.ray_buffer.kib = 256;
    std::vector<ConfigLabel> l = label_configs({a, b, c}, {"gr08", "dir/w8.hw.yaml", "w4-256k.yaml"});
    REQUIRE(l.size() == 3);
    CHECK(l[0].name == "gr08");
    CHECK(l[1].name == "w8");
    CHECK(l[2].name == "w4-256k");
    CHECK(l[0].differences.empty());
    CHECK(l[1].differences == std::vector<std::string>{"simd.width=8"});
    CHECK(l[2].differences == std::vector<std::string>{"simd.width=4", "ray_buffer.kib=256"});
    // Distinct names are kept; the same name and the same stem get a number.
    b.name = "wide";
    l = label_configs({a, b}, {"x.hw.yaml", "x.hw.yaml"});
    CHECK(l[0].name == "gr08");
    CHECK(l[1].name == "wide");
    CHECK(l[1].differences == std::vector<std::string>{"simd.width=8"});  // the name is no knob
    l = label_configs({a, a}, {"x.hw.yaml", "x.hw.yaml"});
    CHECK(l[0].name == "gr08 #1");
    CHECK(l[1].name == "gr08 #2");
    CHECK(l[1].differences.empty());
}

TEST_CASE("The values-only YAML of a configuration reads back as the configuration", "[hw_config]") {
    HwConfig c;
    c.name = "a \"quoted\" name\\ with: colon, # hash\nand a newline";
    c.clock.core_mhz = 1234.5678;
    c.scene_memory.caches.pop_back();
    OpCostConfig box, leaf;
    box.per_lane_cycles = 1.25;
    leaf.op = "triangle_test";
    leaf.per_op_cycles = 3e-7;
    c.op_costs = {box, leaf};
    for (const HwConfig& config : {HwConfig{}, c}) {
        const std::string text = hw_config_values_yaml(config);
        INFO(text);
        const HwConfig back = parse_hw_config(text, "values.yaml");
        CHECK(dump_hw_config(back) == dump_hw_config(config));
        // Indented, it is the same text shifted.
        const std::string indented = hw_config_values_yaml(config, 4);
        CHECK(indented.size() == text.size() + 4 * size_t(std::count(text.begin(), text.end(), '\n')));
    }
    CHECK(hw_config_values_yaml(HwConfig{}).find("op_costs: []\n") != std::string::npos);
}
