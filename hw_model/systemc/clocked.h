#pragma once
// Core cycles and simulated time. Every process of an accelerator counts in its core clock:
// the cycle "now" is the first edge at or after the simulated time, and waiting until a cycle
// waits exactly to its edge, so time stays on the clock however many clocks share a simulation.

#include <cstdint>
#include <systemc>

namespace sfx {

class CoreClock {
  public:
    explicit CoreClock(double mhz)
        : m_period(uint64_t(
              std::llround(1e6 / mhz / sc_core::sc_get_time_resolution().to_seconds() / 1e12))) {}
    uint64_t now() const {
        const uint64_t t = sc_core::sc_time_stamp().value();
        return (t + m_period - 1) / m_period;
    }
    // Waits until cycle `cycle` (returns at once if it has begun).
    void wait_until(uint64_t cycle) const {
        const uint64_t target = cycle * m_period, t = sc_core::sc_time_stamp().value();
        if (target > t) sc_core::wait(sc_core::sc_time::from_value(target - t));
    }

  private:
    uint64_t m_period;  // in units of the time resolution
};

}  // namespace sfx
