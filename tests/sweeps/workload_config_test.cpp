// The workload configuration: strict fields, store columns, and resolve_workload (the scene's
// depth, tile auto, tile fits) agreeing with what run_point_group's model sees.

#include "sweeps/workload_config.h"

#include <catch2/catch.hpp>

#include "kernels/bvh.h"
#include "sweeps/point_group.h"
#include "sweeps/sweep.h"
#include "base/input_error.h"
#include "workloads/ray_layout.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

InputError field_error(const std::string& field, const std::string& value) {
    WorkloadConfig w;
    try {
        set_workload_field(w, field, value, "f.yaml", 4, "workload." + field);
    } catch (const InputError& e) {
        return e;
    }
    FAIL("no InputError for " << field << " = " << value);
    return InputError("", 0, "", "");
}

}  // namespace

TEST_CASE("Workload fields: one list, strict values, columns in the same order", "[workload]") {
    const std::vector<std::string> names = {"scene",
                                            "width",
                                            "height",
                                            "spp",
                                            "depth",
                                            "tile",
                                            "seed",
                                            "primary_entry",
                                            "reorder",
                                            "reorder_lod_ppm",
                                            "batching",
                                            "batching_queue",
                                            "batching_cell_prims"};
    CHECK(workload_field_names() == names);
    WorkloadConfig w;
    set_workload_field(w, "scene", "cornell", "f", 1, "k");
    set_workload_field(w, "res", "64x32", "f", 1, "k");
    set_workload_field(w, "spp", "2", "f", 1, "k");
    set_workload_field(w, "depth", "0", "f", 1, "k");
    set_workload_field(w, "tile", "auto", "f", 1, "k");
    set_workload_field(w, "seed", "18446744073709551615", "f", 1, "k");
    CHECK(w.width == 64);
    CHECK(w.height == 32);
    CHECK(w.depth == 0);
    CHECK(w.tile == WorkloadConfig::k_auto_tile);
    CHECK(w.seed == UINT64_MAX);
    CHECK_FALSE(w.resolved());

    const InputError unknown = field_error("tiles", "8");
    CHECK(unknown.file() == "f.yaml");
    CHECK(unknown.line() == 4);
    CHECK(unknown.key() == "workload.tiles");
    CHECK(unknown.message() ==
          "no such workload field (scene, width, height, spp, depth, tile, seed, primary_entry, "
          "reorder, reorder_lod_ppm, batching, batching_queue, batching_cell_prims, res)");
    CHECK(field_error("depth", "1001").message() == "expected an integer in [0, 1000], got '1001'");
    CHECK(field_error("tile", "0").message() ==
          "expected an integer in [1, 4096] or auto, got '0'");
    CHECK(field_error("spp", "-1").message() == "expected an integer in [1, 1048576], got '-1'");
    CHECK(field_error("seed", "x").message() == "expected a non-negative integer, got 'x'");
    CHECK(field_error("res", "8by8").message() == "expected WxH with 1..65536, got '8by8'");
    CHECK(field_error("scene", "").message() == "expected a scene name or path");
    CHECK(field_error("primary_entry", "frustum").message() ==
          "expected root|aepsa, got 'frustum'");
    CHECK(field_error("reorder", "morton").message() == "expected none|hit_point, got 'morton'");
    CHECK(field_error("reorder_lod_ppm", "0").message() ==
          "expected an integer in [1, 1000000], got '0'");
    CHECK(field_error("batching", "octree").message() == "expected none|raygrid, got 'octree'");
    CHECK(field_error("batching_queue", "0").message() ==
          "expected an integer in [1, 16777216], got '0'");
    CHECK(field_error("batching_cell_prims", "0").message() ==
          "expected an integer in [1, 4294967295], got '0'");

    w.tile = 16;
    const std::vector<WorkloadColumn> columns = workload_columns(w);
    REQUIRE(columns.size() == names.size());
    for (size_t i = 0; i < names.size(); ++i) CHECK(columns[i].name == "workload." + names[i]);
    CHECK_FALSE(columns[0].integer);
    CHECK(columns[0].text == "cornell");
    CHECK(columns[5].integer);
    CHECK(columns[5].number == 16);
}

TEST_CASE("Workload options: render settings, and absent from a point's YAML at their default",
          "[workload]") {
    WorkloadConfig w;
    w.scene = "cornell";
    w.depth = 3;
    CHECK(w.render_settings().primary_entry == PrimaryEntry::root);
    const std::string plain = point_config_yaml(HwConfig(), w, Fidelity::full);
    CHECK(plain.find("primary_entry") == std::string::npos);
    WorkloadConfig a = w;
    set_workload_field(a, "primary_entry", "aepsa", "f", 1, "k");
    CHECK(a != w);
    CHECK(a.render_settings().primary_entry == PrimaryEntry::aepsa);
    const std::string yaml = point_config_yaml(HwConfig(), a, Fidelity::full);
    CHECK(yaml.find("primary_entry: \"aepsa\"") != std::string::npos);
    CHECK(parse_point_config(yaml, "row").workload == a);
    CHECK(parse_point_config(plain, "row").workload == w);
    WorkloadConfig r = w;
    set_workload_field(r, "reorder", "hit_point", "f", 1, "k");
    set_workload_field(r, "reorder_lod_ppm", "500", "f", 1, "k");
    CHECK(r.render_settings().reorder == RayReorder::hit_point);
    CHECK(r.render_settings().reorder_lod_ppm == 500);
    const std::string ryaml = point_config_yaml(HwConfig(), r, Fidelity::full);
    CHECK(ryaml.find("reorder_lod_ppm: 500") != std::string::npos);
    CHECK(parse_point_config(ryaml, "row").workload == r);
    CHECK(plain.find("batching") == std::string::npos);
    WorkloadConfig g = w;
    set_workload_field(g, "batching", "raygrid", "f", 1, "k");
    set_workload_field(g, "batching_queue", "64", "f", 1, "k");
    set_workload_field(g, "batching_cell_prims", "512", "f", 1, "k");
    CHECK(g != w);
    CHECK(g.render_settings().batching == RayBatching::raygrid);
    CHECK(g.render_settings().batching_queue == 64);
    CHECK(g.render_settings().batching_cell_prims == 512);
    const std::string gyaml = point_config_yaml(HwConfig(), g, Fidelity::full);
    CHECK(gyaml.find("batching: \"raygrid\"") != std::string::npos);
    CHECK(gyaml.find("batching_queue: 64") != std::string::npos);
    CHECK(parse_point_config(gyaml, "row").workload == g);
}

TEST_CASE("resolve_workload: the scene's depth, tile auto and tile fits, as the model sees them",
          "[workload]") {
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    WorkloadConfig w;
    w.scene = "cornell";
    w.width = w.height = 16;
    w.spp = 1;

    // The scene's depth; an explicit depth reaches the features the fit is checked with, which
    // equal those the hardware model is given for the same render (workload_shape).
    const ResolvedWorkload own = resolve_workload(w, scene.features(), {}, "--tile");
    CHECK(own.config.depth == scene.max_depth);
    w.depth = 7;
    const ResolvedWorkload deep = resolve_workload(w, scene.features(), {HwConfig{}}, "--tile");
    CHECK(deep.config.depth == 7);
    CHECK(deep.config.resolved());
    const WorkloadShape shape = workload_shape(scene, bvh, deep.config.render_settings());
    CHECK(deep.features.max_depth == 7);
    CHECK(deep.features.max_depth == shape.features.max_depth);
    CHECK(deep.features.describe() == shape.features.describe());

    // tile auto: the largest tile whose stream fits the smallest buffer; 64 with no hardware.
    w.tile = WorkloadConfig::k_auto_tile;
    HwConfig small;
    small.ray_buffer.kib = 128;
    small.ray_buffer.banks = 16;
    const uint64_t bytes = ray_record_bytes(scene.features());
    const uint32_t tile =
        resolve_workload(w, scene.features(), {HwConfig{}, small}, "--tile").config.tile;
    CHECK(uint64_t(tile) * tile * bytes <= 128 * 1024);
    CHECK(uint64_t(tile + 1) * (tile + 1) * bytes > 128 * 1024);
    CHECK(resolve_workload(w, scene.features(), {}, "--tile").config.tile == 64);

    // An explicit tile that does not fit names the key it was given under.
    w.tile = 4096;
    try {
        resolve_workload(w, scene.features(), {small}, "workload.tile");
        FAIL("no InputError for a 4096 tile in 128 KiB");
    } catch (const InputError& e) {
        CHECK(e.key() == "workload.tile");
        CHECK(e.message().find("128 KiB buffers") != std::string::npos);
    }

    // The tracers' settings carry every field.
    w.tile = 8;
    w.seed = 5;
    const RenderSettings s =
        resolve_workload(w, scene.features(), {}, "--tile").config.render_settings(3);
    CHECK(s.width == 16);
    CHECK(s.height == 16);
    CHECK(s.spp == 1);
    CHECK(s.max_depth == 7);
    CHECK(s.tile == 8);
    CHECK(s.seed == 5);
    CHECK(s.threads == 3);
}
