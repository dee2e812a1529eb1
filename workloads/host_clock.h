#pragma once
// Host wall-clock time for progress lines and the host_seconds of results: one monotonic clock
// (steady, so a clock adjustment never makes a duration negative) and one way to read it.

#include <chrono>

namespace sfx {

using HostClock = std::chrono::steady_clock;

// Seconds elapsed since `start`, a HostClock::now() taken earlier.
inline double seconds_since(HostClock::time_point start) {
    return std::chrono::duration<double>(HostClock::now() - start).count();
}

}  // namespace sfx
