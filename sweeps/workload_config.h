#pragma once
// The workload configuration: what is rendered (scene, resolution, samples, depth, tile, seed).
// One struct whose visit() names every field with its unit, description and range, as
// HwConfig's does; that visit() is the one list of workload fields behind the strict parsing
// (sweep files, `--set`, stored point configurations, command-line flags), the point YAML, the
// store's `workload.*` columns and the sweep's `workload.*` axes. resolve_workload() is the one
// place that turns "the scene's depth" and `tile: auto` into numbers and checks the tile fits.

#include <cstdint>
#include <string>
#include <vector>

#include "hw_model/hw_config.h"
#include "kernels/render.h"
#include "workloads/scene.h"

namespace sfx {

struct WorkloadConfig {
    static constexpr int64_t k_scene_depth = -1;  // depth: the scene's own max_depth
    static constexpr uint32_t k_auto_tile = 0;    // tile: auto

    std::string scene;  // a built-in scene name or a path (absolute in a sweep's points)
    uint32_t width = 256;
    uint32_t height = 256;
    uint32_t spp = 4;
    int64_t depth = k_scene_depth;
    uint32_t tile = 32;
    uint64_t seed = 0;
    // The seed papers' alternatives, each a choice of words (k_*_choices, first = default).
    std::string primary_entry = "root";  // root | aepsa (PrimaryEntry)
    std::string reorder = "none";        // none | hit_point (RayReorder)
    uint32_t reorder_lod_ppm = 20000;    // the paper's 2 %
    std::string batching = "none";       // none | raygrid (RayBatching)
    uint32_t batching_queue = 384;       // seeds/000 Sec. 3.5: M = 384
    uint32_t batching_cell_prims = 4096;  // seeds/000 Sec. 3.5: 4096 primitives per leaf

    static constexpr const char* k_primary_entry_choices[] = {"root", "aepsa", nullptr};
    static constexpr const char* k_reorder_choices[] = {"none", "hit_point", nullptr};
    static constexpr const char* k_batching_choices[] = {"none", "raygrid", nullptr};

    // `choices` (null-terminated) lists the words a text field accepts (none: any text).
    // `special` names the word that stands for the field's sentinel value ("auto" for the tile).
    template <class V>
    void visit(V& v) {
        v.text("scene", scene, "a built-in scene name or a scene file");
        v.param("width", width, "pixels", "image width", 1, 65536);
        v.param("height", height, "pixels", "image height", 1, 65536);
        v.param("spp", spp, "samples", "samples per pixel", 1, 1u << 20);
        v.param("depth", depth, "bounces", "bounces after the camera ray (default: the scene's)", 0,
                1000);
        v.param("tile", tile, "pixels",
                "tile edge: the stream holds tile^2 rays (auto: the largest that fits the ray "
                "buffer)",
                1, 4096, "auto");
        v.param("seed", seed, "", "random seed", 0, UINT64_MAX);
        v.text("primary_entry", primary_entry,
               "where primary-ray streams enter the BVH: root, or aepsa (a frustum per tile finds "
               "the deepest node that holds every leaf it overlaps; seeds/004)",
               k_primary_entry_choices);
        v.text("reorder", reorder,
               "sort each generation's stream by approximate hit point before tracing it: none, or "
               "hit_point (seeds/001)",
               k_reorder_choices);
        v.param("reorder_lod_ppm", reorder_lod_ppm, "ppm",
                "hit_point: the simplified geometry's size in parts per million of the primitives "
                "(20000 = 2 %, the paper's)",
                1, 1000000);
        v.text("batching", batching,
               "batch secondary rays in the cells of a top cut of the BVH, each queue traced "
               "against its cell's subtree: none, or raygrid (seeds/000 Sec. 3)",
               k_batching_choices);
        v.param("batching_queue", batching_queue, "rays",
                "raygrid: rays per queue; a full queue is traced first (384, the paper's)", 1,
                1u << 24);
        v.param("batching_cell_prims", batching_cell_prims, "primitives",
                "raygrid: the most primitives under one cell of the cut (4096, the paper's per "
                "octree leaf)",
                1, UINT32_MAX);
    }

    // The seed papers' options: absent from a point's YAML when at their default (sweep.cpp).
    static bool is_option_field(const std::string& name) {
        return name == "primary_entry" || name == "reorder" || name == "reorder_lod_ppm" ||
               name == "batching" || name == "batching_queue" || name == "batching_cell_prims";
    }

    bool resolved() const { return depth >= 0 && tile != k_auto_tile; }
    // The tracers' settings of a resolved configuration.
    RenderSettings render_settings(uint32_t threads = 0) const;
    // Same render: every field equal.
    bool operator==(const WorkloadConfig& o) const;
    bool operator!=(const WorkloadConfig& o) const { return !(*this == o); }
};

// The field names in visit() order; "res" (WxH, both width and height) is accepted besides.
std::vector<std::string> workload_field_names();
// Sets one field (or "res") from text, strictly: InputError(file, line, key) on an unknown
// field or a bad value. A scene is taken as given.
void set_workload_field(WorkloadConfig& w, const std::string& field, const std::string& value,
                        const std::string& file, int line, const std::string& key);

// One `workload.<field>` column of the results store: INTEGER for numbers, TEXT for the scene.
struct WorkloadColumn {
    std::string name;
    bool integer = false;
    int64_t number = 0;
    std::string text;
    std::string unit, description;  // from visit(), for the store's units table
};
std::vector<WorkloadColumn> workload_columns(const WorkloadConfig& w);

// The largest tile whose stream fits every configuration's ray buffer: tile^2 * bytes per ray
// <= buffer bytes. A CPU core's buffers (storage l1d) live in memory and fit any tile; with
// only those, 64.
uint32_t largest_fitting_tile(const FeatureSet& features, const std::vector<HwConfig>& configs);
// Checks a tile against every configuration with banked buffers; throws InputError(key) if one
// cannot hold the stream.
void check_tile_fits(uint32_t tile, const FeatureSet& features,
                     const std::vector<HwConfig>& configs, const std::string& key);

struct ResolvedWorkload {
    WorkloadConfig config;  // resolved(): a number for depth and tile
    FeatureSet features;    // the scene's, with max_depth the resolved depth (as the model sees it)
};
// Depth -1 becomes the scene's max_depth; tile auto becomes the largest tile that fits every
// configuration's ray buffer (64 when no configuration is given: the largest the paper's
// buffers hold); then the tile is checked against every configuration. Errors are
// InputError("command line", 0, tile_key, ...); callers with a file re-throw them with theirs.
ResolvedWorkload resolve_workload(const WorkloadConfig& w, const FeatureSet& scene_features,
                                  const std::vector<HwConfig>& configs,
                                  const std::string& tile_key);

}  // namespace sfx
