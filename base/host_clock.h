#pragma once
// Host wall-clock time for progress lines and the host_seconds of results: one monotonic clock
// (steady, so a clock adjustment never makes a duration negative) and one way to read it.

#include <chrono>

namespace sfx {

using HostClock = std::chrono::steady_clock;

// Seconds from `start` to `end`, two HostClock::now() readings.
inline double seconds_between(HostClock::time_point start, HostClock::time_point end) {
    return std::chrono::duration<double>(end - start).count();
}

// Seconds elapsed since `start`, a HostClock::now() taken earlier.
inline double seconds_since(HostClock::time_point start) {
    return seconds_between(start, HostClock::now());
}

}  // namespace sfx
