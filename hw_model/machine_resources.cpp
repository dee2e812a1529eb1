#include "hw_model/machine_resources.h"

#include <algorithm>

namespace sfx {

bool SlotServer::is_free(uint64_t cycle) const {
    const uint64_t offset = cycle - m_base;
    const uint64_t word = m_bits[(m_head + offset / 64) % k_words];
    return (word >> (offset % 64) & 1) == 0;
}

void SlotServer::mark(uint64_t cycle) {
    const uint64_t offset = cycle - m_base;
    m_bits[(m_head + offset / 64) % k_words] |= uint64_t(1) << (offset % 64);
}

void SlotServer::slide_to(uint64_t last) {
    if (last >= m_base + 2 * uint64_t(k_window)) {  // far ahead: nothing booked survives
        m_bits.fill(0);
        m_head = 0;
        m_base = (last / 64) * 64 - (k_window - 64);
        return;
    }
    while (last >= m_base + k_window) {
        m_bits[m_head] = 0;
        m_head = (m_head + 1) % k_words;
        m_base += 64;
    }
}

uint64_t SlotServer::book_slow(uint64_t ready, uint32_t occupancy) {
    if (occupancy == 0) occupancy = 1;
    // Cycles before the window were forgotten when a later booking moved it: never book them.
    uint64_t cycle = ready > m_base ? ready : m_base;
    if (occupancy == 1) {
        // A pipelined bank: the first free cycle, found a 64-cycle word at a time (a conflict
        // queues behind every booking in flight, so runs of booked cycles are common).
        for (;;) {
            slide_to(cycle);
            const uint64_t offset = cycle - m_base;
            uint64_t& word = m_bits[(m_head + offset / 64) % k_words];
            const uint64_t free = ~word >> (offset % 64);
            if (free) {
                const uint32_t skip = uint32_t(__builtin_ctzll(free));
                word |= uint64_t(1) << (offset % 64 + skip);
                return cycle + skip;
            }
            cycle += 64 - offset % 64;
        }
    }
    for (;;) {
        slide_to(cycle + occupancy - 1);
        if (cycle < m_base) cycle = m_base;
        uint32_t free_run = 0;
        while (free_run < occupancy && is_free(cycle + free_run)) ++free_run;
        if (free_run == occupancy) break;
        cycle += free_run + 1;
    }
    for (uint32_t i = 0; i < occupancy; ++i) mark(cycle + i);
    return cycle;
}

void CapacityServer::slide_to(uint64_t cycle) {
    if (cycle >= m_base + 2 * uint64_t(k_window)) {  // far ahead: nothing booked survives
        m_used.fill(0.0);
        m_head = 0;
        m_base = cycle - (k_window - 1);
        return;
    }
    while (cycle >= m_base + k_window) {
        m_used[m_head] = 0.0;
        m_head = (m_head + 1) % k_window;
        ++m_base;
    }
}

uint64_t CapacityServer::serve(uint64_t ready, double amount) {
    m_work += amount;
    uint64_t cycle = ready > m_base ? ready : m_base;
    double left = amount;
    const double eps = 1e-9 * (m_per_cycle > 1.0 ? m_per_cycle : 1.0);
    while (left > eps) {
        slide_to(cycle);
        double& u = used(cycle);
        const double take = std::min(left, m_per_cycle - u);
        if (take > eps) {
            u += take;
            left -= take;
        }
        if (left > eps) ++cycle;
    }
    return cycle;
}

}  // namespace sfx
