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
#include <sstream>
#include <thread>

#include "app/commands.h"
#include "app/progress.h"
#include "sweeps/engine.h"
#include "sweeps/group_runner.h"
#include "sweeps/results_store.h"
#include "sweeps/sweep.h"
#include "base/host_clock.h"
#include "base/input_error.h"
#include "base/user_files.h"

namespace sfx {
namespace {

std::string fixed(double v, int digits) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(digits) << v;
    return s.str();
}

std::string group_label(const Sweep& sweep, const std::vector<size_t>& points) {
    const SweepPoint& p = sweep.points[points.front()];
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
           " " + to_string(p.fidelity) + " (" + std::to_string(points.size()) + " config" +
           (points.size() == 1 ? "" : "s") + ")";
}

struct Failure {
    size_t group;
    int exit_code;
    std::string message;
};

void print_summary(const Sweep& sweep, const ResultsStore& store, const std::set<std::string>& ran,
                   std::ostream& out) {
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
    for (const SweepPoint& p : sweep.points) {
        std::vector<std::string> row = {std::to_string(p.index)};
        for (const auto& av : p.axis_values) row.push_back(av.second);
        const std::map<std::string, double> n = store.numbers(p.key);
        auto get = [&](const std::string& k) {
            auto it = n.find(k);
            return it == n.end() ? std::nan("") : it->second;
        };
        if (n.empty()) {
            for (size_t i = 0; i < metrics.size(); ++i) row.push_back("-");
            row.push_back("missing");
        } else {
            char fps[32];  // 4 significant digits: paper-scale frames run well below 1 fps
            std::snprintf(fps, sizeof fps, "%.4g", get("fps"));
            row.push_back(fps);
            for (const char* s : {"traversal", "intersection", "shading"})
                row.push_back(fixed(100 * get(std::string("simd_utilization.") + s), 1) + "%");
            row.push_back(fixed(100 * get("stall_cycles.total") / std::max(1.0, get("frame_cycles")), 1));
            const double interval = get("error.relative");
            row.push_back(interval >= 0 ? "+-" + fixed(100 * interval, 2) + "%" : "unknown");
            row.push_back(fixed(get("host_seconds"), 3));
            row.push_back(ran.count(p.key) ? "" : "stored");
        }
        rows.push_back(std::move(row));
    }
    std::vector<size_t> width(headers.size());
    for (size_t c = 0; c < headers.size(); ++c) {
        width[c] = headers[c].size();
        for (const auto& r : rows) width[c] = std::max(width[c], r[c].size());
    }
    auto print = [&](const std::vector<std::string>& r) {
        std::string line;
        for (size_t c = 0; c < r.size(); ++c) {
            const bool left = c > 0 && c <= sweep.axes.size();
            const std::string pad(width[c] - r[c].size(), ' ');
            line += (c ? "  " : "") + (left ? r[c] + pad : pad + r[c]);
        }
        while (!line.empty() && line.back() == ' ') line.pop_back();
        out << line << "\n";
    };
    print(headers);
    for (const auto& r : rows) print(r);
}

void run_sweep(const std::string& path, const std::string& store_path, const std::string& csv,
               const std::string& engine, const std::string& scheduler, unsigned jobs,
               uint32_t threads, const std::vector<std::string>& sets, bool dry_run, bool json) {
    if (engine == "dask" && scheduler.empty())
        throw InputError("command line", 0, "--scheduler", "--engine dask needs --scheduler tcp://HOST:PORT");
    // Everything is checked before the store is opened: a bad sweep writes nothing, and an
    // output that cannot be written fails now, not after the sweep has run.
    if (!csv.empty()) check_output_file(csv, "--csv");
    if (!store_path.empty() && access(store_path.c_str(), F_OK) != 0) check_output_file(store_path, "--store");
    const Sweep sweep = load_sweep(path, sets);
    if (dry_run) {
        if (json) {
            nlohmann::ordered_json j;
            j["sweep"] = sweep.name;
            j["points"] = sweep.points.size();
            j["groups"] = sweep.groups.size();
            j["duplicates"] = sweep.duplicates;
            j["axes"] = sweep.axes;
            std::cout << j.dump(2) << "\n";
        } else {
            std::cout << "sweep " << sweep.name << ": " << sweep.points.size() << " points in "
                      << sweep.groups.size() << " renders";
            if (sweep.duplicates) std::cout << " (" << sweep.duplicates << " duplicate points dropped)";
            std::cout << "\n";
            for (size_t g = 0; g < sweep.groups.size(); ++g)
                std::cout << "  group " << g << ": " << group_label(sweep, sweep.groups[g].points) << "\n";
        }
        return;
    }
    if (store_path.empty()) throw InputError("command line", 0, "--store", "required (or --dry-run)");
    ResultsStore store(store_path);
    const std::set<std::string> stored = store.keys();

    std::map<std::string, size_t> point_of_key;
    for (size_t i = 0; i < sweep.points.size(); ++i) point_of_key[sweep.points[i].key] = i;
    std::vector<std::vector<size_t>> pending(sweep.groups.size());
    size_t pending_points = 0;
    for (size_t g = 0; g < sweep.groups.size(); ++g)
        for (size_t i : sweep.groups[g].points)
            if (!stored.count(sweep.points[i].key)) {
                pending[g].push_back(i);
                ++pending_points;
            }
    std::vector<GroupJob> todo;
    for (size_t g = 0; g < sweep.groups.size(); ++g)
        if (!pending[g].empty()) todo.push_back({g, ""});
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    const unsigned parallel = std::max(1u, std::min<unsigned>(jobs ? jobs : cores, unsigned(std::max<size_t>(1, todo.size()))));
    // Local children share the cores; a Dask task may use its whole worker (0: all cores).
    const uint32_t group_threads = threads ? threads : engine == "local" ? std::max(1u, cores / parallel) : 0;
    for (GroupJob& job : todo) job.spec = group_spec_json(sweep, pending[job.group], group_threads).dump();

    if (!json)
        std::cerr << "sweep " << sweep.name << ": " << sweep.points.size() << " points in "
                  << sweep.groups.size() << " renders; " << (sweep.points.size() - pending_points)
                  << " already stored, " << pending_points << " to run in " << todo.size()
                  << " groups on " << (engine == "local" ? std::to_string(parallel) + " local processes x " +
                                                               std::to_string(group_threads) + " threads"
                                                         : "Dask at " + scheduler)
                  << "\n";
    // Points done / total, ETA and the running group: a bar on a terminal, else one line per
    // finished group.
    Progress progress("sweep", pending_points, "points", 0.0);
    std::set<std::string> ran;
    std::vector<Failure> failures;
    std::vector<size_t> rows_of_group(sweep.groups.size(), 0);
    EngineEvents events;
    events.started = [&](size_t g) { progress.set_label(group_label(sweep, pending[g])); };
    events.row = [&](size_t g, const PointRun& run) {
        auto it = point_of_key.find(run.key);
        if (it == point_of_key.end() ||
            std::find(pending[g].begin(), pending[g].end(), it->second) == pending[g].end())
            throw std::runtime_error("a worker returned a point this group did not ask for (key " + run.key +
                                     ", worker sfx " + run.sfx_version + ", this sfx " + sfx_version() +
                                     "): workers must run the same sfx version");
        store.write_point(sweep.points[it->second], sweep.name, run);
        if (ran.insert(run.key).second) {
            ++rows_of_group[g];
            progress.advance(1);
        }
    };
    events.finished = [&](size_t g) {
        if (rows_of_group[g] != pending[g].size())
            failures.push_back({g, 1, "returned " + std::to_string(rows_of_group[g]) + " of " +
                                          std::to_string(pending[g].size()) + " rows"});
        if (!progress.terminal())
            progress.log("sweep: done " + group_label(sweep, pending[g]) + "  " +
                         progress.status());
    };
    events.failed = [&](size_t g, int code, const std::string& message) {
        failures.push_back({g, code, message});
        if (progress.terminal())
            progress.clear();
        else
            progress.log("sweep: FAILED " + group_label(sweep, pending[g]) + "  " +
                         progress.status());
    };
    if (!todo.empty()) {
        if (engine == "local") run_local(todo, parallel, self_executable(), events);
        else run_dask(todo, scheduler, self_executable(), events);
    }
    progress.finish();
    const double seconds = progress.elapsed();

    std::vector<std::string> keys;
    for (const SweepPoint& p : sweep.points) keys.push_back(p.key);
    if (!csv.empty()) store.export_csv(csv, keys);
    if (json) {
        nlohmann::ordered_json j;
        j["sweep"] = sweep.name;
        j["store"] = store_path;
        j["points"] = sweep.points.size();
        j["groups"] = sweep.groups.size();
        j["already_stored"] = sweep.points.size() - pending_points;
        j["ran"] = ran.size();
        j["failed_groups"] = failures.size();
        j["seconds"] = seconds;
        j["rows"] = nlohmann::ordered_json::array();
        for (const SweepPoint& p : sweep.points) {
            nlohmann::ordered_json r;
            r["point_index"] = p.index;
            r["key"] = p.key;
            for (const auto& [axis, value] : p.axis_values) r[axis] = value;
            for (const auto& [name, value] : store.numbers(p.key))
                if (name != "point_index") r[name] = value;
            j["rows"].push_back(r);
        }
        std::cout << j.dump(2) << "\n";
    } else {
        print_summary(sweep, store, ran, std::cout);
        std::cout << "\n" << ran.size() << " points run, " << (sweep.points.size() - pending_points)
                  << " already stored, in " << fixed(seconds, 1) << " s; store " << store_path;
        if (!csv.empty()) std::cout << ", CSV " << csv;
        std::cout << "\n";
    }
    if (!failures.empty()) {
        bool input_error = false;
        for (const Failure& f : failures) {
            std::cerr << "sfx: group " << f.group << " (" << group_label(sweep, pending[f.group])
                      << ") failed: " << f.message << "\n";
            input_error |= f.exit_code == 2;
        }
        const std::string what = std::to_string(failures.size()) + " of " + std::to_string(todo.size()) +
                                 " groups failed; re-run to retry them (stored points are kept)";
        if (input_error) throw InputError(path, 0, "", what);
        throw std::runtime_error(what);
    }
}

}  // namespace

void add_sweep_command(CLI::App& app) {
    struct Options {
        std::string sweep, store, csv, engine = "local", scheduler;
        unsigned jobs = 0;
        uint32_t threads = 0;
        std::vector<std::string> sets;
        bool dry_run = false, json = false;
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
    c->add_flag("--dry-run", o->dry_run, "check and expand the sweep, run nothing, write nothing");
    c->add_flag("--json", o->json, "print one JSON document");
    c->callback([o] {
        run_sweep(o->sweep, o->store, o->csv, o->engine, o->scheduler, o->jobs, o->threads, o->sets,
                  o->dry_run, o->json);
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
