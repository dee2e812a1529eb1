#pragma once
// Sweeps: a `*.sweep.yaml` file (a base hardware configuration and workload plus axes) parsed
// strictly and expanded into points, and the points grouped so that one functional render
// feeds every hardware variant that shares its workload (trace once, time many).
//
// Everything is checked before anything runs: unknown keys, axis paths (through set_hw_param
// on a scratch configuration), every axis value, cross-parameter rules at every point and tile
// fits. Errors are InputErrors naming the sweep file, the line and the dotted path.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hw_model/hw_config.h"
#include "hw_model/prediction.h"
#include "sweeps/workload_config.h"

namespace sfx {

// The version stamped on every stored row (and part of every point key).
const char* sfx_version();

struct SweepPoint {
    size_t index = 0;  // position in the sweep's expansion
    HwConfig hw;
    WorkloadConfig workload;  // resolved: no "auto", no "the scene's depth"
    Fidelity fidelity = Fidelity::full;
    // The value of each axis at this point, e.g. {"hw.simd.width", "8"}, for tables.
    std::vector<std::pair<std::string, std::string>> axis_values;
    std::string config_yaml;  // hw:, workload:, fidelity: (re-running it reproduces the row)
    std::string key;          // point_key(config_yaml)
};

// Points sharing one functional render: the same scene, resolution, spp, depth, resolved tile,
// seed and fidelity.
struct PointGroup {
    std::vector<size_t> points;  // indices into Sweep::points, in expansion order
};

struct Sweep {
    std::string name;  // `name:`, else the file name without .sweep.yaml
    std::string file;
    std::vector<std::string> axes;  // dotted axis paths in file order
    std::vector<SweepPoint> points;
    std::vector<PointGroup> groups;
    size_t duplicates = 0;  // expanded points identical to an earlier one (dropped)
};

// Reads, checks and expands a sweep. Relative `hw:` and scene paths are relative to the file.
// `sets` are command-line "PATH=VALUE" changes to the base point ("workload.res=32x32").
Sweep load_sweep(const std::string& path, const std::vector<std::string>& sets = {});
Sweep parse_sweep(const std::string& yaml_text, const std::string& file_name,
                  const std::string& base_dir, const std::vector<std::string>& sets = {});

// One point as YAML (comment-free, so the key depends on values only) and its store key:
// hex SHA-256 of (config_yaml + "\n" + sfx version).
std::string point_config_yaml(const HwConfig& hw, const WorkloadConfig& workload,
                              Fidelity fidelity);
std::string point_key(const std::string& config_yaml);

struct ParsedPoint {
    HwConfig hw;
    WorkloadConfig workload;
    Fidelity fidelity = Fidelity::full;
};
// The inverse of point_config_yaml (strict): what a worker runs from.
ParsedPoint parse_point_config(const std::string& yaml_text, const std::string& file_name);

}  // namespace sfx
