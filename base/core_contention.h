#pragma once
// Whether another hardware thread shares this core now. On a cloud virtual machine a core's
// sibling thread may run another tenant's load, in spells: on this project's AMD Zen 5 VM
// (2026-12-02, 20 s sampled every 0.2 s) the box test's lane group took 29 cycles alone and
// 41-47 in spells of 0.4-2 s, about a third of the time, while the core's clock (a chain of
// dependent adds, base/core_clock.h, which a sibling does not slow) read the same. A
// microbenchmark point or a render that falls wholly in a spell converges there (its fastest
// samples agree) and reads 1.5 times the core's cost: the box test's fitted group cost came
// out 29 and 44 cycles in calibrations an hour apart, with the same speed probe. A sibling
// takes the core's ALUs: six chains of independent adds ran 6.2 adds a TSC tick alone and 4-5
// in those spells. So a measurement that must be the core's own waits for the core (wait) and
// sets aside a sample after which it finds it shared (contended).

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

namespace sfx {

// Independent adds (six chains of register adds, 12 288 in all, about 3 us) a TSC tick now:
// the fastest of `runs` timings.
double independent_adds_per_tick(int runs = 3);

class CoreContention {
  public:
    // `rate`: the core's rate now (independent_adds_per_tick by default); `sleep_ms`: how
    // waiting passes (the thread sleeps by default). A rate more than `tolerance` below the
    // best seen is a shared core's: 0.15 lies between the unshared rate's spread (1924-1976
    // TSC ticks for the probe on the AMD VM, 2026-12-02) and a spell's drop (2500-3000), and
    // a wait of 2 s outlasts the longest spell seen there. At most `total_wait_ms` is spent waiting
    // over the gate's life: on a core shared most of the time, after that the gate is open
    // (contended() is false) and measurements take what they get, as they did without it (on the
    // AMD VM a scalar calibration that set aside 2250 samples took 334 s against 18 s, an AVX2 one
    // 545 s). `sfx calibrate --contention-wait` sets it; the test runner allows 30 s
    // (tests/test_main.cpp).
    explicit CoreContention(double tolerance = 0.15, std::function<double()> rate = {},
                            std::function<void(double)> sleep_ms = {},
                            double total_wait_ms = 600000.0);
    void set_total_wait_ms(double ms) { m_total_wait_ms = ms; }

    // The core is shared now. The first call samples the rate every 10 ms over `k_settle`
    // samples first, so that the best seen is an unshared core's unless a spell outlasts
    // them. False once the total wait is spent.
    bool contended();
    // Waits in steps of 10 ms until the core is not shared, at most `budget_ms`; returns true
    // if it is not. A spell that outlasts the budget is the core's state now: the best seen
    // falls to the best rate of the wait, so that a lasting state is measured, not waited on.
    bool wait(double budget_ms = 2000.0);
    // wait(), and where it slept, `warm` (what the sleep let others evict: on a VM whose L3 is
    // shared, 10 ms asleep cost temple's 64 x 64 frame most of what the render before it left
    // in the caches, 30 ms all of it) and the same again, at most `most` times; after the
    // last, the core is checked without sleeping. Returns whether the core is not shared.
    bool wait_warm(const std::function<void()>& warm, int most = 3);

    // After a timed sample: if the core is shared now and fewer than `most` samples of this
    // measurement were set aside (`set_aside`, which it counts), the last sample of each series
    // timed together is set aside and the core waited for; returns whether they were. The
    // caller takes another in its place (the wait ends a spell or takes a lasting one as the
    // core's state, so few follow one another).
    bool set_aside_if_contended(std::vector<std::vector<double>*> series, uint32_t& set_aside,
                                uint32_t most);

    double best() const { return m_best; }
    // The rate below which a probe finds the core shared (0 once the gate is open: nothing is).
    double shared_below() const { return open() ? 0.0 : (1.0 - m_tolerance) * m_best; }
    uint32_t waits() const { return m_waits; }          // wait() calls that found it shared
    uint32_t set_aside() const { return m_set_aside; }  // samples set aside
    bool open() const { return m_waited_ms >= m_total_wait_ms; }  // the total wait is spent

    static constexpr int k_settle = 30;

  private:
    double sample();

    double m_tolerance;
    std::function<double()> m_rate;
    std::function<void(double)> m_sleep_ms;
    double m_total_wait_ms, m_waited_ms = 0.0;
    double m_best = 0.0;
    bool m_settled = false;
    uint32_t m_waits = 0, m_set_aside = 0;
};

// The process's one gate (microbenchmarks and renders of sfx calibrate share its best rate).
CoreContention& core_contention();

// Probes the core while a measured region runs, not only after it. On this project's AMD Zen 4
// VM (2026-12-03) the sibling's load came in bursts of 1-10 ms besides the spells, several in
// 100 ms at times (independent_adds_per_tick sampled back to back for 3 s): a render of 10-50 ms
// overlapped them often and the one probe after it seldom saw one, so a large scene's renders
// lay 0-60 % above their fastest and 8-13 of its 18 workloads a back end did not converge. A
// timer on the monotonic clock interrupts the thread every `period_us` (the signal goes to the
// thread), and the handler times the independent adds twice and keeps the better (the first
// run fetches the loop a large render evicted; about 2 us, 0.2 % of a period of 1 ms,
// subtracted where it runs in a measured region); a probe below `shared_below` adds a tick
// found the core shared. One monitor runs at a time (the handler's tallies are the process's).
// Where the timer cannot be made (timer_create fails), the monitor probes nothing (probes 0).
class ContentionMonitor {
  public:
    // A probe: the TSC when it started and whether it found the core shared.
    struct Probe {
        uint64_t tsc = 0;
        bool shared = false;
    };
    struct Tally {
        uint32_t probes = 0;       // handler runs over the region
        uint32_t shared = 0;       // of which found the core shared
        double probe_ticks = 0.0;  // TSC ticks the handler spent: the monitor's own cost
        // Each probe in order (the first k_kept_probes): where in a region the core was shared,
        // so that a part of it between probes that found the core alone can be kept
        // (clean_spans).
        std::vector<Probe> marks;
    };
    static constexpr uint32_t k_kept_probes = 1u << 16;
    ContentionMonitor(double shared_below, double period_us = 1000.0);
    ~ContentionMonitor();
    ContentionMonitor(const ContentionMonitor&) = delete;
    ContentionMonitor& operator=(const ContentionMonitor&) = delete;
    Tally stop();  // stops the timer (idempotent) and returns the tally

  private:
    void* m_timer = nullptr;  // timer_t
    bool m_running = false;
    Tally m_tally;
};

// Whether each span [start, end) of TSC ticks ran on a core alone by the probes around it
// (`marks`, in TSC order): the nearest probe at or before it and the nearest after it, each
// within `reach` ticks of the span, found the core alone, as did any probe inside it. A burst
// of the sibling shorter than the probes' period can fall between two of them unseen, as it can
// between a whole region's probes.
std::vector<bool> clean_spans(const std::vector<ContentionMonitor::Probe>& marks,
                              const std::vector<std::pair<uint64_t, uint64_t>>& spans,
                              uint64_t reach);

}  // namespace sfx
