// sfx report DB -o DIR: tables and plots from a results store; sfx report DB --paper PAGE.md: the
// comparison with the paper (docs/paper-check.md). The work is Python (analysis/sfx_analysis,
// pandas and matplotlib); this command finds it, runs it and shows its progress.

#include <poll.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/progress.h"
#include "base/input_error.h"
#include "base/user_files.h"

#ifndef SFX_ANALYSIS_DIR
#error "SFX_ANALYSIS_DIR (the analysis/ folder) is set by app/CMakeLists.txt"
#endif

namespace sfx {
namespace {

// Debian's pandas and matplotlib are visible to the system interpreter only.
constexpr const char* k_python = "/usr/bin/python3";

std::string env_or(const char* name, const std::string& fallback) {
    const char* v = std::getenv(name);
    return v && *v ? std::string(v) : fallback;
}

// Writes all of data to fd (the child's output passed through).
void write_all(int fd, const char* data, size_t size) {
    while (size > 0) {
        const ssize_t n = write(fd, data, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return;
        data += n;
        size -= size_t(n);
    }
}

// Runs argv, waits, returns its exit code (128 + signal when killed). The child reports its
// steps as "DONE TOTAL LABEL" lines on the pipe named by SFX_PROGRESS_FD (see
// analysis/sfx_analysis/progress.py), drawn here by the progress display all sfx commands
// share; its stdout and stderr come through pipes too, so the bar is cleared before its output.
int run(const std::vector<std::string>& args, Progress& progress) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    std::cout.flush();
    int steps[2], out[2], err[2];
    if (pipe(steps) != 0 || pipe(out) != 0 || pipe(err) != 0)
        throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    setenv("SFX_PROGRESS_FD", std::to_string(steps[1]).c_str(), 1);
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
    if (pid == 0) {
        dup2(out[1], 1);
        dup2(err[1], 2);
        for (int fd : {steps[0], out[0], out[1], err[0], err[1]}) close(fd);
        execv(argv[0], argv.data());
        std::cerr << "sfx report: cannot run " << args[0] << ": " << std::strerror(errno)
                  << " (install python3-pandas python3-matplotlib: ./scripts/install-deps)\n";
        _exit(127);
    }
    for (int fd : {steps[1], out[1], err[1]}) close(fd);
    // fds[1] and fds[2] are passed through to this process's fd 1 and 2.
    std::vector<pollfd> fds = {{steps[0], POLLIN, 0}, {out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
    std::string pending;  // step lines not yet complete
    char buffer[4096];
    for (size_t open = fds.size(); open > 0;) {
        if (poll(fds.data(), fds.size(), -1) < 0) {
            if (errno == EINTR) continue;
            throw std::runtime_error(std::string("poll: ") + std::strerror(errno));
        }
        for (size_t i = 0; i < fds.size(); ++i) {
            if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
            const ssize_t n = read(fds[i].fd, buffer, sizeof buffer);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                close(fds[i].fd);
                fds[i].fd = -1;
                --open;
                continue;
            }
            if (i > 0) {
                progress.clear();
                write_all(int(i), buffer, size_t(n));
                continue;
            }
            pending.append(buffer, size_t(n));
            for (size_t end; (end = pending.find('\n')) != std::string::npos;
                 pending.erase(0, end + 1)) {
                std::istringstream line(pending.substr(0, end));
                uint64_t done = 0, total = 0;
                std::string label;
                if (!(line >> done >> total)) continue;
                std::getline(line >> std::ws, label);
                progress.set_total(total);
                progress.set_done(done);
                progress.set_label(label);  // draws at once on a terminal
            }
        }
    }
    progress.finish();
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            throw std::runtime_error(std::string("waitpid: ") + std::strerror(errno));
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

}  // namespace

void add_report_command(CLI::App& app) {
    struct Options {
        std::string db;
        std::string output = "report";
        bool quiet = false;
        std::string paper;        // --paper PAGE.md: the paper check instead of the report
        std::string trace_stats;  // sfx trace-stats conference --json, for the trace target
        std::string silicon;      // sfx calibrate --check --json, for the silicon-check section
    };
    auto options = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand("report", "tables and plots from a results store (HTML)");
    c->add_option("db", options->db, "results store written by sfx sweep")->required();
    c->add_option("-o,--output", options->output, "report directory (default: report)");
    c->add_flag("--quiet", options->quiet, "print only where the files are");
    c->add_option("--paper", options->paper,
                  "write the comparison with the paper's tables (Markdown) to this file instead "
                  "of the report (docs/paper-check.md; see scripts/paper-check)");
    c->add_option("--silicon", options->silicon,
                  "`sfx calibrate --check --json` output (scripts/silicon-check writes "
                  "out/silicon-check/rows-WIDEST.json): adds the timing model on silicon to the "
                  "report")
        ->check(CLI::ExistingFile);
    c->add_option("--trace-stats", options->trace_stats,
                  "with --paper: `sfx trace-stats conference --json` output, for the trace-side "
                  "target")
        ->check(CLI::ExistingFile);
    CLI::Option* output = c->get_option("-o");
    c->callback([options, output] {
        struct stat st;
        if (stat(options->db.c_str(), &st) != 0)
            throw InputError(options->db, 0, "db", "no such results store");
        check_regular_file(options->db, "results store");  // a directory, a FIFO: named as such
        // SFX_ANALYSIS_DIR in the environment overrides the baked-in path (an installed sfx).
        const std::string analysis = env_or("SFX_ANALYSIS_DIR", SFX_ANALYSIS_DIR);
        const std::string old_path = env_or("PYTHONPATH", "");
        const std::string path = analysis + (old_path.empty() ? "" : ":" + old_path);
        setenv("PYTHONPATH", path.c_str(), 1);
        if (!options->silicon.empty() && !options->paper.empty())
            throw InputError("command line", 0, "--silicon",
                             "adds a section to the report, not to the --paper page");
        if (!options->trace_stats.empty() && options->paper.empty())
            throw InputError("command line", 0, "--trace-stats", "only used with --paper");
        if (!options->paper.empty() && output->count() > 0)
            throw InputError("command line", 0, "-o",
                             "--paper writes its page instead of the report directory; run "
                             "sfx report twice for both");
        std::vector<std::string> args = {k_python, "-m", "sfx_analysis"};
        if (options->paper.empty()) {
            args.insert(args.end(), {"report", options->db, "-o", options->output});
            if (!options->silicon.empty()) args.insert(args.end(), {"--silicon", options->silicon});
        } else {
            args.insert(args.end(), {"paper", options->db, "-o", options->paper});
            if (!options->trace_stats.empty())
                args.insert(args.end(), {"--trace-stats", options->trace_stats});
        }
        if (options->quiet) args.push_back("--quiet");
        Progress progress("report", 0, "steps");
        const int code = run(args, progress);
        // The exit code passes through: 2 for a store that cannot be reported on.
        if (code != 0) std::exit(code);
    });
}

}  // namespace sfx
