// sfx sweep SWEEP --store DB: every point of a sweep into the results store, resumable, on
// local child processes or a Dask cluster. Also the hidden `sfx run-group` that both engines
// run for one point group.

#include <unistd.h>
#ifdef __linux__
#include <signal.h>
#include <sys/prctl.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/commands.h"
#include "app/point_runner.h"
#include "app/progress.h"
#include "app/text_table.h"
#include "sweeps/engine.h"
#include "sweeps/group_runner.h"
#include "sweeps/host_time_estimate.h"
#include "sweeps/results_store.h"
#include "sweeps/sweep.h"
#include "base/host_clock.h"
#include "base/input_error.h"
#include "base/user_files.h"

namespace sfx {
namespace {

std::string group_label(const PointGroup& group, size_t points) {
    const struct {
        const WorkloadConfig& workload;
        Fidelity fidelity;
    } p{group.workload, group.fidelity};
    std::string scene = p.workload.scene;
    if (scene.find('/') != std::string::npos) scene = scene.substr(scene.find_last_of('/') + 1);
    return scene + " " + std::to_string(p.workload.width) + "x" +
           std::to_string(p.workload.height) + " spp " + std::to_string(p.workload.spp) +
           " depth " + std::to_string(p.workload.depth) + " tile " +
           std::to_string(p.workload.tile) +
           (p.workload.seed ? " seed " + std::to_string(p.workload.seed) : std::string()) +
           (p.workload.primary_entry != "root" ? " entry " + p.workload.primary_entry
                                               : std::string()) +
           (p.workload.reorder != "none" ? " reorder " + p.workload.reorder + " " +
                                               std::to_string(p.workload.reorder_lod_ppm) + " ppm"
                                         : std::string()) +
           (p.workload.batching != "none"
                ? " batching " + p.workload.batching + " " +
                      std::to_string(p.workload.batching_queue) + " rays/queue " +
                      std::to_string(p.workload.batching_cell_prims) + " prims/cell"
                : std::string()) +
           " " + to_string(p.fidelity) + " (" + std::to_string(points) + " config" +
           (points == 1 ? "" : "s") + ")";
}

// Rows of the summary table at most; a larger sweep's rows are in the store (--csv, sfx report).
constexpr size_t k_summary_rows = 200;

// (expansion index, key) of every point of the sweep, in expansion order.
using PointKeys = std::vector<std::pair<size_t, std::string>>;

void print_summary(const Sweep& sweep, const PointKeys& keys, const ResultsStore& store,
                   const std::set<std::string>& ran, std::ostream& out) {
    std::vector<std::string> headers = {"#"};
    for (const std::string& a : sweep.axes) headers.push_back(a);
    const std::vector<std::pair<std::string, std::string>> metrics = {
        {"fps", "fps"},
        {"simd_utilization.traversal", "util trav"},
        {"simd_utilization.intersection", "util isec"},
        {"simd_utilization.shading", "util shade"},
        {"stall_cycles.total", "stalls %"},
        {"error.relative", "interval"},
        {"host_seconds", "host s"}};
    for (const auto& m : metrics) headers.push_back(m.second);
    headers.push_back("");
    std::vector<std::vector<std::string>> rows;
    for (size_t k = 0; k < std::min(keys.size(), k_summary_rows); ++k) {
        const auto& [index, key] = keys[k];
        std::vector<std::string> row = {std::to_string(index)};
        for (const auto& av : sweep.axis_values(index)) row.push_back(av.second);
        const std::map<std::string, double> n = store.numbers(key);
        auto get = [&](const std::string& k) {
            auto it = n.find(k);
            return it == n.end() ? std::nan("") : it->second;
        };
        if (n.empty()) {
            for (size_t i = 0; i < metrics.size(); ++i) row.push_back("-");
            row.push_back("missing");
        } else {
            // 4 significant digits: paper-scale frames run well below 1 fps.
            row.push_back(significant_text(get("fps")));
            for (const char* s : {"traversal", "intersection", "shading"})
                row.push_back(fixed_text(100 * get(std::string("simd_utilization.") + s), 1) + "%");
            row.push_back(fixed_text(100 * get("stall_cycles.total") / std::max(1.0, get("frame_cycles")), 1));
            const double interval = get("error.relative");
            row.push_back(interval >= 0 ? "+-" + fixed_text(100 * interval, 2) + "%" : "unknown");
            row.push_back(fixed_text(get("host_seconds"), 3));
            row.push_back(ran.count(key) ? "" : "stored");
        }
        rows.push_back(std::move(row));
    }
    // Axis values left-aligned, numbers right-aligned.
    print_text_table(out, headers, rows, [&](size_t c) { return c > 0 && c <= sweep.axes.size(); });
    if (keys.size() > rows.size())
        out << "... and " << keys.size() - rows.size()
            << " more rows: every row is in the store (--csv FILE writes them; sfx report)\n";
}

void print_dry_run(const Sweep& sweep, bool json) {
    const std::vector<FidelityEstimate> estimate = estimate_host_seconds(sweep);
    if (json) {
        nlohmann::ordered_json j;
        j["sweep"] = sweep.name;
        j["points"] = sweep.point_count;
        j["groups"] = sweep.groups.size();
        j["duplicates"] = sweep.duplicates;
        j["axes"] = sweep.axes;
        j["estimate"] = nlohmann::ordered_json::array();
        for (const FidelityEstimate& e : estimate)
            j["estimate"].push_back({{"fidelity", to_string(e.fidelity)},
                                     {"points", e.points},
                                     {"groups", e.groups},
                                     {"host_seconds", e.seconds}});
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::cout << "sweep " << sweep.name << ": " << sweep.point_count << " points in "
              << sweep.groups.size() << " renders";
    if (sweep.duplicates) std::cout << " (" << sweep.duplicates << " duplicate points dropped)";
    std::cout << "\n";
    constexpr size_t k_listed = 50;  // a large sweep's groups are counted, not listed
    for (size_t g = 0; g < std::min(k_listed, sweep.groups.size()); ++g)
        std::cout << "  group " << g << ": " << group_label(sweep.groups[g], sweep.groups[g].points.size()) << "\n";
    if (sweep.groups.size() > k_listed) std::cout << "  ... and " << sweep.groups.size() - k_listed << " more groups\n";
    std::cout << "estimated host time (one core; " << k_estimate_basis << "):\n";
    double total = 0;
    for (const FidelityEstimate& e : estimate) {
        std::cout << "  " << std::setw(8) << to_string(e.fidelity) << ": " << e.points << " points in "
                  << e.groups << " renders, " << duration_text(e.seconds) << "\n";
        total += e.seconds;
    }
    std::cout << "  total: " << duration_text(total) << " of CPU time, about "
              << duration_text(total / std::max(1u, std::thread::hardware_concurrency()))
              << " on this machine's " << std::max(1u, std::thread::hardware_concurrency())
              << " cores\n";
}

void run_sweep(const std::string& path, const std::string& store_path, const std::string& csv,
               const std::string& engine, const std::string& scheduler, unsigned jobs,
               uint32_t threads, const std::vector<std::string>& sets, bool dry_run, bool json,
               size_t max_points) {
    if (engine == "dask" && scheduler.empty())
        throw InputError("command line", 0, "--scheduler", "--engine dask needs --scheduler tcp://HOST:PORT");
    // Everything is checked before the store is opened: a bad sweep writes nothing, and an
    // output that cannot be written fails now, not after the sweep has run.
    if (!csv.empty()) check_output_file(csv, "--csv");
    if (!store_path.empty() && access(store_path.c_str(), F_OK) != 0) check_output_file(store_path, "--store");
    const Sweep sweep = load_sweep(path, sets, max_points);
    for (const std::string& w : sweep.warnings) std::cerr << "warning: " << w << "\n";
    if (dry_run) {
        print_dry_run(sweep, json);
        return;
    }
    if (store_path.empty()) throw InputError("command line", 0, "--store", "required (or --dry-run)");
    ResultsStore store(store_path);

    const EngineSettings settings = engine_settings(engine, scheduler, jobs, threads, sweep.groups.size());
    if (!json)
        std::cerr << "sweep " << sweep.name << ": " << sweep.point_count << " points in "
                  << sweep.groups.size() << " renders on "
                  << (engine == "local" ? std::to_string(settings.parallel) + " local processes x " +
                                              std::to_string(settings.group_threads) + " threads"
                                        : "Dask at " + scheduler)
                  << "; points already stored are skipped\n";
    // Points done / total, ETA and the running group: a bar on a terminal, else one line per
    // finished group. The total drops as stored points are found.
    Progress progress("sweep", sweep.point_count, "points", 0.0);

    // Groups are made (points, keys) as the engine asks for them.
    PointKeys keys;
    keys.reserve(sweep.point_count);
    size_t next_group = 0, found = 0;
    const NextRunGroup next = [&](RunGroup& group) {
        if (next_group >= sweep.groups.size()) return false;
        const PointGroup& g = sweep.groups[next_group++];
        group.points.clear();
        for (size_t i : g.points) {
            group.points.push_back(sweep.point(i));
            keys.emplace_back(i, group.points.back().key);
        }
        group.label = group_label(g, g.points.size());
        return true;
    };
    const RunOutcome outcome = run_point_groups(next, store, sweep.name, settings, progress, [&](size_t n) {
        found += n;
        progress.set_total(sweep.point_count - found);
    });
    progress.finish();
    const double seconds = outcome.seconds;
    const std::set<std::string>& ran = outcome.ran;
    const size_t already_stored = outcome.already_stored;

    std::sort(keys.begin(), keys.end());
    if (!csv.empty()) {
        std::vector<std::string> in_order;
        for (const auto& [index, key] : keys) in_order.push_back(key);
        store.export_csv(csv, in_order);
    }
    if (json) {
        nlohmann::ordered_json j;
        j["sweep"] = sweep.name;
        j["store"] = store_path;
        j["points"] = sweep.point_count;
        j["groups"] = sweep.groups.size();
        j["already_stored"] = already_stored;
        j["ran"] = ran.size();
        j["failed_groups"] = outcome.failures.size();
        j["seconds"] = seconds;
        j["rows"] = nlohmann::ordered_json::array();
        for (const auto& [index, key] : keys) {
            nlohmann::ordered_json r;
            r["point_index"] = index;
            r["key"] = key;
            for (const auto& [axis, value] : sweep.axis_values(index)) r[axis] = value;
            for (const auto& [name, value] : store.numbers(key))
                if (name != "point_index") r[name] = value;
            j["rows"].push_back(r);
        }
        std::cout << j.dump(2) << "\n";
    } else {
        print_summary(sweep, keys, store, ran, std::cout);
        std::cout << "\n" << ran.size() << " points run, " << already_stored
                  << " already stored, in " << fixed_text(seconds, 1) << " s; store " << store_path;
        if (!csv.empty()) std::cout << ", CSV " << csv;
        std::cout << "\n";
    }
    if (!outcome.failures.empty()) throw_group_failures(outcome, path);
}

}  // namespace

void add_sweep_command(CLI::App& app) {
    struct Options {
        std::string sweep, store, csv, engine = "local", scheduler;
        unsigned jobs = 0;
        uint32_t threads = 0;
        std::vector<std::string> sets;
        bool dry_run = false, json = false;
        size_t max_points = k_default_max_points;
    };
    auto o = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand("sweep", "run every point of a sweep into the results store (resumable)");
    c->add_option("sweep", o->sweep, "sweep file (*.sweep.yaml)")->required();
    c->add_option("--store", o->store, "results store (SQLite file; created if missing)");
    c->add_option("--csv", o->csv, "also write this sweep's rows as CSV");
    c->add_option("--engine", o->engine, "local | dask")->check(CLI::IsMember({"local", "dask"}))->capture_default_str();
    c->add_option("--scheduler", o->scheduler, "Dask scheduler address, tcp://HOST:PORT");
    c->add_option("--jobs", o->jobs, "local: point groups at once (0: one per core)")
        ->capture_default_str()
        ->check(CLI::Range(0u, k_max_threads));
    c->add_option("--threads", o->threads,
                  "render threads per group (0: the cores divided among the jobs)")
        ->capture_default_str()
        ->check(CLI::Range(0u, k_max_threads));
    c->add_option("--set", o->sets, "change the base point: PATH=VALUE (workload.res=64x64, hw.simd.width=8)");
    c->add_flag("--dry-run", o->dry_run,
                "check and expand the sweep, print its groups and estimated host time, run nothing, write nothing");
    c->add_option("--max-points", o->max_points,
                  "refuse a sweep (or an axis) of more points than this: a guard against a typo in a range")
        ->capture_default_str()
        ->check(CLI::Range(size_t(1), size_t(1) << 40));
    c->add_flag("--json", o->json, "print one JSON document");
    c->callback([o] {
        run_sweep(o->sweep, o->store, o->csv, o->engine, o->scheduler, o->jobs, o->threads, o->sets,
                  o->dry_run, o->json, o->max_points);
    });

    // Hidden: the unit of work of both engines. A group spec on stdin, one JSON row per line.
    auto parent = std::make_shared<long>(0);
    CLI::App* r = app.add_subcommand("run-group", "run one point group from a JSON spec on stdin");
    r->group("");  // not listed in --help
    r->add_option("--parent-pid", *parent, "exit when this process dies");
    r->callback([parent] {
#ifdef __linux__
        // A killed sweep (or Dask worker) must not leave its renders running. The signal follows
        // the spawning thread, which lives until this process has been waited for.
        if (*parent > 0) {
            prctl(PR_SET_PDEATHSIG, SIGKILL);
            if (getppid() != pid_t(*parent)) return;
        }
#endif
        const std::string input{std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>()};
        nlohmann::json spec;
        try {
            spec = nlohmann::json::parse(input);
        } catch (const std::exception& e) {
            throw InputError("group spec", 0, "", std::string("not JSON: ") + e.what());
        }
        for (const PointRun& row : run_group(spec)) std::cout << point_run_json(row).dump() << "\n";
        std::cout.flush();
    });
}

}  // namespace sfx
