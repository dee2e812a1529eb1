#include "sweeps/engine.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <map>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

#include "sweeps/group_runner.h"

#ifndef SFX_DASK_CLIENT
#define SFX_DASK_CLIENT "sweeps/dask_client.py"
#endif

extern char** environ;

namespace sfx {
namespace {

struct Pipe {
    int fd[2] = {-1, -1};
    Pipe() {
        // Close-on-exec: a child must not inherit another child's pipe ends, or EOF never
        // comes when several children run at once.
        if (pipe2(fd, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    }
    ~Pipe() { close_both(); }
    void close_end(int i) {
        if (fd[i] >= 0) close(fd[i]);
        fd[i] = -1;
    }
    void close_both() { close_end(0); close_end(1); }
};

// One line of engine output; anything not a JSON object (a library's banner) is ignored.
bool parse_row_line(const std::string& line, nlohmann::ordered_json& out) {
    if (line.empty() || line[0] != '{') return false;
    try {
        out = nlohmann::ordered_json::parse(line);
        return out.is_object();
    } catch (const std::exception&) {
        return false;
    }
}

std::string last_lines(const std::string& text, size_t max_chars = 2000) {
    std::string t = text;
    while (!t.empty() && (t.back() == '\n' || t.back() == '\r')) t.pop_back();
    return t.size() > max_chars ? "..." + t.substr(t.size() - max_chars) : t;
}

}  // namespace

std::string self_executable() {
    char buf[4096];
    const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
    if (n <= 0) throw std::runtime_error("cannot find this executable (/proc/self/exe)");
    return std::string(buf, size_t(n));
}

int run_process(const std::vector<std::string>& argv, const std::string& input,
                const std::function<void(const std::string&)>& on_line, std::string* err) {
    bool given = false;
    return run_process(
        argv,
        [&](std::string& chunk) {
            if (given) return false;
            given = true;
            chunk += input;
            return true;
        },
        on_line, err);
}

int run_process(const std::vector<std::string>& argv, const InputSource& input,
                const std::function<void(const std::string&)>& on_line, std::string* err) {
    Pipe in, out, errp;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, in.fd[0], 0);
    posix_spawn_file_actions_adddup2(&actions, out.fd[1], 1);
    if (err) posix_spawn_file_actions_adddup2(&actions, errp.fd[1], 2);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(rc));
    in.close_end(0);
    out.close_end(1);
    errp.close_end(1);
    if (!err) errp.close_end(0);
    fcntl(in.fd[1], F_SETFL, O_NONBLOCK);

    std::string pending;  // given by the source, not yet written
    size_t written = 0;
    auto refill = [&] {
        pending.erase(0, written);
        written = 0;
        while (pending.empty())
            if (!input(pending)) return false;
        return true;
    };
    if (!refill()) in.close_end(1);
    std::string line_buf;
    char chunk[65536];
    while (out.fd[0] >= 0 || errp.fd[0] >= 0) {
        pollfd fds[3];
        int n = 0;
        int in_i = -1, out_i = -1, err_i = -1;
        if (in.fd[1] >= 0) { in_i = n; fds[n++] = {in.fd[1], POLLOUT, 0}; }
        if (out.fd[0] >= 0) { out_i = n; fds[n++] = {out.fd[0], POLLIN, 0}; }
        if (errp.fd[0] >= 0) { err_i = n; fds[n++] = {errp.fd[0], POLLIN, 0}; }
        if (poll(fds, nfds_t(n), -1) < 0) {
            if (errno == EINTR) continue;
            break;
        }
        if (in_i >= 0 && fds[in_i].revents) {
            const ssize_t w = write(in.fd[1], pending.data() + written, pending.size() - written);
            if (w > 0) written += size_t(w);
            // EPIPE (the child exited without reading everything) ends the input too.
            if (w < 0 && errno != EAGAIN && errno != EINTR) in.close_end(1);
            else if (written == pending.size() && !refill()) in.close_end(1);
        }
        if (out_i >= 0 && fds[out_i].revents) {
            const ssize_t r = read(out.fd[0], chunk, sizeof chunk);
            if (r > 0) {
                line_buf.append(chunk, size_t(r));
                size_t nl;
                while ((nl = line_buf.find('\n')) != std::string::npos) {
                    const std::string line = line_buf.substr(0, nl);
                    line_buf.erase(0, nl + 1);
                    on_line(line);
                }
            } else if (r == 0 || (errno != EINTR && errno != EAGAIN)) {
                out.close_end(0);
            }
        }
        if (err_i >= 0 && fds[err_i].revents) {
            const ssize_t r = read(errp.fd[0], chunk, sizeof chunk);
            if (r > 0) err->append(chunk, size_t(r));
            else if (r == 0 || (errno != EINTR && errno != EAGAIN)) errp.close_end(0);
        }
    }
    if (!line_buf.empty()) on_line(line_buf);
    in.close_end(1);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return 1;
}

void run_local(const NextGroup& next, unsigned parallel, const std::string& sfx_path,
               const EngineEvents& events) {
    // A child whose reader is gone must not kill us; write errors are handled instead.
    signal(SIGPIPE, SIG_IGN);
    std::mutex mutex;  // serializes the callbacks
    const std::string parent = std::to_string(getpid());
    auto worker = [&] {
        for (;;) {
            GroupJob job;
            {
                std::lock_guard<std::mutex> lock(mutex);
                if (!next(job)) return;
                events.started(job.group);
            }
            std::string err;
            std::string bad_line;
            int code = 0;
            try {
                code = run_process(
                    {sfx_path, "run-group", "--parent-pid", parent}, job.spec + "\n",
                    [&](const std::string& line) {
                        nlohmann::ordered_json row;
                        if (!parse_row_line(line, row)) return;
                        try {
                            const PointRun run = point_run_from_json(row);
                            std::lock_guard<std::mutex> lock(mutex);
                            events.row(job.group, run);
                        } catch (const std::exception& e) {
                            // A malformed row, or the caller refusing it (a foreign key).
                            if (bad_line.empty()) bad_line = std::string(e.what()) + ": " + line.substr(0, 120);
                        }
                    },
                    &err);
            } catch (const std::exception& e) {
                code = 1;
                err = e.what();
            }
            std::lock_guard<std::mutex> lock(mutex);
            if (code == 0 && bad_line.empty()) {
                events.finished(job.group);
            } else {
                std::string msg = last_lines(err);
                if (!bad_line.empty()) msg += (msg.empty() ? "" : "\n") + ("bad row: " + bad_line.substr(0, 400));
                if (msg.empty()) msg = "sfx run-group exited with status " + std::to_string(code);
                events.failed(job.group, code ? code : 1, msg);
            }
        }
    };
    std::vector<std::thread> threads;
    for (unsigned t = 0; t < std::max(1u, parallel); ++t) threads.emplace_back(worker);
    for (std::thread& t : threads) t.join();
}

void run_dask(const NextGroup& next, const std::string& scheduler, const std::string& sfx_path,
              unsigned window, const EngineEvents& events) {
    signal(SIGPIPE, SIG_IGN);
    // Groups given to the client and not yet reported: true once reported.
    std::map<size_t, bool> done;
    // The client reads a group's line only when its window has room, so the pipe holds the
    // backlog and the specs are made as the cluster takes them.
    const InputSource input = [&](std::string& chunk) {
        GroupJob job;
        if (!next(job)) return false;
        done.emplace(job.group, false);
        chunk += "{\"group\":" + std::to_string(job.group) + ",\"spec\":" + job.spec + "}\n";
        return true;
    };
    // The client's own stderr (Dask's warnings, its fatal errors) goes to ours.
    const int code = run_process(
        {"/usr/bin/python3", SFX_DASK_CLIENT, "--scheduler", scheduler, "--sfx", sfx_path,
         "--window", std::to_string(std::max(1u, window))},
        input,
        [&](const std::string& line) {
            nlohmann::ordered_json msg;
            if (!parse_row_line(line, msg) || !msg.contains("group")) return;
            const size_t group = msg["group"].get<size_t>();
            auto it = done.find(group);
            if (it == done.end() || it->second) return;  // a late duplicate of a retried task
            if (msg.contains("error")) {
                done[group] = true;
                events.failed(group, msg.value("exit_code", 1), msg["error"].get<std::string>());
                return;
            }
            if (msg.contains("started")) {
                events.started(group);
                return;
            }
            try {
                std::vector<PointRun> rows;
                for (const auto& r : msg.at("rows")) rows.push_back(point_run_from_json(r));
                for (const PointRun& r : rows) events.row(group, r);
                done[group] = true;
                events.finished(group);
            } catch (const std::exception& e) {
                done[group] = true;
                events.failed(group, 1, std::string("bad rows from the Dask client: ") + e.what());
            }
        },
        nullptr);
    for (const auto& [group, reported] : done)
        if (!reported)
            events.failed(group, 1,
                          "not run: the Dask client exited with status " + std::to_string(code) +
                              " (its own message is above)");
}

}  // namespace sfx
