#pragma once
// How busy the other CPUs were over a measured region, from /proc/stat: on a shared machine a
// neighbour on another core (or on the same physical core, behind a virtual machine's back)
// slows a render through the caches and the core it shares, by a bias that holds for as long
// as the neighbour runs and that no repetition inside the run averages out (on this project's
// 2-CPU VM: the same workloads 25-37 % apart between runs minutes apart, each within 3 % inside
// its run). `sfx calibrate --check` records it per render, so a page can say what its fastest
// renders ran beside.

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace sfx {

struct CpuTimes {
    uint64_t busy = 0, total = 0;  // jiffies: user+nice+system+irq+softirq+steal; all of them
};

// Per CPU (cpu0, cpu1, ... in order) from /proc/stat; empty if it cannot be read.
inline std::vector<CpuTimes> read_cpu_times() {
    std::vector<CpuTimes> out;
    std::ifstream in("/proc/stat");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("cpu", 0) != 0 || line.size() < 4 || line[3] < '0' || line[3] > '9')
            continue;
        std::istringstream fields(line.substr(line.find(' ')));
        uint64_t v[8] = {};
        for (uint64_t& x : v) fields >> x;
        CpuTimes t;
        t.busy = v[0] + v[1] + v[2] + v[5] + v[6] + v[7];
        t.total = t.busy + v[3] + v[4];
        out.push_back(t);
    }
    return out;
}

}  // namespace sfx
