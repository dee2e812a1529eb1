#pragma once
// One point group as a unit of work that can travel: a JSON spec (the points' config YAML)
// in, one JSON row per point out. `sfx run-group` wraps it, so the local engine's child
// processes and the Dask workers run exactly the same code.
//
//   spec: {"threads": N, "points": ["<config_yaml>", ...]}   (all points share one render)
//   row:  {"key", "sfx_version", "started_at", "finished_at", "metrics": {name: value|null}}

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sweeps/results_store.h"
#include "sweeps/sweep.h"

namespace sfx {

nlohmann::json group_spec_json(const std::vector<SweepPoint>& points, uint32_t threads);

// Parses every point (strictly), checks they share one render, runs run_point_group once and
// returns one row per point, in order. Throws InputError on a bad spec (or sampled fidelity).
std::vector<PointRun> run_group(const nlohmann::json& spec);

nlohmann::ordered_json point_run_json(const PointRun& run);
PointRun point_run_from_json(const nlohmann::ordered_json& row);  // throws std::exception if malformed

}  // namespace sfx
