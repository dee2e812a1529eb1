#include "sweeps/workload_config.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <type_traits>

#include "base/input_error.h"
#include "workloads/ray_layout.h"
#include "base/strict_number.h"

namespace sfx {
namespace {

// Collects the field names.
struct NameLister {
    std::vector<std::string> names;
    void text(const char* name, std::string&, const char*, const char* const* = nullptr) {
        names.push_back(name);
    }
    template <class T>
    void param(const char* name, T&, const char*, const char*, uint64_t, uint64_t,
               const char* = nullptr) {
        names.push_back(name);
    }
};

// Sets the field called `field` from text: a number in [lo, hi], or the field's special word.
struct FieldSetter {
    const std::string& field;
    const std::string& value;
    const std::string& file;
    int line;
    const std::string& key;
    bool found = false;

    void text(const char* name, std::string& target, const char*,
              const char* const* choices = nullptr) {
        if (field != name) return;
        found = true;
        if (!choices) {
            if (value.empty()) throw InputError(file, line, key, "expected a scene name or path");
            target = value;
            return;
        }
        std::string list;
        for (const char* const* c = choices; *c; ++c) {
            if (value == *c) {
                target = value;
                return;
            }
            list += (list.empty() ? "" : "|") + std::string(*c);
        }
        throw InputError(file, line, key, "expected " + list + ", got '" + value + "'");
    }
    template <class T>
    void param(const char* name, T& target, const char*, const char*, uint64_t lo, uint64_t hi,
               const char* special = nullptr) {
        if (field != name) return;
        found = true;
        if (special && value == special) {
            target = T(0);
            return;
        }
        uint64_t v = 0;
        if (!parse_unsigned(value, v) || v < lo || v > hi) {
            const std::string range = hi == UINT64_MAX ? "a non-negative integer"
                                                       : "an integer in [" + std::to_string(lo) +
                                                             ", " + std::to_string(hi) + "]";
            throw InputError(file, line, key,
                             "expected " + range + (special ? std::string(" or ") + special : "") +
                                 ", got '" + value + "'");
        }
        target = T(v);
    }
};

// The store's columns: numbers as INTEGER, the scene as TEXT.
struct ColumnWriter {
    std::vector<WorkloadColumn> columns;
    void text(const char* name, std::string& value, const char* description,
              const char* const* = nullptr) {
        columns.push_back({std::string("workload.") + name, false, 0, value, "", description});
    }
    template <class T>
    void param(const char* name, T& value, const char* unit, const char* description, uint64_t,
               uint64_t, const char* = nullptr) {
        columns.push_back(
            {std::string("workload.") + name, true, int64_t(value), "", unit, description});
    }
};

}  // namespace

RenderSettings WorkloadConfig::render_settings(uint32_t threads) const {
    RenderSettings s;
    s.width = width;
    s.height = height;
    s.spp = spp;
    s.max_depth = uint32_t(depth);
    s.tile = tile;
    s.seed = seed;
    s.threads = threads;
    s.primary_entry = primary_entry == "aepsa" ? PrimaryEntry::aepsa : PrimaryEntry::root;
    s.reorder = reorder == "hit_point" ? RayReorder::hit_point : RayReorder::none;
    s.reorder_lod_ppm = reorder_lod_ppm;
    s.batching = batching == "raygrid" ? RayBatching::raygrid : RayBatching::none;
    s.batching_queue = batching_queue;
    s.batching_cell_prims = batching_cell_prims;
    return s;
}

bool WorkloadConfig::operator==(const WorkloadConfig& o) const {
    return scene == o.scene && width == o.width && height == o.height && spp == o.spp &&
           depth == o.depth && tile == o.tile && seed == o.seed &&
           primary_entry == o.primary_entry && reorder == o.reorder &&
           reorder_lod_ppm == o.reorder_lod_ppm && batching == o.batching &&
           batching_queue == o.batching_queue && batching_cell_prims == o.batching_cell_prims;
}

std::vector<std::string> workload_field_names() {
    NameLister lister;
    WorkloadConfig().visit(lister);
    return lister.names;
}

void set_workload_field(WorkloadConfig& w, const std::string& field, const std::string& value,
                        const std::string& file, int line, const std::string& key) {
    if (field == "res") {
        unsigned width = 0, height = 0;
        char tail = 0;
        if (std::sscanf(value.c_str(), "%ux%u%c", &width, &height, &tail) != 2 || width == 0 ||
            height == 0 || width > 65536 || height > 65536)
            throw InputError(file, line, key, "expected WxH with 1..65536, got '" + value + "'");
        w.width = width;
        w.height = height;
        return;
    }
    FieldSetter setter{field, value, file, line, key};
    w.visit(setter);
    if (!setter.found) {
        std::string list;
        for (const std::string& n : workload_field_names()) list += (list.empty() ? "" : ", ") + n;
        throw InputError(file, line, key, "no such workload field (" + list + ", res)");
    }
}

std::vector<WorkloadColumn> workload_columns(const WorkloadConfig& w) {
    ColumnWriter writer;
    const_cast<WorkloadConfig&>(w).visit(writer);  // the writer only reads
    return writer.columns;
}

uint32_t largest_fitting_tile(const FeatureSet& features, const std::vector<HwConfig>& configs) {
    const uint64_t bytes_per_ray = ray_record_bytes(features);
    uint64_t smallest = UINT64_MAX;
    for (const HwConfig& c : configs)
        if (c.ray_buffer.storage == "banks")  // l1d: the buffers live in memory, any size
            smallest = std::min<uint64_t>(smallest, uint64_t(c.ray_buffer.kib) * 1024);
    if (smallest == UINT64_MAX) return 64;  // the tracer's default tile
    return uint32_t(std::sqrt(double(smallest / bytes_per_ray)));
}

void check_tile_fits(uint32_t tile, const FeatureSet& features,
                     const std::vector<HwConfig>& configs, const std::string& key) {
    const uint64_t need = uint64_t(tile) * tile * ray_record_bytes(features);
    for (const HwConfig& c : configs)
        if (c.ray_buffer.storage == "banks" && need > uint64_t(c.ray_buffer.kib) * 1024)
            throw InputError("command line", 0, key,
                             "a " + std::to_string(tile) + "x" + std::to_string(tile) +
                                 " stream needs " + std::to_string((need + 1023) / 1024) +
                                 " KiB of ray data; configuration '" + c.name + "' has " +
                                 std::to_string(c.ray_buffer.kib) + " KiB buffers (largest tile: " +
                                 std::to_string(largest_fitting_tile(features, {c})) + ")");
}

ResolvedWorkload resolve_workload(const WorkloadConfig& w, const FeatureSet& scene_features,
                                  const std::vector<HwConfig>& configs,
                                  const std::string& tile_key) {
    ResolvedWorkload r{w, scene_features};
    for (const HwConfig& c : configs) check_machine_model_config(c);  // before its buffer size
    if (w.depth < 0) r.config.depth = scene_features.max_depth;
    // The ray record does not depend on the depth today, but the hardware model sees the
    // resolved depth (workload_shape), so the fit is checked against the same features.
    r.features.max_depth = uint32_t(r.config.depth);
    if (w.tile == WorkloadConfig::k_auto_tile) {
        r.config.tile = configs.empty() ? 64 : largest_fitting_tile(r.features, configs);
        if (r.config.tile == 0)
            throw InputError("command line", 0, tile_key,
                             "tile auto: not even one ray record fits the ray buffer");
    }
    check_tile_fits(r.config.tile, r.features, configs, tile_key);
    return r;
}

}  // namespace sfx
