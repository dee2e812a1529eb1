#pragma once
// Core cycles and simulated time. Every process of an accelerator counts in its core clock:
// the cycle "now" is the first edge at or after the simulated time, and waiting until a cycle
// waits exactly to its edge, so time stays on the clock however many clocks share a simulation.

#include <cmath>
#include <cstdint>
#include <memory>
#include <systemc>
#include <vector>

namespace sfx {

// The wake-ups of one accelerator's processes: one event per time any of them waits for. Its
// processes due at the same time then resume in an order of the accelerator's own making (the
// order in which they began to wait), never in the order SystemC's timed-event queue breaks
// ties in, which depends on every other configuration simulated beside it: a configuration's
// prediction must not depend on its point group.
class CycleWakeups {
  public:
    // The event notified at time `target` (in units of the time resolution; now < target).
    sc_core::sc_event& at(uint64_t target, uint64_t now) {
        // At most one pending time per process of the accelerator: a short list, searched
        // linearly (a std::map's node per wait showed in profiles).
        Pending* slot = nullptr;
        for (Pending& p : m_pending) {
            if (p.target == target) return *p.event;
            if (p.target <= now && !slot) slot = &p;  // fired: free again
        }
        if (!slot) {
            m_pending.push_back({0, std::make_unique<sc_core::sc_event>()});
            slot = &m_pending.back();
        }
        slot->target = target;
        slot->event->notify(sc_core::sc_time::from_value(target - now));
        return *slot->event;
    }

  private:
    struct Pending {
        uint64_t target;  // when its event fires (a time past: it has fired)
        std::unique_ptr<sc_core::sc_event> event;
    };
    std::vector<Pending> m_pending;
};

// One cycle of a clock of `mhz`, in units of the time resolution.
inline uint64_t clock_period(double mhz) {
    return uint64_t(
        std::llround(1e6 / mhz / sc_core::sc_get_time_resolution().to_seconds() / 1e12));
}

class CoreClock {
  public:
    CoreClock(double mhz, std::shared_ptr<CycleWakeups> wakeups)
        : m_period(clock_period(mhz)), m_wakeups(std::move(wakeups)) {}
    uint64_t now() const {
        const uint64_t t = sc_core::sc_time_stamp().value();
        return (t + m_period - 1) / m_period;
    }
    // Waits until cycle `cycle` (returns at once if it has begun).
    void wait_until(uint64_t cycle) const {
        const uint64_t target = cycle * m_period, t = sc_core::sc_time_stamp().value();
        if (target > t) sc_core::wait(m_wakeups->at(target, t));
    }

  private:
    uint64_t m_period;  // in units of the time resolution
    std::shared_ptr<CycleWakeups> m_wakeups;  // the accelerator's
};

}  // namespace sfx
