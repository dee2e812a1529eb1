#include "base/core_contention.h"

#include <signal.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>
#include <x86intrin.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

namespace sfx {

double independent_adds_per_tick(int runs) {
    constexpr uint64_t k_rounds = 2048;  // of six adds
    uint64_t best = ~0ull;
    for (int r = 0; r < runs; ++r) {
        uint64_t x0 = 1, x1 = 2, x2 = 3, x3 = 4, x4 = 5, x5 = 6, left = k_rounds;
        const uint64_t step = uint64_t(r) | 1;
        const uint64_t start = __rdtsc();
        // The whole loop in assembly, starting a 64-byte line: where the compiler placed it,
        // its rate followed the placement, and the contention monitor's copy (inlined into its
        // signal handler) crossed a line and ran 7/8 of the gate's, so that its probes read
        // within 2 % of the gate's threshold and found the core shared over most of a large
        // scene's renders (temple's 64-pixel tiles, AMD Zen 4 VM, 2026-12-04).
        asm volatile(
            ".p2align 6\n"
            "1:\n\t"
            "add %7, %0\n\tadd %7, %1\n\tadd %7, %2\n\tadd %7, %3\n\tadd %7, %4\n\tadd %7, %5\n\t"
            "dec %6\n\t"
            "jnz 1b"
            : "+&r"(x0), "+&r"(x1), "+&r"(x2), "+&r"(x3), "+&r"(x4), "+&r"(x5), "+&r"(left)
            : "r"(step)
            : "cc");
        best = std::min<uint64_t>(best, __rdtsc() - start);
    }
    return double(6 * k_rounds) / double(std::max<uint64_t>(best, 1));
}

CoreContention::CoreContention(double tolerance, std::function<double()> rate,
                               std::function<void(double)> sleep_ms, double total_wait_ms)
    : m_tolerance(tolerance),
      m_rate(std::move(rate)),
      m_sleep_ms(std::move(sleep_ms)),
      m_total_wait_ms(total_wait_ms) {
    if (!m_rate) m_rate = [] { return independent_adds_per_tick(); };
    if (!m_sleep_ms)
        m_sleep_ms = [](double ms) {
            std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(ms));
        };
}

double CoreContention::sample() {
    const double r = m_rate();
    m_best = std::max(m_best, r);
    return r;
}

bool CoreContention::contended() {
    if (open()) return false;
    if (!m_settled) {
        m_settled = true;
        for (int i = 0; i < k_settle; ++i) {
            sample();
            m_sleep_ms(10.0);
        }
    }
    return sample() < (1.0 - m_tolerance) * m_best;
}

bool CoreContention::wait(double budget_ms) {
    if (!contended()) return true;
    ++m_waits;
    double best_of_wait = 0.0;
    for (double waited = 0.0; waited < budget_ms; waited += 10.0) {
        if (open()) return true;
        m_sleep_ms(10.0);
        m_waited_ms += 10.0;
        const double r = sample();
        if (r >= (1.0 - m_tolerance) * m_best) return true;
        best_of_wait = std::max(best_of_wait, r);
    }
    m_best = best_of_wait;
    return false;
}

bool CoreContention::wait_warm(const std::function<void()>& warm, int most) {
    for (int attempt = 0; attempt < most; ++attempt) {
        const uint32_t waits = m_waits;
        const bool alone = wait();
        if (m_waits == waits) return alone;  // no sleep: the caches are as the render before left
        warm();
    }
    return !contended();
}

CoreContention& core_contention() {
    static CoreContention gate;
    return gate;
}

bool CoreContention::set_aside_if_contended(std::vector<std::vector<double>*> series,
                                            uint32_t& set_aside, uint32_t most) {
    if (set_aside >= most || !contended()) return false;
    ++set_aside;
    for (std::vector<double>* s : series)
        if (!s->empty()) s->pop_back();
    ++m_set_aside;
    wait();
    return true;
}

namespace {

// The running monitor's state, read by its signal handler (lock-free atomics only).
std::atomic<double> g_shared_below{0.0};
std::atomic<uint32_t> g_probes{0}, g_shared{0};
std::atomic<uint64_t> g_probe_ticks{0};
// Written by the handler on the monitored thread only, read after the timer stops.
ContentionMonitor::Probe g_marks[ContentionMonitor::k_kept_probes];

void probe_core(int) {
    const int saved_errno = errno;
    const uint64_t start = __rdtsc();
    // The better of two runs: the first fetches the loop's code and translation, which a
    // render streaming more than the L2 evicts between probes. After random reads over 64 MiB
    // the first of two back-to-back runs read 11 % or more below the second in a tenth of the
    // probes. Over temple's 64-pixel tiles (1.4 MB of rays), one run found 0.17-0.38 of the
    // probes shared and the better of two 0.07-0.19, in two of three alternated pairs of runs
    // (the third: 0.29-0.41 both; AMD Zen 4 VM, 2026-12-04).
    const double rate = independent_adds_per_tick(2);
    const uint32_t index = g_probes.fetch_add(1, std::memory_order_relaxed);
    const bool shared = rate < g_shared_below.load(std::memory_order_relaxed);
    if (shared) g_shared.fetch_add(1, std::memory_order_relaxed);
    if (index < ContentionMonitor::k_kept_probes) g_marks[index] = {start, shared};
    g_probe_ticks.fetch_add(__rdtsc() - start, std::memory_order_relaxed);
    errno = saved_errno;
}

}  // namespace

ContentionMonitor::ContentionMonitor(double shared_below, double period_us) {
    g_shared_below = shared_below;
    g_probes = 0;
    g_shared = 0;
    g_probe_ticks = 0;
    struct sigaction action;
    std::memset(&action, 0, sizeof action);
    action.sa_handler = probe_core;
    action.sa_flags = SA_RESTART;
    sigemptyset(&action.sa_mask);
    if (sigaction(SIGPROF, &action, nullptr) != 0) return;
    struct sigevent event;
    std::memset(&event, 0, sizeof event);
    event.sigev_notify = SIGEV_THREAD_ID;
    event.sigev_signo = SIGPROF;
    event._sigev_un._tid = pid_t(syscall(SYS_gettid));
    timer_t timer;
    // CLOCK_MONOTONIC: a timer on the thread's CPU time fires only at the scheduler's tick (every
    // 4 ms here, 509 probes in 2 s asked for every 500 us), too seldom for a render of 10 ms.
    if (timer_create(CLOCK_MONOTONIC, &event, &timer) != 0) return;
    m_timer = new timer_t(timer);
    const long ns = long(period_us * 1000.0);
    struct itimerspec every;
    every.it_interval.tv_sec = ns / 1000000000L;
    every.it_interval.tv_nsec = ns % 1000000000L;
    every.it_value = every.it_interval;
    m_running = timer_settime(timer, 0, &every, nullptr) == 0;
}

ContentionMonitor::Tally ContentionMonitor::stop() {
    if (m_running) {
        struct itimerspec off;
        std::memset(&off, 0, sizeof off);
        timer_settime(*static_cast<timer_t*>(m_timer), 0, &off, nullptr);
        m_running = false;
        m_tally.probes = g_probes;
        m_tally.shared = g_shared;
        m_tally.probe_ticks = double(g_probe_ticks.load());
        std::atomic_signal_fence(std::memory_order_seq_cst);
        m_tally.marks.assign(g_marks, g_marks + std::min(m_tally.probes, k_kept_probes));
    }
    return m_tally;
}

ContentionMonitor::~ContentionMonitor() {
    stop();
    if (m_timer) {
        timer_delete(*static_cast<timer_t*>(m_timer));
        delete static_cast<timer_t*>(m_timer);
    }
}

std::vector<bool> clean_spans(const std::vector<ContentionMonitor::Probe>& marks,
                              const std::vector<std::pair<uint64_t, uint64_t>>& spans,
                              uint64_t reach) {
    std::vector<bool> clean(spans.size(), false);
    auto before = [](const ContentionMonitor::Probe& m, uint64_t t) { return m.tsc < t; };
    for (size_t i = 0; i < spans.size(); ++i) {
        const auto [start, end] = spans[i];
        // The first probe at or after the span's start, and the last before it.
        auto first = std::lower_bound(marks.begin(), marks.end(), start, before);
        const bool seen_before = first != marks.begin() && start - std::prev(first)->tsc <= reach;
        if (seen_before && std::prev(first)->shared) continue;
        auto after = first;
        bool shared_inside = false;
        for (; after != marks.end() && after->tsc < end; ++after) shared_inside |= after->shared;
        const bool seen_after = after != marks.end() && after->tsc - end <= reach;
        if (shared_inside || (seen_after && after->shared)) continue;
        clean[i] = seen_before && seen_after;
    }
    return clean;
}

}  // namespace sfx
