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

// The groups to run, made as the engine asks for them (a large sweep's specs never all exist at
// once): fills `job` and returns true, or returns false when there are no more. Called one at a
// time, never concurrently with the events.
using NextGroup = std::function<bool(GroupJob& job)>;

void run_local(const NextGroup& next, unsigned parallel, const std::string& sfx_path,
               const EngineEvents& events);

// The client holds at most `window` groups submitted and not finished. Throws
// std::runtime_error if the client cannot start or reach the scheduler.
void run_dask(const NextGroup& next, const std::string& scheduler, const std::string& sfx_path,
              unsigned window, const EngineEvents& events);

// More input for a process: appends to `chunk` and returns true, or returns false at the end.
using InputSource = std::function<bool(std::string& chunk)>;

// Runs argv with its stdin fed from `input` (written concurrently with reading, so neither side
// blocks the other; a source is asked for more only when the pipe has taken what it gave),
// calls on_line for every stdout line as it arrives, and returns the exit status (128 + signal
// if killed). stderr is collected into *err, or inherited if err is null.
int run_process(const std::vector<std::string>& argv, const InputSource& input,
                const std::function<void(const std::string&)>& on_line, std::string* err);
int run_process(const std::vector<std::string>& argv, const std::string& input,
                const std::function<void(const std::string&)>& on_line, std::string* err);

// This executable's absolute path (/proc/self/exe).
std::string self_executable();

}  // namespace sfx
