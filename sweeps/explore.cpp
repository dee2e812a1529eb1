#include "sweeps/explore.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "base/input_error.h"
#include "base/strict_number.h"
#include "base/strict_yaml.h"
#include "base/user_files.h"

namespace sfx {

const std::vector<std::string> k_explore_metrics = {"fps", "area_mm2", "energy_mj", "power_w", "fps_per_mm2"};

namespace {

namespace fs = std::filesystem;
using strict_yaml::check_keys;
using strict_yaml::line_of;

// `n` must be present (an absent key has no line: callers check for it first).
std::string scalar(const YAML::Node& n, const std::string& file, const std::string& key) {
    if (!n.IsScalar()) throw InputError(file, line_of(n), key, "expected a single value");
    return n.Scalar();
}

double number(const YAML::Node& n, const std::string& file, const std::string& key) {
    double v = 0;
    if (!n.IsScalar() || !strict_yaml::is_plain_scalar(n) || !parse_finite(n.Scalar(), v))
        throw InputError(file, line_of(n), key, "expected a number");
    return v;
}

uint64_t count(const YAML::Node& n, const std::string& file, const std::string& key, uint64_t lo, uint64_t hi) {
    uint64_t v = 0;
    if (!n.IsScalar() || !strict_yaml::is_plain_scalar(n) || !parse_unsigned(n.Scalar(), v))
        throw InputError(file, line_of(n), key, "expected a whole number");
    if (v < lo || v > hi)
        throw InputError(file, line_of(n), key,
                         "value " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
}

Fidelity fidelity_at(const YAML::Node& n, const std::string& file, const std::string& key) {
    const std::string v = scalar(n, file, key);
    try {
        return parse_fidelity(v);
    } catch (const std::invalid_argument&) {
        throw InputError(file, line_of(n), key, "'" + v + "' is not one of: analytic, sampled, full");
    }
}

void require_map(const YAML::Node& n, const std::string& file, const std::string& key, const char* what) {
    if (!n.IsMap()) throw InputError(file, line_of(n), key, std::string("expected a mapping ") + what);
}

}  // namespace

ExploreSpec parse_explore(const std::string& text, const std::string& file, const std::string& base_dir,
                          const std::vector<std::string>& sets, size_t max_points) {
    const YAML::Node root = parse_yaml_document(text, file);
    if (!root.IsMap()) throw InputError(file, line_of(root), "(top level)", "expected a mapping");
    check_keys(root, file, "",
               {"version", "name", "hw", "hw_overrides", "workload", "workloads", "knobs", "objectives",
                "constraints", "budget", "fidelity", "search"});
    for (const char* k : {"version", "hw", "workloads", "knobs", "objectives", "budget"})
        if (!root[k]) throw InputError(file, 1, k, "missing");
    if (scalar(root["version"], file, "version") != "1")
        throw InputError(file, line_of(root["version"]), "version", "only version 1 is supported");

    ExploreSpec spec;
    spec.file = file;
    if (root["name"]) {
        spec.name = scalar(root["name"], file, "name");
    } else {
        spec.name = fs::path(file).filename().string();
        for (const std::string suffix : {".yaml", ".yml"})
            if (spec.name.size() > suffix.size() &&
                spec.name.compare(spec.name.size() - suffix.size(), suffix.size(), suffix) == 0) {
                spec.name.resize(spec.name.size() - suffix.size());
                break;
            }
    }

    const YAML::Node workloads = root["workloads"];
    if (!workloads.IsSequence() || workloads.size() == 0)
        throw InputError(file, line_of(workloads), "workloads", "expected a list of {scene, weight}");
    std::set<std::string> scenes;
    for (size_t i = 0; i < workloads.size(); ++i) {
        const std::string key = "workloads[" + std::to_string(i) + "]";
        const YAML::Node w = workloads[i];
        require_map(w, file, key, "{scene, weight}");
        check_keys(w, file, key, {"scene", "weight"});
        if (!w["scene"]) throw InputError(file, line_of(w), key + ".scene", "missing");
        ExploreWorkload ew;
        ew.scene = scalar(w["scene"], file, key + ".scene");
        if (!scenes.insert(ew.scene).second)
            throw InputError(file, line_of(w["scene"]), key + ".scene", "scene listed twice");
        if (w["weight"]) {
            ew.weight = number(w["weight"], file, key + ".weight");
            if (!(ew.weight > 0)) throw InputError(file, line_of(w["weight"]), key + ".weight", "must be positive");
        }
        spec.workloads.push_back(ew);
    }

    const YAML::Node objectives = root["objectives"];
    require_map(objectives, file, "objectives", "of metric: maximize | minimize");
    if (objectives.size() == 0) throw InputError(file, line_of(objectives), "objectives", "at least one objective");
    check_keys(objectives, file, "objectives", k_explore_metrics);
    for (const auto& kv : objectives) {
        const std::string metric = kv.first.Scalar(), key = "objectives." + metric;
        const std::string dir = scalar(kv.second, file, key);
        if (dir != "maximize" && dir != "minimize")
            throw InputError(file, line_of(kv.second), key, "'" + dir + "' is not one of: maximize, minimize");
        spec.objectives.push_back({metric, dir == "maximize"});
    }

    if (const YAML::Node constraints = root["constraints"]) {
        require_map(constraints, file, "constraints", "of metric: {min: X} | {max: X}");
        check_keys(constraints, file, "constraints", k_explore_metrics);
        for (const auto& kv : constraints) {
            const std::string metric = kv.first.Scalar(), key = "constraints." + metric;
            require_map(kv.second, file, key, "{min: X}, {max: X} or both");
            check_keys(kv.second, file, key, {"min", "max"});
            ExploreConstraint c;
            c.metric = metric;
            if (kv.second["min"]) c.has_min = true, c.min = number(kv.second["min"], file, key + ".min");
            if (kv.second["max"]) c.has_max = true, c.max = number(kv.second["max"], file, key + ".max");
            if (!c.has_min && !c.has_max) throw InputError(file, line_of(kv.second), key, "give min, max or both");
            if (c.has_min && c.has_max && c.min > c.max)
                throw InputError(file, line_of(kv.second["max"]), key + ".max", "below min: no configuration can meet it");
            spec.constraints.push_back(c);
        }
    }

    const YAML::Node budget = root["budget"];
    require_map(budget, file, "budget", "{evaluations: N, host_seconds: S}");
    check_keys(budget, file, "budget", {"evaluations", "host_seconds"});
    if (!budget["evaluations"] && !budget["host_seconds"])
        throw InputError(file, line_of(budget), "budget", "give evaluations, host_seconds or both");
    if (budget["evaluations"]) spec.budget_evaluations = count(budget["evaluations"], file, "budget.evaluations", 1, max_points);
    if (budget["host_seconds"]) {
        spec.budget_seconds = number(budget["host_seconds"], file, "budget.host_seconds");
        if (!(spec.budget_seconds > 0))
            throw InputError(file, line_of(budget["host_seconds"]), "budget.host_seconds", "must be positive");
    }

    if (const YAML::Node f = root["fidelity"]) {
        require_map(f, file, "fidelity", "{screen: analytic, confirm: sampled}");
        check_keys(f, file, "fidelity", {"screen", "confirm"});
        if (f["screen"]) spec.screen = fidelity_at(f["screen"], file, "fidelity.screen");
        if (f["confirm"]) spec.confirm = fidelity_at(f["confirm"], file, "fidelity.confirm");
    }

    if (const YAML::Node s = root["search"]) {
        require_map(s, file, "search", "{sampler, seed, batch, startup}");
        check_keys(s, file, "search", {"sampler", "seed", "batch", "startup"});
        if (s["sampler"]) {
            spec.sampler = scalar(s["sampler"], file, "search.sampler");
            if (spec.sampler != "tpe" && spec.sampler != "nsga2" && spec.sampler != "random")
                throw InputError(file, line_of(s["sampler"]), "search.sampler",
                                 "'" + spec.sampler + "' is not one of: tpe, nsga2, random");
        }
        if (s["seed"]) spec.seed = count(s["seed"], file, "search.seed", 0, 1u << 30);
        if (s["batch"]) spec.batch = count(s["batch"], file, "search.batch", 1, 4096);
        if (s["startup"]) spec.startup = count(s["startup"], file, "search.startup", 1, max_points);
    }

    if (!root["knobs"].IsMap() || root["knobs"].size() == 0)
        throw InputError(file, line_of(root["knobs"]), "knobs", "expected a mapping of hardware paths to values");
    spec.space = parse_explore_space(root, spec.name, spec.screen, file, base_dir, sets, max_points);
    if (!spec.budget_evaluations) spec.budget_evaluations = spec.configurations();
    spec.budget_evaluations = std::min(spec.budget_evaluations, spec.configurations());
    if (!spec.startup)
        spec.startup = std::clamp<size_t>(spec.budget_evaluations / 4, 4, 10);
    return spec;
}

ExploreSpec load_explore(const std::string& path, const std::vector<std::string>& sets, size_t max_points) {
    const std::string text = read_input_file(path, "explore file");
    const fs::path dir = fs::absolute(fs::path(path)).parent_path();
    return parse_explore(text, path, dir.string(), sets, max_points);
}

size_t ExploreSpec::configurations() const {
    size_t n = 1;
    for (size_t a = 1; a < space.axis_choices.size(); ++a) n *= space.axis_choices[a].size();
    return n;
}

std::vector<size_t> ExploreSpec::knob_positions(size_t config) const {
    std::vector<size_t> at(knob_count());
    for (size_t k = at.size(); k-- > 0;) {
        const size_t n = space.axis_choices[k + 1].size();
        at[k] = config % n;
        config /= n;
    }
    return at;
}

size_t ExploreSpec::config_of(const std::vector<size_t>& positions) const {
    size_t c = 0;
    for (size_t k = 0; k < positions.size(); ++k) c = c * space.axis_choices[k + 1].size() + positions[k];
    return c;
}

SweepPoint ExploreSpec::point(size_t workload, size_t config, Fidelity fidelity) const {
    SweepPoint p = space.point(workload * configurations() + config);
    if (p.fidelity != fidelity) {
        p.fidelity = fidelity;
        p.config_yaml = point_config_yaml(p.hw, p.workload, p.fidelity);
        p.key = point_key(p.config_yaml);
    }
    return p;
}

std::vector<std::pair<std::string, std::string>> ExploreSpec::knob_values(size_t config) const {
    const std::vector<size_t> at = knob_positions(config);
    std::vector<std::pair<std::string, std::string>> out;
    for (size_t k = 0; k < at.size(); ++k) out.emplace_back(space.axes[k + 1], space.axis_choices[k + 1][at[k]]);
    return out;
}

std::vector<std::string> ExploreSpec::nodes() const {
    for (size_t a = 1; a < space.axes.size(); ++a)
        if (space.axes[a] == "hw.tech.node") return space.axis_choices[a];
    return {space.point(0).hw.tech.node};
}

std::string ExploreSpec::fingerprint() const {
    std::ostringstream s;
    // Not the budget, batch or startup: a search may go on with more evaluations or other
    // batches; everything that changes what a configuration scores, or which sequence a seed
    // draws, is in.
    s << "sampler " << sampler << " seed " << seed << "\n";
    for (const ExploreObjective& o : objectives) s << "objective " << o.metric << " " << o.maximize << "\n";
    for (const ExploreConstraint& c : constraints)
        s << "constraint " << c.metric << " " << (c.has_min ? shortest_text(c.min) : "-") << " "
          << (c.has_max ? shortest_text(c.max) : "-") << "\n";
    for (const ExploreWorkload& w : workloads) s << "weight " << shortest_text(w.weight) << "\n";
    for (size_t a = 0; a < space.axes.size(); ++a) {
        s << "axis " << space.axes[a];
        for (const std::string& v : space.axis_choices[a]) s << " " << v;
        s << "\n";
    }
    // The base point (hardware and workload) through the first configuration's key.
    s << "base " << space.point(0).key << "\n";
    return s.str();
}

double ExploreScore::metric(const std::string& name) const {
    if (name == "fps") return fps;
    if (name == "area_mm2") return area_mm2;
    if (name == "energy_mj") return energy_mj;
    if (name == "power_w") return power_w;
    if (name == "fps_per_mm2") return fps_per_mm2;
    throw std::invalid_argument("unknown explore metric " + name);
}

ExploreScore combine_workloads(const ExploreSpec& spec, const std::vector<std::map<std::string, double>>& numbers) {
    auto get = [](const std::map<std::string, double>& n, const char* k) {
        auto it = n.find(k);
        return it == n.end() ? std::nan("") : it->second;
    };
    ExploreScore s;
    double weight = 0, seconds = 0, energy = 0, worst_error = 0;
    bool error_known = true;
    for (size_t w = 0; w < numbers.size(); ++w) {
        const double wt = spec.workloads[w].weight, fps = get(numbers[w], "fps");
        weight += wt;
        seconds += wt / fps;
        energy += wt * get(numbers[w], "energy.total_per_frame_mj");
        s.area_mm2 = std::max(s.area_mm2, get(numbers[w], "area.total_mm2"));
        const double e = get(numbers[w], "error.relative");
        if (!(e >= 0)) error_known = false;
        else worst_error = std::max(worst_error, e);
    }
    s.fps = weight / seconds;
    s.energy_mj = energy / weight;
    s.power_w = s.energy_mj * 1e-3 * s.fps;
    s.fps_per_mm2 = s.area_mm2 > 0 ? s.fps / s.area_mm2 : 0;
    s.fps_error = error_known ? worst_error : -1;
    return s;
}

std::vector<double> objective_values(const ExploreSpec& spec, const ExploreScore& s) {
    std::vector<double> v;
    for (const ExploreObjective& o : spec.objectives) v.push_back(s.metric(o.metric));
    return v;
}

std::vector<double> constraint_values(const ExploreSpec& spec, const ExploreScore& s) {
    std::vector<double> v;
    auto scaled = [](double excess, double bound) { return excess / std::max(1e-12, std::fabs(bound)); };
    for (const ExploreConstraint& c : spec.constraints) {
        const double x = s.metric(c.metric);
        double worst = -std::numeric_limits<double>::infinity();
        if (c.has_min) worst = std::max(worst, scaled(c.min - x, c.min));
        if (c.has_max) worst = std::max(worst, scaled(x - c.max, c.max));
        v.push_back(std::isnan(x) ? 1.0 : worst);
    }
    return v;
}

bool feasible(const ExploreSpec& spec, const ExploreScore& s) {
    for (double c : constraint_values(spec, s))
        if (c > 0) return false;
    for (double v : objective_values(spec, s))
        if (!std::isfinite(v)) return false;
    return true;
}

std::vector<size_t> pareto_front(const ExploreSpec& spec, const std::vector<ExploreScore>& scores) {
    std::vector<std::vector<double>> v;  // minimised
    std::vector<size_t> candidates;
    for (size_t i = 0; i < scores.size(); ++i) {
        if (!feasible(spec, scores[i])) continue;
        std::vector<double> x = objective_values(spec, scores[i]);
        for (size_t k = 0; k < x.size(); ++k)
            if (spec.objectives[k].maximize) x[k] = -x[k];
        v.push_back(x);
        candidates.push_back(i);
    }
    auto dominates = [](const std::vector<double>& a, const std::vector<double>& b) {
        bool better = false;
        for (size_t k = 0; k < a.size(); ++k) {
            if (a[k] > b[k]) return false;
            better |= a[k] < b[k];
        }
        return better;
    };
    std::vector<size_t> front;
    for (size_t i = 0; i < v.size(); ++i) {
        bool dominated = false;
        for (size_t j = 0; j < v.size() && !dominated; ++j) dominated = j != i && dominates(v[j], v[i]);
        if (!dominated) front.push_back(candidates[i]);
    }
    return front;
}

}  // namespace sfx
