#include "app/point_runner.h"

#include <algorithm>
#include <iostream>
#include <map>
#include <stdexcept>
#include <thread>

#include "base/input_error.h"
#include "sweeps/engine.h"
#include "sweeps/group_runner.h"

namespace sfx {
namespace {

// Dask: groups submitted and unfinished at most, so the client holds a bounded part of the
// run; enough to keep a few hundred worker threads busy.
constexpr unsigned k_dask_window = 256;

}  // namespace

EngineSettings engine_settings(const std::string& engine, const std::string& scheduler,
                               unsigned jobs, uint32_t threads, size_t groups) {
    if (engine == "dask" && scheduler.empty())
        throw InputError("command line", 0, "--scheduler", "--engine dask needs --scheduler tcp://HOST:PORT");
    EngineSettings s;
    s.engine = engine;
    s.scheduler = scheduler;
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    s.parallel = std::max(1u, std::min<unsigned>(jobs ? jobs : cores, unsigned(std::max<size_t>(1, groups))));
    s.group_threads = threads ? threads : engine == "local" ? std::max(1u, cores / s.parallel) : 0;
    return s;
}

RunOutcome run_point_groups(const NextRunGroup& next_group, ResultsStore& store, const std::string& writer,
                            const EngineSettings& settings, Progress& progress,
                            const std::function<void(size_t)>& found_stored) {
    struct Running {
        std::string label;
        std::vector<SweepPoint> points;  // not yet stored
        std::vector<ResultsStore::PointRow> rows;
    };
    std::map<size_t, Running> running;
    size_t next_id = 0;
    RunOutcome out;
    const NextGroup next = [&](GroupJob& job) {
        RunGroup group;
        while (next_group(group)) {
            std::vector<std::string> keys;
            for (const SweepPoint& p : group.points) keys.push_back(p.key);
            const std::set<std::string> stored = store.stored_keys(keys);
            group.points.erase(std::remove_if(group.points.begin(), group.points.end(),
                                              [&](const SweepPoint& p) { return stored.count(p.key) > 0; }),
                               group.points.end());
            out.already_stored += stored.size();
            if (!stored.empty() && found_stored) found_stored(stored.size());
            if (group.points.empty()) continue;
            job.group = next_id++;
            job.spec = group_spec_json(group.points, settings.group_threads).dump();
            running[job.group] = {group.label, std::move(group.points), {}};
            ++out.groups_run;
            return true;
        }
        return false;
    };
    // The rows a group returned, in one transaction; each point counted once.
    auto write_rows = [&](size_t g) {
        Running& r = running[g];
        store.write_points(r.rows, writer);
        for (const ResultsStore::PointRow& row : r.rows)
            if (out.ran.insert(row.run.key).second) progress.advance(1);
    };
    EngineEvents events;
    events.started = [&](size_t g) { progress.set_label(running[g].label); };
    events.row = [&](size_t g, const PointRun& run) {
        Running& r = running[g];
        auto it = std::find_if(r.points.begin(), r.points.end(),
                               [&](const SweepPoint& p) { return p.key == run.key; });
        if (it == r.points.end())
            throw std::runtime_error("a worker returned a point this group did not ask for (key " + run.key +
                                     ", worker sfx " + run.sfx_version + ", this sfx " + sfx_version() +
                                     "): workers must run the same sfx version");
        for (const ResultsStore::PointRow& row : r.rows)
            if (row.run.key == run.key) return;  // a repeat
        r.rows.push_back({&*it, run});
    };
    events.finished = [&](size_t g) {
        write_rows(g);
        const Running& r = running[g];
        if (r.rows.size() != r.points.size())
            out.failures.push_back({r.label, 1, "returned " + std::to_string(r.rows.size()) + " of " +
                                                    std::to_string(r.points.size()) + " rows"});
        if (!progress.terminal()) progress.log(progress.what() + ": done " + r.label + "  " + progress.status());
        running.erase(g);
    };
    events.failed = [&](size_t g, int code, const std::string& message) {
        write_rows(g);  // rows returned before the failure are kept
        out.failures.push_back({running[g].label, code, message});
        if (progress.terminal())
            progress.clear();
        else
            progress.log(progress.what() + ": FAILED " + running[g].label + "  " + progress.status());
        running.erase(g);
    };
    const HostClock::time_point start = HostClock::now();
    if (settings.engine == "local")
        run_local(next, settings.parallel, self_executable(), events);
    else
        run_dask(next, settings.scheduler, self_executable(), k_dask_window, events);
    out.seconds = seconds_since(start);
    return out;
}

void throw_group_failures(const RunOutcome& outcome, const std::string& file) {
    bool input_error = false;
    for (const GroupFailure& f : outcome.failures) {
        std::cerr << "sfx: group (" << f.label << ") failed: " << f.message << "\n";
        input_error |= f.exit_code == 2;
    }
    const std::string what = std::to_string(outcome.failures.size()) + " of " +
                             std::to_string(outcome.groups_run) +
                             " groups failed; re-run to retry them (stored points are kept)";
    if (input_error) throw InputError(file, 0, "", what);
    throw std::runtime_error(what);
}

}  // namespace sfx
