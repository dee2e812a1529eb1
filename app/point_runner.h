#pragma once
// Runs point groups into the results store on an engine: the part of `sfx sweep` that
// `sfx explore` shares. A group's points are looked up in the store just before it runs (stored
// points are skipped, so nothing runs twice), and a group's rows are written in one transaction
// when it finishes.

#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "app/progress.h"
#include "sweeps/results_store.h"
#include "sweeps/sweep.h"

namespace sfx {

struct EngineSettings {
    std::string engine = "local";  // local | dask
    std::string scheduler;         // dask: tcp://HOST:PORT
    unsigned parallel = 1;         // local: groups at once
    uint32_t group_threads = 0;    // render threads per group (0: all of a worker's cores)
};

// Local children share the machine's cores; a Dask task may use its whole worker. `jobs` and
// `threads` are the user's flags (0: choose).
EngineSettings engine_settings(const std::string& engine, const std::string& scheduler,
                               unsigned jobs, uint32_t threads, size_t groups);

struct RunGroup {
    std::string label;               // for progress and messages
    std::vector<SweepPoint> points;  // every point of the group, stored ones included
};
// The next group (false: no more). Called as the engine has room, never concurrently.
using NextRunGroup = std::function<bool(RunGroup& group)>;

struct GroupFailure {
    std::string label;
    int exit_code = 1;  // 2: bad input
    std::string message;
};

struct RunOutcome {
    std::set<std::string> ran;  // keys of the points run and written now
    size_t already_stored = 0;  // points found in the store and skipped
    size_t groups_run = 0;
    std::vector<GroupFailure> failures;
    double seconds = 0;
};

// `progress` counts points run; `found_stored(n)` tells the caller n points of a group were
// already stored (to lower its total). `writer` names the rows' producer (the sweep column).
RunOutcome run_point_groups(const NextRunGroup& next, ResultsStore& store, const std::string& writer,
                            const EngineSettings& settings, Progress& progress,
                            const std::function<void(size_t)>& found_stored);

// A failed run's message (throws InputError if a group failed on bad input, else runtime_error).
[[noreturn]] void throw_group_failures(const RunOutcome& outcome, const std::string& file);

}  // namespace sfx
