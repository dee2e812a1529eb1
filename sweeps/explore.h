#pragma once
// Explore files (`*.yaml` for `sfx explore`): a sweep's base (hw, hw_overrides, workload
// without a scene) plus the scenes to judge on (`workloads`, weighted), the `knobs` and their
// values (the search space, written as a sweep's axes), the objectives, constraints, a budget,
// the fidelity policy (screen, confirm) and the search's settings. Parsed strictly: errors name
// the file, line and key, as in sweep files.
//
// A configuration is one choice of every knob, numbered in odometer order (the last knob
// fastest); its point on workload w is the space's expansion index w x configurations + c, so
// its key is the key a sweep of the same values gives (a point either ran is reused).

#include <map>
#include <string>
#include <vector>

#include "hw_model/prediction.h"
#include "sweeps/sweep.h"

namespace sfx {

// What an objective or constraint may name: the frame's prediction combined over workloads.
// fps: the weighted frame rate (total weight / weighted sum of frame times); energy_mj: energy
// per frame, weighted mean; power_w: the weighted mix's energy over its time; area_mm2: on-chip
// area; fps_per_mm2: fps / area.
extern const std::vector<std::string> k_explore_metrics;

struct ExploreObjective {
    std::string metric;
    bool maximize = true;
};
struct ExploreConstraint {
    std::string metric;
    bool has_min = false, has_max = false;
    double min = 0, max = 0;
};
struct ExploreWorkload {
    std::string scene;  // as written in the file
    double weight = 1;
};

struct ExploreSpec {
    std::string name, file;
    Sweep space;  // axis 0: the workloads' scenes; axes 1...: the knobs
    std::vector<ExploreWorkload> workloads;
    std::vector<ExploreObjective> objectives;
    std::vector<ExploreConstraint> constraints;
    size_t budget_evaluations = 0;  // configurations screened at most
    double budget_seconds = 0;      // 0: no limit on host seconds
    Fidelity screen = Fidelity::analytic;
    Fidelity confirm = Fidelity::sampled;  // == screen: no confirmation
    std::string sampler = "tpe";           // tpe | nsga2 | random (the baseline)
    uint64_t seed = 0;
    // Configurations asked of the sampler at once: fewer, the more each round learns from the
    // last (bench/explore_vs_grid.py: TPE at 4 reached 99.9 % of the grid's hypervolume, at 8
    // 92.9 %); more, the more groups run in parallel.
    size_t batch = 4;
    size_t startup = 0;  // TPE: random trials first (0: a quarter of the budget, 4 to 10)

    size_t knob_count() const { return space.axes.size() - 1; }
    size_t configurations() const;
    // The knobs' value indices of configuration c, and back.
    std::vector<size_t> knob_positions(size_t config) const;
    size_t config_of(const std::vector<size_t>& positions) const;
    // The point of configuration c on workload w at `fidelity`.
    SweepPoint point(size_t workload, size_t config, Fidelity fidelity) const;
    // {knob path: value} of configuration c.
    std::vector<std::pair<std::string, std::string>> knob_values(size_t config) const;
    // The technology nodes the space is built at: a `hw.tech.node` knob's values, else the
    // base's node.
    std::vector<std::string> nodes() const;
    // Space, base point, workload weights, objectives, constraints, sampler and seed as one
    // canonical text: a study or stored search made for another fingerprint is not this one's.
    std::string fingerprint() const;
};

// `sets`: command-line PATH=VALUE changes to the base (hw.*, workload.*), as for sweeps.
ExploreSpec load_explore(const std::string& path, const std::vector<std::string>& sets = {},
                         size_t max_points = k_default_max_points);
ExploreSpec parse_explore(const std::string& text, const std::string& file, const std::string& base_dir,
                          const std::vector<std::string>& sets = {},
                          size_t max_points = k_default_max_points);

// A configuration's scores, combined over the workloads. fps_error: the largest relative
// half-width of the workloads' fps intervals (-1: some workload's is unknown).
struct ExploreScore {
    double fps = 0, fps_error = -1, area_mm2 = 0, energy_mj = 0, power_w = 0, fps_per_mm2 = 0;
    double metric(const std::string& name) const;
};
// `numbers`: each workload's stored numbers (ResultsStore::numbers), in workload order.
ExploreScore combine_workloads(const ExploreSpec& spec,
                               const std::vector<std::map<std::string, double>>& numbers);

std::vector<double> objective_values(const ExploreSpec& spec, const ExploreScore& s);
// Optuna's convention: one value per constraint, <= 0 when met (scaled by the bound).
std::vector<double> constraint_values(const ExploreSpec& spec, const ExploreScore& s);
bool feasible(const ExploreSpec& spec, const ExploreScore& s);
// Indices (into `scores`) of the feasible scores no other feasible score dominates.
std::vector<size_t> pareto_front(const ExploreSpec& spec, const std::vector<ExploreScore>& scores);

}  // namespace sfx
