#include "hw_model/host_description.h"

#include <cpuid.h>
#include <sched.h>
#include <sys/mman.h>
#include <x86intrin.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numeric>
#include <random>
#include <sstream>
#include <thread>

#include "base/cache_eviction.h"
#include "base/convergence.h"
#include "base/core_clock.h"
#include "base/host_clock.h"
#include "base/huge_pages.h"
#include "base/strict_number.h"
#include "hw_model/cache_model.h"

namespace sfx {

namespace {

bool read_text(const std::string& path, std::string& out) {
    std::ifstream in(path);
    if (!in) return false;
    std::getline(in, out);
    return true;
}

// "48K", "1024K", "32M" -> KiB.
uint32_t parse_kib(const std::string& s) {
    uint64_t v = 0;
    size_t i = 0;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') v = v * 10 + uint64_t(s[i++] - '0');
    if (i < s.size() && s[i] == 'M') v *= 1024;
    return uint32_t(v);
}

std::vector<HostCacheLevel> caches_from_sysfs() {
    std::vector<HostCacheLevel> out;
    const std::string root = "/sys/devices/system/cpu/cpu0/cache/index";
    for (int i = 0; i < 16; ++i) {
        const std::string dir = root + std::to_string(i) + "/";
        std::string level, type, size, line, ways, shared;
        if (!read_text(dir + "level", level) || !read_text(dir + "type", type)) break;
        if (type == "Instruction") continue;
        read_text(dir + "size", size);
        read_text(dir + "coherency_line_size", line);
        read_text(dir + "ways_of_associativity", ways);
        read_text(dir + "shared_cpu_list", shared);
        HostCacheLevel c;
        c.level = uint32_t(std::stoul(level));
        c.type = type == "Data" ? "data" : "unified";
        c.kib = parse_kib(size);
        c.line_bytes = uint32_t(std::stoul(line.empty() ? "64" : line));
        c.ways = uint32_t(std::stoul(ways.empty() ? "1" : ways));
        c.shared = shared.find_first_of(",-") != std::string::npos;
        c.source = "sysfs " + dir;
        out.push_back(c);
    }
    return out;
}

// cpuid deterministic cache parameters: leaf 4 (Intel) or 0x8000001D (AMD), same layout.
std::vector<HostCacheLevel> caches_from_cpuid() {
    std::vector<HostCacheLevel> out;
    unsigned a, b, c, d;
    __cpuid(0, a, b, c, d);
    const bool amd = b == 0x68747541;  // "Auth"enticAMD
    const unsigned leaf = amd ? 0x8000001D : 4;
    if (amd) {
        __cpuid(0x80000000, a, b, c, d);
        if (a < leaf) return out;
    } else if (a < leaf) {
        return out;
    }
    for (unsigned sub = 0; sub < 16; ++sub) {
        __cpuid_count(leaf, sub, a, b, c, d);
        const unsigned type = a & 0x1f;
        if (type == 0) break;
        if (type == 2) continue;  // instruction cache
        HostCacheLevel l;
        l.level = (a >> 5) & 7;
        l.type = type == 1 ? "data" : "unified";
        l.line_bytes = (b & 0xfff) + 1;
        const uint32_t partitions = ((b >> 12) & 0x3ff) + 1;
        l.ways = (b >> 22) + 1;
        const uint64_t sets = uint64_t(c) + 1;
        l.kib = uint32_t(uint64_t(l.ways) * partitions * l.line_bytes * sets / 1024);
        l.shared = ((a >> 14) & 0xfff) > 0;
        char buf[64];
        std::snprintf(buf, sizeof buf, "cpuid leaf 0x%X subleaf %u", leaf, sub);
        l.source = buf;
        out.push_back(l);
    }
    return out;
}

// AMD's legacy cache leaves (0x80000005 L1D, 0x80000006 L2 and L3), for when 0x8000001D is
// masked (some hypervisors). The L2/L3 associativity is a code (AMD APM vol. 3, CPUID
// Fn8000_0006); code 9 means "see 0x8000001D", which then is masked: 16 ways assumed.
std::vector<HostCacheLevel> caches_from_amd_legacy() {
    std::vector<HostCacheLevel> out;
    unsigned a, b, c, d;
    __cpuid(0x80000000, a, b, c, d);
    if (a < 0x80000006) return out;
    auto ways_of = [](unsigned code, std::string& source) -> uint32_t {
        static const uint32_t k_ways[16] = {0, 1, 2, 3, 4, 6, 8, 0, 16, 0, 32, 48, 64, 96, 128, 0};
        if (k_ways[code & 15]) return k_ways[code & 15];
        source += " (ways not given: 16 assumed)";
        return 16;
    };
    __cpuid(0x80000005, a, b, c, d);
    HostCacheLevel l1{
        1, "data", c >> 24, c & 0xff, (c >> 16) & 0xff, false, "cpuid leaf 0x80000005 ECX"};
    if (l1.kib) out.push_back(l1);
    __cpuid(0x80000006, a, b, c, d);
    HostCacheLevel l2{2, "unified", c >> 16, c & 0xff, 0, false, "cpuid leaf 0x80000006 ECX"};
    l2.ways = ways_of((c >> 12) & 15, l2.source);
    if (l2.kib) out.push_back(l2);
    HostCacheLevel l3{
        3, "unified", (d >> 18) * 512, d & 0xff, 0, true, "cpuid leaf 0x80000006 EDX"};
    l3.ways = ways_of((d >> 12) & 15, l3.source);
    if (l3.kib) out.push_back(l3);
    return out;
}

std::string fmt(double v, int digits = 1) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

}  // namespace

std::vector<HostCacheLevel> read_host_caches() {
    std::vector<HostCacheLevel> c = caches_from_sysfs();
    if (c.empty()) c = caches_from_cpuid();
    unsigned a, b, cx, d;
    __cpuid(0, a, b, cx, d);
    if (c.empty() && b == 0x68747541) c = caches_from_amd_legacy();
    std::stable_sort(c.begin(), c.end(), [](const HostCacheLevel& x, const HostCacheLevel& y) {
        return x.level < y.level;
    });
    return c;
}

CpuSignature decode_cpu_signature(uint32_t eax) {
    CpuSignature s;
    const uint32_t base_family = (eax >> 8) & 0xf, base_model = (eax >> 4) & 0xf;
    s.stepping = eax & 0xf;
    s.family = base_family == 0xf ? base_family + ((eax >> 20) & 0xff) : base_family;
    s.model = base_family == 0x6 || base_family == 0xf ? base_model | (((eax >> 16) & 0xf) << 4)
                                                       : base_model;
    return s;
}

Microarchitecture read_microarchitecture() {
    Microarchitecture m;
    unsigned a, b, c, d;
    __cpuid(0, a, b, c, d);
    char vendor[13] = {};
    std::memcpy(vendor, &b, 4);
    std::memcpy(vendor + 4, &d, 4);
    std::memcpy(vendor + 8, &c, 4);
    m.vendor = vendor;
    __cpuid(1, a, b, c, d);
    m.signature = decode_cpu_signature(a);
    __cpuid(0x80000000, a, b, c, d);
    if (a >= 0x80000004) {
        char brand[49] = {};
        for (unsigned leaf = 0; leaf < 3; ++leaf) {
            unsigned r[4];
            __cpuid(0x80000002 + leaf, r[0], r[1], r[2], r[3]);
            std::memcpy(brand + 16 * leaf, r, 16);
        }
        m.brand = brand;
        while (!m.brand.empty() && m.brand.back() == ' ') m.brand.pop_back();
        while (!m.brand.empty() && m.brand.front() == ' ') m.brand.erase(m.brand.begin());
    }
    return m;
}

std::string vendor_short_name(const std::string& vendor) {
    if (vendor == "AuthenticAMD") return "amd";
    if (vendor == "GenuineIntel") return "intel";
    std::string out;
    for (char ch : vendor)
        if (std::isalnum(static_cast<unsigned char>(ch)))
            out += char(std::tolower(static_cast<unsigned char>(ch)));
    return out.empty() ? "unknown" : out;
}

std::string describe(const Microarchitecture& m) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s family 0x%X model 0x%X stepping %u", m.vendor.c_str(),
                  m.signature.family, m.signature.model, m.signature.stepping);
    return std::string(buf) + (m.brand.empty() ? "" : " (" + m.brand + ")");
}

uint64_t read_tsc() {
    return __rdtsc();
}

double measure_tsc_mhz(double seconds) {
    const auto t0 = HostClock::now();
    const uint64_t c0 = __rdtsc();
    auto t1 = t0;
    while (seconds_between(t0, t1 = HostClock::now()) < seconds) {
    }
    const uint64_t c1 = __rdtsc();
    return double(c1 - c0) / (seconds_between(t0, t1) * 1e6);
}

namespace {

// `spin` dependent multiplies by one: a wait the compiler cannot fold, a few cycles each.
inline size_t spin_on(size_t x, uint32_t spin) {
    for (uint32_t i = 0; i < spin; ++i) asm volatile("imul $1, %0, %0" : "+r"(x));
    return x;
}

using Chase = std::vector<size_t, HugePageAllocator<size_t>>;

constexpr size_t k_chase_stride = 64 / sizeof(size_t);  // words a line

// Links `count` lines of `chase`, line `first` and every `step`-th after it, into a cycle in
// random order from line `first`: each one's first word holds the index of the next one's.
void link_cycle(Chase& chase, size_t count, size_t first, size_t step, uint64_t seed) {
    std::vector<size_t> order(count);
    for (size_t i = 0; i < count; ++i) order[i] = (first + i * step) * k_chase_stride;
    std::shuffle(order.begin() + 1, order.end(), std::mt19937_64(seed));
    for (size_t i = 0; i < count; ++i) chase[order[i]] = order[(i + 1) % count];
}

// A cycle through the lines of `bytes` (at least 8) in random order: each line's first word
// holds the index of the next line's. Allocated as the BVH is (base/huge_pages.h): huge pages
// where the chase is 2 MiB or more, so the latency includes the page walks the traversal's
// scene reads have, and no others.
Chase random_chase(uint64_t bytes) {
    const size_t lines = std::max<uint64_t>(bytes / 64, 8);
    Chase chase(lines * k_chase_stride);
    link_cycle(chase, lines, 0, 1, 12345);
    return chase;
}

// Nanoseconds a load over `loads` loads along `chase` from the word `at` (left where they end).
double chase_pass_ns(const Chase& chase, size_t& at, size_t loads, double tsc_mhz) {
    const uint64_t c0 = __rdtsc();
    for (size_t i = 0; i < loads; ++i) at = chase[at];
    const uint64_t c1 = __rdtsc();
    if (at == size_t(-1)) std::printf(" ");  // keeps the chase
    return double(c1 - c0) / double(loads) / tsc_mhz * 1000.0;
}

}  // namespace

double measure_load_latency_ns(uint64_t bytes, double tsc_mhz, uint32_t spin, double* step_ns) {
    const Chase chase = random_chase(bytes);
    const size_t lines = chase.size() / k_chase_stride;
    size_t at = 0;
    for (size_t i = 0; i < std::min<size_t>(lines, 1u << 20); ++i)  // warm
        at = spin_on(chase[at], spin);
    // Many short runs, the fastest kept: on a shared machine a run is often descheduled, and
    // the TSC keeps counting then (three runs of 2^19 loads each read 4-5x the true latency at
    // a load average of 8). A run of 2^12 loads (well under a millisecond even from DRAM) is
    // usually not interrupted at all. Fewer runs when spaced out: each is longer.
    const size_t loads = 1u << 12;
    const int runs = spin == 0 ? 128 : int(std::clamp(16384u / std::max(spin, 1u), 4u, 16u));
    double best = 1e30, spin_best = spin == 0 ? 0.0 : 1e30;
    for (int rep = 0; rep < runs; ++rep) {
        const uint64_t c0 = __rdtsc();
        for (size_t i = 0; i < loads; ++i) at = spin_on(chase[at], spin);
        const uint64_t c1 = __rdtsc();
        best = std::min(best, double(c1 - c0) / double(loads));
    }
    for (int rep = 0; spin > 0 && rep < runs; ++rep) {  // the spin alone, to take out
        size_t x = at;
        const uint64_t c0 = __rdtsc();
        for (size_t i = 0; i < loads; ++i) x = spin_on(x, spin);
        const uint64_t c1 = __rdtsc();
        spin_best = std::min(spin_best, double(c1 - c0) / double(loads));
        at = x;  // the same value (multiplies by one), after the spin
    }
    if (at == size_t(-1)) std::printf(" ");  // keeps the chase
    if (step_ns) *step_ns = best / tsc_mhz * 1000.0;
    return std::max(0.0, best - spin_best) / tsc_mhz * 1000.0;
}

DtlbReading measure_dtlb_pages(uint32_t max_pages) {
    constexpr size_t k_page = 4096;
    max_pages = std::min(max_pages, 512u);
    const size_t bytes = size_t(max_pages) * k_page;
    void* mapped = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    DtlbReading r;
    if (mapped == MAP_FAILED) return r;
    madvise(mapped, bytes, MADV_NOHUGEPAGE);
    char* const base = static_cast<char*>(mapped);
    // Page p's line: at line p mod 64 of its page, so that 512 lines fill the sets alike.
    const auto line = [&](uint32_t p) {
        return reinterpret_cast<uintptr_t*>(base + p * k_page + (p % 64) * 64);
    };
    uintptr_t at = 0;
    for (uint32_t pages = 8; pages <= max_pages; pages += 8) {
        std::vector<uint32_t> order(pages);
        std::iota(order.begin(), order.end(), 0u);
        std::shuffle(order.begin() + 1, order.end(), std::mt19937_64(pages));
        for (uint32_t i = 0; i < pages; ++i)
            *line(order[i]) = reinterpret_cast<uintptr_t>(line(order[(i + 1) % pages]));
        at = reinterpret_cast<uintptr_t>(line(order[0]));
        for (uint32_t i = 0; i < 4 * pages; ++i) at = *reinterpret_cast<uintptr_t*>(at);
        constexpr size_t k_loads = 1u << 12;
        double best = 1e30;
        for (int run = 0; run < 32; ++run) {
            const uint64_t c0 = __rdtsc();
            for (size_t i = 0; i < k_loads; ++i) at = *reinterpret_cast<uintptr_t*>(at);
            const uint64_t c1 = __rdtsc();
            best = std::min(best, double(c1 - c0) / double(k_loads));
        }
        r.chases.emplace_back(pages, best);
    }
    if (at == 0) std::printf(" ");  // keeps the chase
    munmap(mapped, bytes);
    r.pages = dtlb_reach(r.chases);
    return r;
}

uint32_t dtlb_reach(const std::vector<std::pair<uint32_t, double>>& chases) {
    // A third: well under the step the Intel Xeon VM of model 0xCF showed (x1.7 at 104 pages,
    // x2.4 from 128), well over its chases' spread within the reach (8 to 96 pages within 5 %
    // but one count, +13 %, which the second count in a row sets aside).
    if (chases.empty()) return 0;
    const double step = chases.front().second * 4 / 3;
    for (size_t i = 1; i + 1 < chases.size(); ++i)
        if (chases[i].second > step && chases[i + 1].second > step) return chases[i - 1].first;
    return 0;
}

std::string describe(const DtlbReading& r) {
    if (r.chases.empty()) return "not measured";
    char buf[192];
    if (r.pages == 0) {
        std::snprintf(buf, sizeof buf,
                      "no step in a chase of one line a page up to %u pages (%.1f TSC ticks a "
                      "load at %u): not modelled",
                      r.chases.back().first, r.chases.back().second, r.chases.back().first);
        return buf;
    }
    const auto step = std::find_if(r.chases.begin(), r.chases.end(),
                                   [&](const auto& c) { return c.first > r.pages; });
    std::snprintf(buf, sizeof buf,
                  "measured: a chase of one line a page, %.1f TSC ticks a load at %u pages, "
                  "%.1f at %u, %.1f at %u",
                  r.chases.front().second, r.chases.front().first, step[-1].second, step[-1].first,
                  step->second, step->first);
    return buf;
}

double measure_dram_first_pass_ns(uint64_t span_bytes, double tsc_mhz, int runs) {
    const Chase chase = random_chase(span_bytes);
    const size_t lines = chase.size() / k_chase_stride;
    const size_t loads = std::min<size_t>(lines, 1u << 16);
    size_t at = 0;
    double best = 1e30;
    for (int rep = 0; rep < runs; ++rep) {
        evict_caches();
        best = std::min(best, chase_pass_ns(chase, at, loads, tsc_mhz));
    }
    return best;
}

PairFillReading measure_pair_fill(double tsc_mhz, uint64_t pair_bytes, int runs) {
    const size_t pairs = std::max<uint64_t>(pair_bytes / 128, 8);
    // Two cycles through the pairs in random order: one over their even lines, one over their
    // odd lines.
    Chase chase(pairs * 2 * k_chase_stride);
    link_cycle(chase, pairs, 0, 2, 777);
    link_cycle(chase, pairs, 1, 2, 778);
    PairFillReading r{1e30, 1e30};
    for (int rep = 0; rep < runs; ++rep) {
        size_t even = 0, odd = k_chase_stride;
        evict_caches();
        chase_pass_ns(chase, even, 3 * pairs, tsc_mhz);
        r.after_even_ns = std::min(r.after_even_ns, chase_pass_ns(chase, odd, pairs, tsc_mhz));
        odd = k_chase_stride;
        evict_caches();
        r.cold_ns = std::min(r.cold_ns, chase_pass_ns(chase, odd, pairs, tsc_mhz));
    }
    return r;
}

namespace {

// A chase meant to read a level behind another spans this many times that one's size: mostly
// beyond it, and far below where the level itself starts to lose lines (latency_chase_kib, and
// the last level's first chase).
constexpr uint32_t k_chase_over_level_before = 2;

// The last level's chases: from twice the level before it (mostly beyond that level) in steps
// of a quarter to a half, up to the level's size and at most 64 MiB (a quarter of DRAM's).
std::vector<uint32_t> last_level_chase_kib(uint32_t before_kib, uint32_t last_kib) {
    static const double k_steps[] = {1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32};
    const uint64_t most = std::min<uint64_t>(last_kib, (k_beyond_last_level_bytes / 4) >> 10);
    std::vector<uint32_t> kib;
    for (double step : k_steps) {
        const uint64_t k = uint64_t(step * k_chase_over_level_before * before_kib);
        if (k > most) break;
        kib.push_back(uint32_t(k));
    }
    return kib;
}

// Where `points` (x rising, a latency each) first pass `mid`, x interpolated in log x between
// the points either side (the first point's x if it is past already; 0: never).
double crossing(const std::vector<std::pair<double, double>>& points, double mid) {
    for (size_t i = 0; i < points.size(); ++i) {
        if (points[i].second <= mid) continue;
        if (i == 0) return points[0].first;
        const auto [x0, l0] = points[i - 1];
        const auto [x1, l1] = points[i];
        return std::exp(std::log(x0) + (mid - l0) / (l1 - l0) * (std::log(x1) - std::log(x0)));
    }
    return 0.0;
}

}  // namespace

SeenLevel last_level_seen(const HostDescription& h) {
    SeenLevel seen;
    if (h.caches.empty()) return seen;
    const HostCacheLevel& last = h.caches.back();
    seen.kib = last.kib;
    seen.latency_ns =
        h.latency_ns.size() >= h.caches.size() ? h.latency_ns[h.caches.size() - 1] : 0.0;
    if (h.last_level_chases.empty()) return seen;
    const double hit = h.last_level_chases.front().second;
    // A line evicted: the largest size chase (64 MiB, more than a core keeps of any current
    // L3); where even it kept its lines, the median of the three most spaced-out chases. Not
    // the slowest reading of all: one interrupted chase (566 ns where its neighbours read
    // 112-145 ns, 2026-11-27) set the midpoint above every crossing, and the level to 64 MiB.
    double evicted = h.last_level_chases.back().second;
    const auto& idle = h.last_level_idle_chases;
    if (evicted < 2.0 * hit && !idle.empty()) {
        std::vector<double> tail;
        for (auto it = idle.end() - long(std::min<size_t>(idle.size(), 3)); it != idle.end(); ++it)
            tail.push_back(it->second);
        evicted = median(tail);
    }
    seen.latency_ns = hit;
    if (evicted < 2.0 * hit) return seen;  // no chase lost its lines
    const double mid = 0.5 * (hit + evicted);
    std::vector<std::pair<double, double>> sizes;  // lines, ns
    for (const auto& [kib, ns] : h.last_level_chases)
        sizes.emplace_back(double(kib) * 1024.0 / last.line_bytes, ns);
    const double s0 = sizes.front().first, s_star = crossing(sizes, mid);
    const double t_star = crossing(h.last_level_idle_chases, mid);
    double capacity = 0.0, per_ns = 0.0;  // lines, others' lines per ns
    if (s_star > s0 && t_star > 0.0 && s0 * t_star > s_star * hit) {
        per_ns = (s_star - s0) / (s0 * t_star - s_star * hit);
        capacity = s_star * (1.0 + per_ns * hit);
    } else if (s_star > 0.0) {
        capacity = s_star;  // spacing the loads out lost nothing more than size did
    } else if (t_star > 0.0) {
        capacity = sizes.back().first;  // at least the largest chase, which kept its lines
        per_ns = std::max(0.0, (capacity / s0 - 1.0) / t_star);
    } else {
        return seen;
    }
    const uint64_t kib = uint64_t(std::llround(capacity * last.line_bytes / 1024.0));
    // Whole sets (a 20-way level's come in steps of 5 KiB), within cpuid's size.
    seen.kib = std::min(
        whole_sets_kib(uint32_t(std::min<uint64_t>(kib, last.kib)), last.ways, last.line_bytes),
        last.kib);
    seen.cut = seen.kib < last.kib;
    seen.foreign_fill_per_us = per_ns * 1000.0;
    return seen;
}

void chase_last_level(HostDescription& h) {
    h.last_level_chases.clear();
    h.last_level_idle_chases.clear();
    if (h.caches.size() < 2) return;
    for (uint32_t kib :
         last_level_chase_kib(h.caches[h.caches.size() - 2].kib, h.caches.back().kib))
        h.last_level_chases.emplace_back(kib,
                                         measure_load_latency_ns(uint64_t(kib) << 10, h.tsc_mhz));
    if (h.last_level_chases.empty()) return;
    // Spaced out by 16 to 8192 multiplies (about 14 ns to 7 us a step at 3.5 GHz, laps of 2 MiB
    // up to a quarter of a second): on this project's AMD VM, with quiet neighbours, 2 us steps
    // lost a third of the lines (2026-11-27).
    for (uint32_t spin = 16; spin <= 8192; spin *= 2) {
        double step = 0.0;
        const double ns = measure_load_latency_ns(uint64_t(h.last_level_chases.front().first) << 10,
                                                  h.tsc_mhz, spin, &step);
        h.last_level_idle_chases.emplace_back(step, ns);
    }
}

uint32_t latency_chase_kib(const std::vector<HostCacheLevel>& caches, size_t level) {
    const uint32_t half = std::max(1u, caches[level].kib / 2);
    return level == 0 ? half : std::min(half, k_chase_over_level_before * caches[level - 1].kib);
}

HostDescription describe_host(uint32_t simd_width, const std::string& isa, bool measure_memory) {
    HostDescription h;
    h.microarchitecture = read_microarchitecture();
    h.simd_width = simd_width;
    h.isa = isa;
    h.cpu = sched_getcpu();
    h.tsc_mhz = measure_tsc_mhz();
    h.core_mhz = h.tsc_mhz / tsc_ticks_per_core_cycle(21, simd_width);
    h.caches = read_host_caches();
    h.dtlb = measure_dtlb_pages();  // the ray buffers' pages: measured with or without the memory
    if (!measure_memory) return h;
    for (size_t i = 0; i < h.caches.size(); ++i) {
        if (i > 0 && i + 1 == h.caches.size()) {
            chase_last_level(h);
            if (!h.last_level_chases.empty()) {
                h.latency_ns.push_back(h.last_level_chases.front().second);
                continue;
            }
        }
        h.latency_ns.push_back(
            measure_load_latency_ns(uint64_t(latency_chase_kib(h.caches, i)) << 10, h.tsc_mhz));
    }
    h.pair_fill = measure_pair_fill(h.tsc_mhz);
    // DRAM: in huge pages, as the BVH's nodes and leaf primitives are.
    h.latency_ns.push_back(measure_load_latency_ns(k_beyond_last_level_bytes, h.tsc_mhz));
    // And by span, from a few MiB (a small scene's data) to 256 MiB.
    for (uint32_t mib = 2; mib <= (k_beyond_last_level_bytes >> 20); mib *= 2)
        h.dram_span_latencies.emplace_back(
            mib, measure_dram_first_pass_ns(uint64_t(mib) << 20, h.tsc_mhz));
    return h;
}

HwConfig host_hw_config(const HostDescription& h, const std::vector<OpCostConfig>& op_costs) {
    HwConfig c;
    c.name = "host";
    c.clock.core_mhz = h.core_mhz > 0 ? h.core_mhz : h.tsc_mhz;
    c.clock.interconnect_mhz = c.clock.core_mhz;
    c.simd.width = h.simd_width;
    c.simd.units = 1;
    c.cores.count = 1;
    const uint32_t l1d = h.caches.empty() ? 32 : h.caches.front().kib;
    c.ray_buffer.kib = l1d;
    c.ray_buffer.banks = 1;
    c.ray_buffer.storage = "l1d";
    c.ray_buffer.slot_bytes = h.slot_bytes;
    c.ray_buffer.slot_arrays = std::max(1u, h.slot_arrays);
    c.ray_buffer.dtlb_pages = h.dtlb.pages;
    c.ray_buffer.line_words = (h.caches.empty() ? 64 : h.caches.front().line_bytes) / 4;
    c.partition.kind = "compress";
    c.scene_memory.caches.clear();
    for (size_t i = 0; i < h.caches.size(); ++i) {
        const HostCacheLevel& l = h.caches[i];
        CacheLevelConfig cl;
        cl.name = "l" + std::to_string(l.level);
        cl.kib = l.kib;
        cl.line_bytes = l.line_bytes;
        cl.ways = l.ways;
        cl.hit_latency_ns = i < h.latency_ns.size() ? h.latency_ns[i] : 1.0;
        cl.shared = l.shared;
        c.scene_memory.caches.push_back(cl);
    }
    if (!c.scene_memory.caches.empty()) {  // the last level as this core's chases see it
        const SeenLevel seen = last_level_seen(h);
        c.scene_memory.caches.back().kib = seen.kib;
        c.scene_memory.caches.back().hit_latency_ns = seen.latency_ns;
        c.scene_memory.caches.back().foreign_fill_per_us = seen.foreign_fill_per_us;
        c.scene_memory.caches.back().pair_fill = h.pair_fill.pairs();
    }
    if (h.latency_ns.size() > h.caches.size()) c.scene_memory.dram_latency_ns = h.latency_ns.back();
    for (const auto& [mib, ns] : h.dram_span_latencies)
        c.scene_memory.dram_latency_by_span.push_back({mib, ns});
    // Caches and DRAM from another file of this machine; the prefetch and hit reads below are
    // this tracer's whoever measured them.
    if (!h.memory_source.empty()) c.scene_memory = h.memory;
    // The native tracer prefetches a node's children (a leaf's primitives) while it tests the
    // node (prefetch_below in kernels/stream/stream_kernels_impl.h), and nothing else.
    c.scene_memory.prefetch_depth = 0;
    c.scene_memory.prefetch_children = true;
    // Its surface_at reads the mesh's triangle and vertex arrays, not the leaves' copies.
    c.scene_memory.hit_reads = "mesh";
    c.op_costs = op_costs;
    c.branch_predictor = h.branch_predictor;
    c.speed_probe_cycles = h.speed_probe_cycles;
    return c;
}

std::string host_hw_yaml(const HostDescription& h, const std::vector<OpCostConfig>& op_costs,
                         const std::string& fit_note) {
    const HwConfig c = host_hw_config(h, op_costs);
    std::ostringstream y;
    y << "# The host CPU as a hardware configuration, written by `sfx calibrate --describe-host`.\n"
      << "# One core running the native stream tracer (kernels/stream) single-threaded; timed by\n"
      << "# the same machine model as the paper's machine (hw_model/core_model.h): one SIMD unit,\n"
      << "# ray buffers behind the L1D, partition by compress, measured per-op costs.\n"
      << "# Microarchitecture (cpuid): " << describe(h.microarchitecture) << "\n"
      << "# Measured on CPU " << h.cpu << " (sched_getcpu): check it pinned to the same CPU\n"
      << "version: 1\nname: host\nclock:\n"
      << "  core_mhz: " << fmt(c.clock.core_mhz, 3) << "  # measured: a chain of dependent "
      << clock_chain_name(h.simd_width)
      << " (one a core cycle, the back end's own) against the TSC (" << fmt(h.tsc_mhz, 3)
      << " MHz, over 0.2 s of the steady clock); op costs are core cycles\n"
      << "  interconnect_mhz: " << fmt(c.clock.core_mhz, 3)
      << "  # one clock (unused: storage l1d has no interconnect)\n"
      << "simd:\n  width: " << h.simd_width << "  # cpuid: " << h.isa << "\n"
      << "  units: 1  # the native tracer runs its filters on one core's vector unit\n"
      << "cores:\n  count: 1  # measured single-threaded, one pinned thread\n"
      << "  op_window: 1  # the native tracer's next op waits for the current op's pass count\n"
      << "                # (its loop bound); on an AVX2 host's conference cells (2026-11-25) 1, "
         "2\n"
      << "                # and 4 gave frame MAE 9.2, 8.6 and 8.5 %, apart by less than the noise\n"
      << "ray_buffer:\n"
      << "  kib: " << c.ray_buffer.kib
      << "  # the L1D holds the ray buffers (the closed form's share beyond it; the cycle level "
         "asks scene_memory's first level): "
      << (h.caches.empty() ? "assumed" : h.caches.front().source) << "\n"
      << "  banks: 1  # no banks: the L1D serves the filters' loads (storage: l1d)\n"
      << "  line_words: " << c.ray_buffer.line_words << "  # the L1D line\n"
      << "  storage: l1d\n"
      << "  slot_bytes: " << h.slot_bytes << "  # the native tracer's ray slot (kernels/stream)\n"
      << "  slot_arrays: " << c.ray_buffer.slot_arrays
      << "  # the arrays a slot indexes beyond its traversal record (kernels/stream)\n"
      << "  dtlb_pages: " << c.ray_buffer.dtlb_pages << "  # " << describe(h.dtlb) << "\n"
      << "partition:\n  kind: compress  # vpcompressd (AVX-512) or a permutation table (AVX2)\n"
      << "scene_memory:\n  caches:\n";
    for (size_t i = 0; i < c.scene_memory.caches.size(); ++i) {
        const CacheLevelConfig& l = c.scene_memory.caches[i];
        y << "    - {name: " << l.name << ", kib: " << l.kib << ", line_bytes: " << l.line_bytes
          << ", ways: " << l.ways << ", hit_latency_ns: " << fmt(l.hit_latency_ns, 2)
          << ", shared: " << (l.shared ? "true" : "false")
          << (l.foreign_fill_per_us > 0 ? ", foreign_fill_per_us: " + fmt(l.foreign_fill_per_us, 2)
                                        : std::string())
          << (l.pair_fill ? ", pair_fill: true" : "") << "}  # ";
        if (!h.memory_source.empty()) {
            y << "as " << h.memory_source << " describes it\n";
            continue;
        }
        y << h.caches[i].source << "; latency measured (pointer chase over ";
        const bool chased = i + 1 == c.scene_memory.caches.size() && !h.last_level_chases.empty();
        if (!chased) {
            y << latency_chase_kib(h.caches, i) << " KiB)\n";
            continue;
        }
        const SeenLevel seen = last_level_seen(h);
        y << h.last_level_chases.front().first << " KiB); kib"
          << (seen.foreign_fill_per_us > 0 ? " and foreign_fill_per_us" : "")
          << (seen.cut || seen.foreign_fill_per_us > 0
                  ? ": the LRU stack through this core's chases (last_level_seen; cpuid: " +
                        std::to_string(h.caches[i].kib) + " KiB)"
                  : ": cpuid's (no chase lost its lines)")
          << "; chases over";
        for (const auto& [kib, ns] : h.last_level_chases)
            y << " " << fmt(kib / 1024.0, kib % 1024 ? 1 : 0) << " MiB " << fmt(ns, 1) << " ns"
              << (kib == h.last_level_chases.back().first ? "" : ",");
        if (!h.last_level_idle_chases.empty()) {
            const uint32_t kib = h.last_level_chases.front().first;
            y << "; over " << fmt(kib / 1024.0, kib % 1024 ? 1 : 0) << " MiB with steps of";
            for (const auto& [step, ns] : h.last_level_idle_chases)
                y << " " << fmt(step, 0) << " ns " << fmt(ns, 1) << " ns"
                  << (step == h.last_level_idle_chases.back().first ? "" : ",");
        }
        if (h.pair_fill.cold_ns > 0)
            y << "; pair_fill (measure_pair_fill): the odd lines of 1 MiB read first after a chase "
                 "of its even lines "
              << fmt(h.pair_fill.after_even_ns, 1) << " ns a load, from DRAM "
              << fmt(h.pair_fill.cold_ns, 1) << " ns";
        y << "\n";
    }
    y << "  dram_latency_ns: " << fmt(c.scene_memory.dram_latency_ns, 2) << "  # "
      << (h.memory_source.empty() ? "measured: pointer chase over 256 MiB"
                                  : "as " + h.memory_source + " describes it")
      << (c.scene_memory.dram_latency_by_span.empty() ? ""
                                                      : " (a scene's reads: by their pages' "
                                                        "recency, below)")
      << "\n";
    if (!c.scene_memory.dram_latency_by_span.empty()) {
        y << "  dram_latency_by_span:  # "
          << (h.memory_source.empty()
                  ? "measured: the first pass of a random chase over the span after other "
                    "data read elsewhere (measure_dram_first_pass_ns, evict_caches)"
                  : "as " + h.memory_source + " describes it")
          << "\n";
        for (const DramSpanLatency& s : c.scene_memory.dram_latency_by_span)
            y << "    - {span_mib: " << fmt(s.span_mib, s.span_mib < 1 ? 3 : 0)
              << ", latency_ns: " << fmt(s.latency_ns, 1) << "}\n";
    }
    y << "  dram_bandwidth_gbps: " << fmt(c.scene_memory.dram_bandwidth_gbps, 1)
      << "  # assumed: not measured; DRAM lines queue for it\n"
      << "  prefetch_depth: 0  # the native tracer prefetches no op by its place in the order\n"
      << "  prefetch_children: true  # it prefetches a node's children (a leaf's primitives) "
      << "as it\n"
      << "                           # tests the node (prefetch_below, kernels/stream)\n"
      << "  hit_reads: mesh  # surface_at reads the mesh's triangle and vertex arrays, not the\n"
      << "                   # copies its leaf tests read (kernels/intersect.h)\n";
    if (h.branch_predictor.kind != "none")
        y << "branch_predictor:\n  kind: " << h.branch_predictor.kind
          << (h.branch_predictor.kind == "unseen_ops"
                  ? "  # each op of a traversal not just run (a frame's: all) one misprediction\n"
                    "                    # (hw_model/branch_predictor.h): the core's own "
                    "predictor is not published\n"
                  : "  # the model's (L-TAGE's TAGE, hw_model/branch_predictor.h) over the "
                    "traversal's\n              # branches: the core's own predictor is not "
                    "published\n")
          << "  mispredict_cycles: " << fmt(h.branch_predictor.mispredict_cycles, 1)
          << "  # fitted: " << h.branch_predictor_fit << "\n";
    if (h.branch_predictor.kind != "none") {
        const BranchPredictorConfig& b = h.branch_predictor;
        const std::pair<const char*, double> by_loop[] = {{"one_ray", b.one_ray_mispredict_cycles},
                                                          {"few_ray", b.few_ray_mispredict_cycles},
                                                          {"stream", b.stream_mispredict_cycles}};
        for (const auto& [loop, cycles] : by_loop)
            if (cycles >= 0)
                y << "  " << loop << "_mispredict_cycles: " << fmt(cycles, 1)
                  << (std::string(loop) == "few_ray" && !h.few_ray_source.empty()
                          ? "  # as " + h.few_ray_source +
                                " gives it (the few-ray loop is the same code at 8 and 16 "
                                "lanes)\n"
                          : std::string("  # fitted: the same microbenchmark, a box test's in "
                                        "that loop (the stage clock's split)\n"));
    }
    if (h.speed_probe_cycles > 0)
        y << "speed_probe_cycles: " << fmt(h.speed_probe_cycles, 0)
          << "  # measured: the speed probe's microbenchmark points at calibration (fastest of "
             "repetitions, sweeps/host_calibration.h)\n";
    y << "# Fitted: " << fit_note << "\n";
    if (op_costs.empty()) {
        y << "op_costs: []\n";
    } else {
        y << "op_costs:\n";
        for (const OpCostConfig& o : op_costs)
            y << "  - {op: " << o.op << ", per_op_cycles: " << fmt(o.per_op_cycles, 2)
              << ", per_group_cycles: " << fmt(o.per_group_cycles, 2)
              << ", per_lane_cycles: " << fmt(o.per_lane_cycles, 2)
              << ", per_pass_cycles: " << fmt(o.per_pass_cycles, 2)
              << ", per_fail_cycles: " << fmt(o.per_fail_cycles, 2)
              << ", per_minority_lane_cycles: " << fmt(o.per_minority_lane_cycles, 2)
              << ", beyond_l1_per_lane_cycles: " << fmt(o.beyond_l1_per_lane_cycles, 2)
              << ", beyond_l2_per_lane_cycles: " << fmt(o.beyond_l2_per_lane_cycles, 2)
              << ", beyond_l1_skipping_per_lane_cycles: "
              << fmt(o.beyond_l1_skipping_per_lane_cycles, 2)
              << ", beyond_tlb_per_lane_cycles: " << fmt(o.beyond_tlb_per_lane_cycles, 2)
              << ", one_lane_cycles: " << fmt(o.one_lane_cycles, 2)
              << (o.one_lane_pass_cycles > 0
                      ? ", one_lane_pass_cycles: " + fmt(o.one_lane_pass_cycles, 2)
                      : std::string())
              << (o.one_lane_failed_candidate_cycles > 0
                      ? ", one_lane_failed_candidate_cycles: " +
                            fmt(o.one_lane_failed_candidate_cycles, 2)
                      : std::string())
              << ", few_lane_cycles: " << fmt(o.few_lane_cycles, 2)
              << (o.one_ray_entry_cycles > 0 || o.few_ray_entry_cycles > 0
                      ? ", one_ray_entry_cycles: " + fmt(o.one_ray_entry_cycles, 2) +
                            ", few_ray_entry_cycles: " + fmt(o.few_ray_entry_cycles, 2)
                      : std::string())
              << (o.traversal_start_cycles > 0
                      ? ", traversal_start_cycles: " + fmt(o.traversal_start_cycles, 2)
                      : std::string())
              << (o.shared_origin_per_lane_cycles > 0 ? ", shared_origin_per_lane_cycles: " +
                                                            fmt(o.shared_origin_per_lane_cycles, 2)
                                                      : std::string())
              << (o.hit_read_exposed_share > 0
                      ? ", hit_read_exposed_share: " + fmt(o.hit_read_exposed_share, 3)
                      : std::string())
              << (o.node_read_exposed_share < 1
                      ? ", node_read_exposed_share: " + fmt(o.node_read_exposed_share, 3)
                      : std::string())
              << (o.thin_lens_per_lane_cycles > 0
                      ? ", thin_lens_per_lane_cycles: " + fmt(o.thin_lens_per_lane_cycles, 2)
                      : std::string())
              << (o.sphere_light_per_pass_cycles > 0
                      ? ", sphere_light_per_pass_cycles: " + fmt(o.sphere_light_per_pass_cycles, 2)
                      : std::string())
              << (o.per_failed_candidate_cycles > 0
                      ? ", per_failed_candidate_cycles: " + fmt(o.per_failed_candidate_cycles, 2)
                      : std::string())
              << (o.sphere_hit_per_lane_cycles != 0
                      ? ", sphere_hit_per_lane_cycles: " + fmt(o.sphere_hit_per_lane_cycles, 2)
                      : std::string())
              << (o.cold_call_cycles > 0 ? ", cold_call_cycles: " + fmt(o.cold_call_cycles, 2)
                                         : std::string())
              << "}\n";
    }
    return y.str();
}

}  // namespace sfx
