#include "base/cycle_source.h"

#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "base/core_clock.h"

namespace sfx {

namespace {

double thread_cpu_seconds() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The error's symbolic name (glibc's strerrorname_np), or "errno" for a code it does not name.
const char* errno_name(int e) {
    const char* name = strerrorname_np(e);
    return name ? name : "errno";
}

// The counter's value, scaled up if the kernel multiplexed it; false if unreadable.
bool read_counter(int fd, double& value) {
    uint64_t v[3] = {0, 0, 0};  // value, time enabled, time running
    if (::read(fd, v, sizeof v) != ssize_t(sizeof v)) return false;
    value = v[2] > 0 && v[2] < v[1] ? double(v[0]) * double(v[1]) / double(v[2]) : double(v[0]);
    return true;
}

}  // namespace

int open_perf_event(perf_event_attr& attr) {
    return int(syscall(SYS_perf_event_open, &attr, 0, -1, -1, 0));
}

CycleSource::CycleSource(uint32_t lanes, double tsc_mhz, const PerfEventOpener& open)
    : m_lanes(lanes), m_tsc_mhz(tsc_mhz) {
    perf_event_attr attr;
    std::memset(&attr, 0, sizeof attr);
    attr.size = sizeof attr;
    attr.type = PERF_TYPE_HARDWARE;
    attr.config = PERF_COUNT_HW_CPU_CYCLES;
    attr.disabled = 1;
    attr.exclude_kernel = 1;
    attr.exclude_hv = 1;
    attr.read_format = PERF_FORMAT_TOTAL_TIME_ENABLED | PERF_FORMAT_TOTAL_TIME_RUNNING;
    errno = 0;
    const int fd = open ? open(attr) : -1;
    if (fd < 0) {
        const int e = errno;
        m_refusal = std::string("perf_event_open refused: ") + errno_name(e) +
                    (e ? std::string(" (") + std::strerror(e) + ")" : std::string());
    } else {
        // Some hypervisors accept the event and never count it: a probe of a few thousand
        // adds must count something.
        ioctl(fd, PERF_EVENT_IOC_RESET, 0);
        ioctl(fd, PERF_EVENT_IOC_ENABLE, 0);
        tsc_ticks_per_core_cycle(2, 1);
        ioctl(fd, PERF_EVENT_IOC_DISABLE, 0);
        double probe = 0.0;
        if (!read_counter(fd, probe) || probe <= 0.0) {
            m_refusal = "perf_event_open opened, but the counter counted nothing";
            ::close(fd);
        } else {
            m_fd = fd;
        }
    }
    if (m_fd >= 0)
        m_description = "counted: perf_event_open, user-mode core cycles of the measured thread";
    else
        m_description = std::string(
                            "estimated: thread CPU time x the core clock (a chain of "
                            "dependent ") +
                        clock_chain_name(lanes) +
                        ", one a cycle, against the TSC) measured before and after each render, "
                        "the mean taken (" +
                        m_refusal + ")";
}

CycleSource::~CycleSource() {
    if (m_fd >= 0) ::close(m_fd);
}

double clock_moved(const CycleReading& r) {
    const double low = std::min(r.clock_mhz_before, r.clock_mhz_after);
    return low > 0 ? std::abs(r.clock_mhz_after - r.clock_mhz_before) / low : 0.0;
}

double CycleSource::clock_mhz() const {
    return m_tsc_mhz / tsc_ticks_per_core_cycle(3, m_lanes);
}

void CycleSource::start() {
    if (m_fd >= 0) {
        ioctl(m_fd, PERF_EVENT_IOC_RESET, 0);
        m_cpu_start = thread_cpu_seconds();
        ioctl(m_fd, PERF_EVENT_IOC_ENABLE, 0);
        return;
    }
    m_clock_before = clock_mhz();
    m_cpu_start = thread_cpu_seconds();
}

CycleReading CycleSource::stop() {
    CycleReading r;
    if (m_fd >= 0) {
        ioctl(m_fd, PERF_EVENT_IOC_DISABLE, 0);
        r.cpu_seconds = thread_cpu_seconds() - m_cpu_start;
        read_counter(m_fd, r.cycles);
        r.clock_mhz_before = r.clock_mhz_after =
            r.cpu_seconds > 0 ? r.cycles / r.cpu_seconds * 1e-6 : 0.0;
        return r;
    }
    r.cpu_seconds = thread_cpu_seconds() - m_cpu_start;
    r.clock_mhz_before = m_clock_before;
    r.clock_mhz_after = clock_mhz();
    r.cycles = r.cpu_seconds * 0.5 * (r.clock_mhz_before + r.clock_mhz_after) * 1e6;
    return r;
}

}  // namespace sfx
