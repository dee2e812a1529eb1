#pragma once
// Where a measured region's core cycles come from, in one place: counted by the core where the
// host allows it (perf_event_open, the user-mode cycles of the calling thread), else estimated
// (the thread's CPU time at the core's clock, the clock measured under the back end being
// timed, base/core_clock.h, both just before and just after the region, and their mean taken).
// A virtual machine often exposes no PMU (perf_event_open for hardware cycles fails with
// ENOENT, EOPNOTSUPP or EACCES, or opens and counts nothing): then the estimate is used, and
// description() says so and why. The opener is injectable, so the fallback can be tested on a
// host whose counters work.

#include <cstdint>
#include <functional>
#include <string>

struct perf_event_attr;

namespace sfx {

// perf_event_open(attr, pid, cpu, group, flags) for the calling thread on any CPU: a file
// descriptor, or -1 with errno set.
using PerfEventOpener = std::function<int(perf_event_attr&)>;
int open_perf_event(perf_event_attr& attr);

struct CycleReading {
    double cycles = 0.0;       // core cycles of the region
    double cpu_seconds = 0.0;  // the thread's CPU time over it
    // The estimate's clock before and after (MHz); with the counter, the counted cycles over
    // the CPU time for both.
    double clock_mhz_before = 0.0, clock_mhz_after = 0.0;
};

// How far the estimate's clock moved over the region: |after - before| over the lower of the
// two (0 when counted, or with no clock). The estimate takes their mean, but the clock may have
// changed anywhere in the region (a frequency step: 3584 to 4081 MHz around a render on this
// project's Intel VM), so its cycles lie anywhere between the two clocks' and the reading is
// only as good as this.
double clock_moved(const CycleReading& r);

class CycleSource {
  public:
    // `lanes`: the back end timed (1 scalar, 8 AVX2, 16 AVX-512): its chain measures the clock
    // of the estimate. `tsc_mhz`: the TSC's rate (hw_model/host_description.h measures it).
    CycleSource(uint32_t lanes, double tsc_mhz, const PerfEventOpener& open = open_perf_event);
    ~CycleSource();
    CycleSource(const CycleSource&) = delete;
    CycleSource& operator=(const CycleSource&) = delete;

    bool counted() const { return m_fd >= 0; }
    // "counted: perf_event_open, user-mode core cycles of the measured thread" or
    // "estimated: thread CPU time x the core clock (a chain of dependent vpaddd ymm, ...)
    // measured before and after each render, the mean taken (perf_event_open refused: ...)".
    const std::string& description() const { return m_description; }
    const std::string& refusal() const { return m_refusal; }  // empty when counted

    void start();
    CycleReading stop();

  private:
    double clock_mhz() const;
    uint32_t m_lanes;
    double m_tsc_mhz;
    int m_fd = -1;
    std::string m_description, m_refusal;
    double m_clock_before = 0.0;
    double m_cpu_start = 0.0;
};

}  // namespace sfx
