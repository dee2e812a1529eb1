#pragma once
// Execution engines: they run point groups (as `sfx run-group` processes) and report rows as
// they arrive. The caller (app/cmd_sweep.cpp) owns the store; engines never touch it.
//
// local: up to `parallel` child processes of this sfx at once, each timing one group. Child
//   processes, not threads, because SystemC allows one simulation context per process (a
//   `full` group must own it), and a child that dies takes no other group with it.
// dask:  one Python client (sweeps/dask_client.py) that submits each group as a Dask task;
//   each task runs `sfx run-group` on a worker and returns the rows. Dask re-runs the tasks
//   of a lost worker; the store's key makes a repeated row a no-op.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "sweeps/results_store.h"

namespace sfx {

struct GroupJob {
    size_t group = 0;  // index into Sweep::groups
    std::string spec;  // group_spec_json(...).dump(): one line
};

// Engine callbacks. They are called one at a time (never concurrently), from engine threads.
struct EngineEvents {
    std::function<void(size_t group)> started;
    std::function<void(size_t group, const PointRun& row)> row;
    std::function<void(size_t group)> finished;
    // exit_code 2: bad input (e.g. an unsupported fidelity); anything else: a failure.
    std::function<void(size_t group, int exit_code, const std::string& message)> failed;
};

void run_local(const std::vector<GroupJob>& jobs, unsigned parallel, const std::string& sfx_path,
               const EngineEvents& events);

// Throws std::runtime_error if the client cannot start or reach the scheduler.
void run_dask(const std::vector<GroupJob>& jobs, const std::string& scheduler,
              const std::string& sfx_path, const EngineEvents& events);

// Runs argv with `input` on its stdin (written concurrently with reading, so neither side
// blocks the other), calls on_line for every stdout line as it arrives, and returns the exit
// status (128 + signal if killed). stderr is collected into *err, or inherited if err is null.
int run_process(const std::vector<std::string>& argv, const std::string& input,
                const std::function<void(const std::string&)>& on_line, std::string* err);

// This executable's absolute path (/proc/self/exe).
std::string self_executable();

}  // namespace sfx
