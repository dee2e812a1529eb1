#pragma once
// Sweeps: a `*.sweep.yaml` file (a base hardware configuration and workload plus axes) parsed
// strictly and expanded into points, and the points grouped so that one functional render
// feeds every hardware variant that shares its workload (trace once, time many).
//
// Everything is checked before anything runs: unknown keys, axis paths (through set_hw_param
// on a scratch configuration), every axis value, cross-parameter rules at every point and tile
// fits. Errors are InputErrors naming the sweep file, the line and the dotted path.

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hw_model/hw_config.h"
#include <yaml-cpp/yaml.h>
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
    std::vector<size_t> points;  // expansion indices of the group's points, in order
    WorkloadConfig workload;     // resolved, shared by every point of the group
    Fidelity fidelity = Fidelity::full;
    uint32_t scene_primitives = 0;  // for the host-time estimate
};

class SweepExpansion;

// A sweep is expanded lazily: parsing checks every point (cross-parameter rules, tile fits) and
// groups them, keeping per point only its place in a group; a point's configuration, YAML and
// key are made when asked for (point()), so a 10^6-point sweep costs megabytes, not gigabytes.
struct Sweep {
    std::string name;  // `name:`, else the file name without .sweep.yaml
    std::string file;
    std::vector<std::string> axes;  // dotted axis paths in file order
    std::vector<std::vector<std::string>> axis_choices;  // each axis's values (explore spaces)
    std::vector<PointGroup> groups;
    size_t point_count = 0;  // distinct points: the expansion less its duplicates
    size_t duplicates = 0;   // expanded points identical to an earlier one (dropped)
    // Written clocks above what their critical path allows at the point's node, each once
    // (hw_model/node_clock.h); the commands print them.
    std::vector<std::string> warnings;

    // The point at this expansion index (an index of some group's `points`).
    SweepPoint point(size_t index) const;
    // Only its axis values (SweepPoint::axis_values), without making the point.
    std::vector<std::pair<std::string, std::string>> axis_values(size_t index) const;
    // Every distinct point in expansion order: for small sweeps and tests.
    std::vector<SweepPoint> all_points() const;
    // Every distinct point's expansion index, in order.
    std::vector<size_t> point_indices() const;

    std::shared_ptr<const SweepExpansion> expansion;
};

// The guard against a typo in a range eating the machine: a sweep (and an axis) may expand to at
// most this many points unless the user raises it (`sfx sweep --max-points`).
constexpr size_t k_default_max_points = 1000000;

// Reads, checks and expands a sweep. Relative `hw:` and scene paths are relative to the file.
// `sets` are command-line "PATH=VALUE" changes to the base point ("workload.res=32x32").
// `max_points` bounds the expansion (the cross product, duplicates included).
Sweep load_sweep(const std::string& path, const std::vector<std::string>& sets = {},
                 size_t max_points = k_default_max_points);
Sweep parse_sweep(const std::string& yaml_text, const std::string& file_name,
                  const std::string& base_dir, const std::vector<std::string>& sets = {},
                  size_t max_points = k_default_max_points);

// An explore file's space (sweeps/explore.h): `workloads` scenes as the first axis, then the
// `knobs`, every point at `fidelity`. The explore's own keys are checked by the caller.
// `sets`: command-line changes to the base, as load_sweep's (a scene set is overruled by the
// workloads' scenes; a fidelity set by the explore's fidelity policy).
Sweep parse_explore_space(const YAML::Node& root, const std::string& name, Fidelity fidelity,
                          const std::string& file, const std::string& base_dir,
                          const std::vector<std::string>& sets = {},
                          size_t max_points = k_default_max_points);

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
