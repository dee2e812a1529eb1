// sfx explore EXPLORE.yaml --store DB: searches an explore file's space for the Pareto front of
// its objectives under its constraints. Optuna (sweeps/explore_search.py) proposes
// configurations; they run as sweep points (same keys, same store, same engines), screened at
// one fidelity; the screened front is then confirmed at another.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/point_runner.h"
#include "app/progress.h"
#include "app/text_table.h"
#include "base/input_error.h"
#include "base/strict_number.h"
#include "base/user_files.h"
#include "sweeps/engine.h"
#include "sweeps/explore.h"
#include "sweeps/results_store.h"
#include "sweeps/sha256.h"

#ifndef SFX_EXPLORE_SEARCH
#error "SFX_EXPLORE_SEARCH (sweeps/explore_search.py) is set by app/CMakeLists.txt"
#endif

namespace sfx {
namespace {

// Debian's optuna is visible to the system interpreter only.
constexpr const char* k_python = "/usr/bin/python3";
// Rounds in a row in which the sampler proposes only configurations already screened, before
// the search is taken to have converged (a small space's samplers repeat themselves).
constexpr int k_stale_rounds = 5;

// The Optuna study: one short process per ask or tell (explore_search.py says why).
class Search {
public:
    Search(const ExploreSpec& spec, std::string study_path) : m_spec(spec), m_study(std::move(study_path)) {
        m_base["storage"] = m_study;
        // One study per explore name and fingerprint: a changed file (or --set, --seed) starts
        // a study of its own in the same file instead of mixing trials of two spaces.
        m_base["study"] = spec.name + "@" + sha256_hex(spec.fingerprint()).substr(0, 12);
        m_base["sampler"] = spec.sampler;
        m_base["seed"] = spec.seed;
        m_base["batch"] = spec.batch;
        m_base["startup"] = spec.startup;
        m_base["fingerprint"] = spec.fingerprint();
        for (const ExploreObjective& o : spec.objectives) m_base["directions"].push_back(o.maximize ? "maximize" : "minimize");
        for (size_t a = 1; a < spec.space.axes.size(); ++a) {
            const std::vector<std::string>& values = spec.space.axis_choices[a];
            // Numbers in increasing order are ordinal (TPE and NSGA-II then know 8 lies between
            // 4 and 16); anything else is a category.
            bool ordinal = true;
            double last = -INFINITY;
            for (const std::string& v : values) {
                double x = 0;
                ordinal = ordinal && parse_finite(v, x) && x > last;
                last = x;
            }
            m_base["space"].push_back({{"name", spec.space.axes[a]}, {"values", values}, {"ordinal", ordinal}});
        }
    }

    struct Trial {
        int64_t number = 0;
        size_t config = 0;
        bool resumed = false;
    };
    // Tells the results of earlier trials (Optuna's convention: one value per objective, one
    // constraint value per constraint), then asks for `n` trials; trials asked before and never
    // told (a killed explore's) come first.
    std::vector<Trial> tell_and_ask(const nlohmann::json& results, size_t n) {
        nlohmann::json req = m_base;
        req["results"] = results;
        req["n"] = n;
        const nlohmann::json answer = call(req);
        std::vector<Trial> out;
        for (const auto& t : answer.at("trials")) {
            std::vector<size_t> at;
            for (size_t a = 1; a < m_spec.space.axes.size(); ++a) at.push_back(t["params"][m_spec.space.axes[a]].get<size_t>());
            out.push_back({t["number"].get<int64_t>(), m_spec.config_of(at), t["resumed"].get<bool>()});
        }
        return out;
    }

private:
    nlohmann::json call(const nlohmann::json& req) {
        std::string out, err;
        const int rc = run_process({k_python, SFX_EXPLORE_SEARCH}, req.dump(),
                                   [&](const std::string& line) { out += line; }, &err);
        while (!err.empty() && err.back() == '\n') err.pop_back();
        if (rc == 2) throw InputError(m_study, 0, "", err.substr(err.find(": ") == std::string::npos ? 0 : err.find(": ") + 2));
        if (rc != 0)
            throw std::runtime_error("the Optuna search (" + std::string(SFX_EXPLORE_SEARCH) + ") failed (exit " +
                                     std::to_string(rc) + "): " + err +
                                     (err.find("No module named 'optuna'") != std::string::npos
                                          ? " (install Debian's python3-optuna: scripts/install-deps)"
                                          : ""));
        return nlohmann::json::parse(out);
    }

    const ExploreSpec& m_spec;
    std::string m_study;
    nlohmann::json m_base;
};

struct Context {
    const ExploreSpec& spec;
    ResultsStore& store;
    EngineSettings settings;
    Progress& progress;
    uint64_t total = 0, found = 0;  // progress: points to run, points found stored
    size_t ran = 0, stored = 0;
};

std::string scene_label(const std::string& scene) {
    return scene.find('/') == std::string::npos ? scene : scene.substr(scene.find_last_of('/') + 1);
}

// Runs (or finds stored) every point of `configs` at `fidelity` and scores each configuration.
std::map<size_t, ExploreScore> evaluate(Context& cx, const std::vector<size_t>& configs, Fidelity fidelity) {
    const ExploreSpec& spec = cx.spec;
    std::map<size_t, std::vector<std::string>> keys;  // per configuration, one per workload
    std::vector<RunGroup> groups;
    std::vector<WorkloadConfig> group_workload;
    for (size_t w = 0; w < spec.workloads.size(); ++w)
        for (size_t c : configs) {
            SweepPoint p = spec.point(w, c, fidelity);
            keys[c].push_back(p.key);
            size_t g = 0;  // tile auto may resolve differently per configuration
            while (g < groups.size() && !(group_workload[g] == p.workload)) ++g;
            if (g == groups.size()) {
                groups.emplace_back();
                group_workload.push_back(p.workload);
            }
            groups[g].points.push_back(std::move(p));
        }
    for (size_t g = 0; g < groups.size(); ++g) {
        const WorkloadConfig& w = group_workload[g];
        groups[g].label = scene_label(w.scene) + " " + std::to_string(w.width) + "x" + std::to_string(w.height) +
                          " tile " + std::to_string(w.tile) + " " + to_string(fidelity) + " (" +
                          std::to_string(groups[g].points.size()) + " configs)";
    }
    size_t next = 0;
    const RunOutcome outcome = run_point_groups(
        [&](RunGroup& group) {
            if (next >= groups.size()) return false;
            group = std::move(groups[next++]);
            return true;
        },
        cx.store, spec.name, cx.settings, cx.progress, [&](size_t n) {
            cx.found += n;
            cx.progress.set_total(cx.total - std::min(cx.total, cx.found));
        });
    cx.ran += outcome.ran.size();
    cx.stored += outcome.already_stored;
    if (!outcome.failures.empty()) throw_group_failures(outcome, spec.file);
    std::map<size_t, ExploreScore> scores;
    for (const auto& [c, ks] : keys) {
        std::vector<std::map<std::string, double>> numbers;
        for (const std::string& k : ks) {
            numbers.push_back(cx.store.numbers(k));
            if (numbers.back().empty()) throw std::runtime_error("point " + k + " is not in the store after running");
        }
        scores[c] = combine_workloads(spec, numbers);
    }
    return scores;
}

nlohmann::ordered_json knobs_json(const ExploreSpec& spec, size_t config) {
    nlohmann::ordered_json j = nlohmann::ordered_json::object();
    for (const auto& [path, value] : spec.knob_values(config)) j[path] = value;
    return j;
}

nlohmann::ordered_json scores_json(const ExploreScore& s) {
    return {{"fps", s.fps},         {"fps_error", s.fps_error}, {"area_mm2", s.area_mm2},
            {"energy_mj", s.energy_mj}, {"power_w", s.power_w},  {"fps_per_mm2", s.fps_per_mm2}};
}

ResultsStore::ExploreConfigRow store_row(const ExploreSpec& spec, size_t config, const std::string& stage,
                                         int64_t trial, const ExploreScore& s, bool front) {
    return {config, stage, trial, knobs_json(spec, config).dump(), s, feasible(spec, s), front};
}

nlohmann::ordered_json objectives_json(const ExploreSpec& spec) {
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (const ExploreObjective& o : spec.objectives)
        j.push_back({{"metric", o.metric}, {"direction", o.maximize ? "maximize" : "minimize"}});
    return j;
}

// The explores table's spec: what the report needs to draw and judge the front.
std::string spec_json(const ExploreSpec& spec) {
    nlohmann::ordered_json j;
    j["objectives"] = objectives_json(spec);
    j["constraints"] = nlohmann::ordered_json::array();
    for (const ExploreConstraint& c : spec.constraints) {
        nlohmann::ordered_json x = {{"metric", c.metric}};
        if (c.has_min) x["min"] = c.min;
        if (c.has_max) x["max"] = c.max;
        j["constraints"].push_back(x);
    }
    for (const ExploreWorkload& w : spec.workloads) j["workloads"].push_back({{"scene", w.scene}, {"weight", w.weight}});
    for (size_t a = 1; a < spec.space.axes.size(); ++a)
        j["knobs"].push_back({{"path", spec.space.axes[a]}, {"values", spec.space.axis_choices[a]}});
    j["screen"] = to_string(spec.screen);
    j["confirm"] = to_string(spec.confirm);
    j["nodes"] = spec.nodes();
    j["configurations"] = spec.configurations();
    j["budget"] = {{"evaluations", spec.budget_evaluations}, {"host_seconds", spec.budget_seconds}};
    j["search"] = {{"sampler", spec.sampler}, {"seed", spec.seed}, {"batch", spec.batch}};
    return j.dump();
}

// The front as a table: knobs, the scores, and each configuration's rank by the first objective
// when screened and when confirmed.
void print_front(const ExploreSpec& spec, const std::vector<size_t>& front, const std::map<size_t, ExploreScore>& screened,
                 const std::map<size_t, ExploreScore>& confirmed, bool has_confirm, std::ostream& out) {
    const ExploreObjective& first = spec.objectives[0];
    auto rank_by = [&](const std::map<size_t, ExploreScore>& scores) {
        std::vector<size_t> order = front;
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
            const double x = scores.at(a).metric(first.metric), y = scores.at(b).metric(first.metric);
            return first.maximize ? x > y : x < y;
        });
        std::map<size_t, size_t> rank;
        for (size_t i = 0; i < order.size(); ++i) rank[order[i]] = i + 1;
        return rank;
    };
    const std::map<size_t, size_t> screen_rank = rank_by(screened);
    const std::map<size_t, size_t> confirm_rank = has_confirm ? rank_by(confirmed) : screen_rank;
    std::vector<std::string> headers;
    for (size_t a = 1; a < spec.space.axes.size(); ++a) headers.push_back(spec.space.axes[a]);
    for (const char* h : {"fps", "interval", "area mm2", "energy mJ", "power W", "rank"}) headers.push_back(h);
    headers.push_back(has_confirm ? "confirmed by" : "screened by");
    std::vector<std::vector<std::string>> rows;
    std::vector<size_t> order = front;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return confirm_rank.at(a) < confirm_rank.at(b); });
    for (size_t c : order) {
        const ExploreScore& s = has_confirm ? confirmed.at(c) : screened.at(c);
        std::vector<std::string> row;
        for (const auto& kv : spec.knob_values(c)) row.push_back(kv.second);
        row.push_back(significant_text(s.fps));
        row.push_back(s.fps_error >= 0 ? "+-" + fixed_text(100 * s.fps_error, 1) + "%" : "unknown");
        row.push_back(significant_text(s.area_mm2));
        row.push_back(significant_text(s.energy_mj));
        row.push_back(significant_text(s.power_w));
        row.push_back(has_confirm ? std::to_string(screen_rank.at(c)) + " -> " + std::to_string(confirm_rank.at(c))
                                  : std::to_string(screen_rank.at(c)));
        row.push_back(to_string(has_confirm ? spec.confirm : spec.screen));
        rows.push_back(row);
    }
    print_text_table(out, headers, rows, [](size_t) { return true; }, "  ");
}

struct Options {
    std::string file, store, study, engine = "local", scheduler;
    unsigned jobs = 0;
    uint32_t threads = 0;
    std::vector<std::string> sets;
    std::string sampler;
    long seed = -1;
    size_t budget = 0;
    bool exhaustive = false, json = false;
};

void run_explore(const Options& o) {
    if (!o.store.empty() && access(o.store.c_str(), F_OK) != 0) check_output_file(o.store, "--store");
    ExploreSpec spec = load_explore(o.file, o.sets);
    for (const std::string& w : spec.space.warnings) std::cerr << "warning: " << w << "\n";
    if (o.seed >= 0) spec.seed = uint64_t(o.seed);
    if (!o.sampler.empty()) spec.sampler = o.sampler;
    if (o.budget) spec.budget_evaluations = std::min(o.budget, spec.configurations());
    if (o.exhaustive) {
        spec.name += "/grid";
        spec.budget_evaluations = spec.configurations();
        spec.confirm = spec.screen;
    }
    const std::string study = o.study.empty() ? o.store + ".optuna" : o.study;
    if (!o.exhaustive && access(study.c_str(), F_OK) != 0) check_output_file(study, "--study");
    ResultsStore store(o.store);
    store.begin_explore(spec.name, spec.file, spec.fingerprint(), spec_json(spec));
    const size_t workloads = spec.workloads.size(), space = spec.configurations();
    const EngineSettings settings = engine_settings(o.engine, o.scheduler, o.jobs, o.threads, workloads);
    if (!o.json)
        std::cerr << "explore " << spec.name << ": " << space << " configurations x " << workloads
                  << " workload" << (workloads == 1 ? "" : "s") << "; "
                  << (o.exhaustive ? "every configuration" : "budget " + std::to_string(spec.budget_evaluations) + " evaluations" +
                          (spec.budget_seconds > 0 ? " or " + duration_text(spec.budget_seconds) : std::string()) +
                          ", Optuna " + spec.sampler + " seed " + std::to_string(spec.seed))
                  << ", screened " << to_string(spec.screen)
                  << (spec.confirm != spec.screen ? ", front confirmed " + std::string(to_string(spec.confirm)) : "")
                  << "; stored points are reused\n";
    Progress progress("explore", spec.budget_evaluations * workloads, "points", 0.0);
    Context cx{spec, store, settings, progress, spec.budget_evaluations * workloads};

    // Configurations screened so far (a resumed explore's from the store), with the trial that
    // first asked for each.
    std::map<size_t, ExploreScore> screened;
    std::map<size_t, int64_t> trial_of;
    {
        std::vector<size_t> known;
        for (const auto& [c, trial] : store.explore_configs(spec.name, "screen")) {
            known.push_back(c);
            trial_of[c] = trial;
        }
        if (!known.empty()) screened = evaluate(cx, known, spec.screen);
    }
    if (o.exhaustive) {
        std::vector<size_t> missing;
        for (size_t c = 0; c < space; ++c)
            if (!screened.count(c)) missing.push_back(c);
        for (const auto& [c, s] : evaluate(cx, missing, spec.screen)) {
            screened[c] = s;
            trial_of[c] = -1;
        }
    } else {
        Search search(spec, study);
        int stale = 0;
        nlohmann::json results = nlohmann::json::array();  // of the last round, told with the next ask
        auto more = [&] {
            return screened.size() < spec.budget_evaluations && screened.size() < space && stale < k_stale_rounds &&
                   !(spec.budget_seconds > 0 && progress.elapsed() >= spec.budget_seconds);
        };
        while (more()) {
            const size_t n = std::min(spec.batch, spec.budget_evaluations - screened.size());
            const std::vector<Search::Trial> trials = search.tell_and_ask(results, n);
            results = nlohmann::json::array();
            std::vector<size_t> fresh;
            for (const Search::Trial& t : trials)
                if (!screened.count(t.config) && std::find(fresh.begin(), fresh.end(), t.config) == fresh.end()) {
                    // A resumed batch may hold more than the budget has left: the budget wins.
                    if (screened.size() + fresh.size() >= spec.budget_evaluations) break;
                    fresh.push_back(t.config);
                    trial_of[t.config] = t.number;
                }
            stale = fresh.empty() ? stale + 1 : 0;
            const std::map<size_t, ExploreScore> scores = evaluate(cx, fresh, spec.screen);
            std::vector<ResultsStore::ExploreConfigRow> rows;
            for (const auto& [c, s] : scores) {
                screened[c] = s;
                rows.push_back(store_row(spec, c, "screen", trial_of[c], s, false));
            }
            store.write_explore_configs(spec.name, rows);
            for (const Search::Trial& t : trials) {
                auto it = screened.find(t.config);
                if (it == screened.end())
                    results.push_back({{"number", t.number}, {"failed", true}});  // cut by the budget
                else
                    results.push_back({{"number", t.number},
                                       {"values", objective_values(spec, it->second)},
                                       {"constraints", constraint_values(spec, it->second)}});
            }
            if (!more()) search.tell_and_ask(results, 0);
        }
    }

    // The screened front, then its confirmation and the confirmed front.
    std::vector<size_t> configs;
    std::vector<ExploreScore> scores;
    for (const auto& [c, s] : screened) {
        configs.push_back(c);
        scores.push_back(s);
    }
    std::vector<size_t> screen_front;
    for (size_t i : pareto_front(spec, scores)) screen_front.push_back(configs[i]);
    const bool has_confirm = spec.confirm != spec.screen && !screen_front.empty();
    std::map<size_t, ExploreScore> confirmed;
    std::vector<size_t> front = screen_front;
    if (has_confirm) {
        cx.total += screen_front.size() * workloads;
        progress.set_total(cx.total - std::min(cx.total, cx.found));
        confirmed = evaluate(cx, screen_front, spec.confirm);
        std::vector<ExploreScore> cs;
        for (size_t c : screen_front) cs.push_back(confirmed.at(c));
        front.clear();
        for (size_t i : pareto_front(spec, cs)) front.push_back(screen_front[i]);
    }
    progress.finish();
    std::vector<ResultsStore::ExploreConfigRow> rows;
    for (const auto& [c, s] : screened)
        rows.push_back(store_row(spec, c, "screen", trial_of[c], s,
                                 std::find(screen_front.begin(), screen_front.end(), c) != screen_front.end()));
    for (const auto& [c, s] : confirmed)
        rows.push_back(store_row(spec, c, "confirm", trial_of[c], s, std::find(front.begin(), front.end(), c) != front.end()));
    store.write_explore_configs(spec.name, rows);

    size_t feasible_count = 0;
    for (const auto& kv : screened) feasible_count += feasible(spec, kv.second);
    if (o.json) {
        nlohmann::ordered_json j;
        j["explore"] = spec.name;
        j["store"] = o.store;
        if (!o.exhaustive) j["study"] = study;
        j["configurations"] = space;
        j["evaluations"] = screened.size();
        j["feasible"] = feasible_count;
        j["points_run"] = cx.ran;
        j["points_stored"] = cx.stored;
        j["seconds"] = progress.elapsed();
        j["screen"] = to_string(spec.screen);
        j["confirm"] = to_string(spec.confirm);
        j["nodes"] = spec.nodes();
        j["objectives"] = objectives_json(spec);
        auto entry = [&](size_t c, const ExploreScore& s) {
            return nlohmann::ordered_json{{"config", c},
                                          {"trial", trial_of[c]},
                                          {"knobs", knobs_json(spec, c)},
                                          {"values", objective_values(spec, s)},
                                          {"feasible", feasible(spec, s)},
                                          {"scores", scores_json(s)}};
        };
        j["screened"] = nlohmann::ordered_json::array();
        for (const auto& [c, s] : screened) j["screened"].push_back(entry(c, s));
        j["screen_front"] = nlohmann::ordered_json::array();
        for (size_t c : screen_front) j["screen_front"].push_back(entry(c, screened.at(c)));
        j["front"] = nlohmann::ordered_json::array();
        for (size_t c : front) j["front"].push_back(entry(c, has_confirm ? confirmed.at(c) : screened.at(c)));
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::string nodes;
    for (const std::string& n : spec.nodes()) nodes += (nodes.empty() ? "" : ", ") + n;
    std::cout << "explore " << spec.name << " at " << nodes << ": " << screened.size() << " of " << space
              << " configurations screened at " << to_string(spec.screen) << " (" << feasible_count
              << " meet the constraints); " << screen_front.size() << " on the screened front";
    if (has_confirm) std::cout << ", " << front.size() << " still on it at " << to_string(spec.confirm);
    std::cout << "\n";
    if (front.empty()) {
        std::cout << "no screened configuration meets the constraints: relax them or widen the knobs\n";
    } else {
        std::cout << "the front (rank: by " << spec.objectives[0].metric << (has_confirm ? ", screened -> confirmed" : "")
                  << "):\n";
        print_front(spec, front, screened, confirmed, has_confirm, std::cout);
    }
    std::cout << "\n" << cx.ran << " points run, " << cx.stored << " already stored, in "
              << fixed_text(progress.elapsed(), 1) << " s; store " << o.store;
    if (!o.exhaustive) std::cout << ", study " << study;
    std::cout << " (sfx report " << o.store << " -o DIR shows the front)\n";
}

}  // namespace

void add_explore_command(CLI::App& app) {
    auto o = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand("explore", "search an explore file's space for the Pareto front (Optuna; resumable)");
    c->add_option("explore", o->file, "explore file (see sweeps/README.md)")->required();
    c->add_option("--store", o->store, "results store (SQLite file; created if missing)")->required();
    c->add_option("--study", o->study, "the Optuna study (SQLite file; default: the store's path + .optuna)");
    c->add_option("--engine", o->engine, "local | dask")->check(CLI::IsMember({"local", "dask"}))->capture_default_str();
    c->add_option("--scheduler", o->scheduler, "Dask scheduler address, tcp://HOST:PORT");
    c->add_option("--jobs", o->jobs, "local: point groups at once (0: one per core)")
        ->capture_default_str()
        ->check(CLI::Range(0u, k_max_threads));
    c->add_option("--threads", o->threads, "render threads per group (0: the cores divided among the jobs)")
        ->capture_default_str()
        ->check(CLI::Range(0u, k_max_threads));
    c->add_option("--set", o->sets, "change the base point: PATH=VALUE (workload.res=64x64, hw.clock.core_mhz=1000)");
    c->add_option("--sampler", o->sampler, "tpe | nsga2 | random (default: search.sampler of the file)")
        ->check(CLI::IsMember({"tpe", "nsga2", "random"}));
    c->add_option("--seed", o->seed, "the search's seed (default: search.seed of the file)")->check(CLI::Range(0L, 1L << 30));
    c->add_option("--budget", o->budget, "configurations to screen at most (default: budget.evaluations of the file)")
        ->check(CLI::Range(size_t(1), size_t(1) << 40));
    c->add_flag("--exhaustive", o->exhaustive,
                "screen every configuration of the space, no search (recorded as NAME/grid): the grid to judge a search by");
    c->add_flag("--json", o->json, "print one JSON document");
    c->callback([o] { run_explore(*o); });
}

}  // namespace sfx
