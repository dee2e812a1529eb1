#include "hw_model/machine_resources.h"

#include <algorithm>

namespace sfx {

BankSchedule::BankSchedule(uint32_t banks, uint32_t occupancy)
    : m_banks(banks),
      m_words((banks + 63) / 64),
      m_occupancy(occupancy == 0 ? 1 : occupancy),
      m_full(banks >= 64 ? ~uint64_t(0) : (uint64_t(1) << banks) - 1),
      m_ring(size_t(k_window) * (m_words + 1), 0),
      m_grant(m_words, 0) {
    for (size_t i = 0; i < k_window; ++i) m_ring[i * (m_words + 1)] = ~uint64_t(0);
}

void BankSchedule::set_lanes(const uint32_t* lane_banks, uint32_t count) {
    m_lane_count = count;
    m_fast = m_words == 1 && m_occupancy == 1;
    if (m_fast) {
        // Each lane's bit goes to the first layer without it (mostly the first).
        m_layers = 0;
        for (uint32_t i = 0; i < count; ++i) {
            const uint64_t bit = uint64_t(1) << lane_banks[i];
            uint32_t k = 0;
            while (k < m_layers && (m_layer[k] & bit)) ++k;
            if (k == m_layers) {
                if (k == k_fast_layers) {
                    m_fast = false;
                    break;
                }
                m_layer[m_layers++] = 0;
            }
            m_layer[k] |= bit;
        }
    }
    if (!m_fast) m_lanes.assign(lane_banks, lane_banks + count);
}

uint64_t BankSchedule::book_lanes(uint32_t rotation, uint64_t ready) {
    if (m_lane_count == 0) return ready;
    if (m_fast) {
        // Pipelined banks: each cycle grants every wanting bank that is free in it.
        uint64_t layer[k_fast_layers];
        uint32_t layers = m_layers;
        for (uint32_t k = 0; k < layers; ++k) layer[k] = rotate(m_layer[k], rotation);
        for (uint64_t cycle = ready > m_base ? ready : m_base;; ++cycle) {
            uint64_t& bits = *busy<true>(cycle);
            const uint64_t granted = layer[0] & ~bits;
            if (!granted) continue;
            bits |= granted;
            // One request fewer per granted bank: layer k keeps it only if layer k+1 has it.
            for (uint32_t k = 0; k + 1 < layers; ++k) layer[k] &= ~granted | layer[k + 1];
            layer[layers - 1] &= ~granted;
            if (!layer[0]) return cycle;
            if (!layer[layers - 1]) --layers;  // at most one layer empties per cycle
        }
    }
    // The general case: the layers a bit per lane, as many as the most requests to one bank.
    const uint32_t words = m_words, count = m_lane_count;
    if (m_want.size() < size_t(count) * words) m_want.resize(size_t(count) * words);
    uint32_t layers = 0;
    for (uint32_t i = 0; i < count; ++i) {
        const uint32_t bank = (m_lanes[i] + rotation) % m_banks;
        const uint32_t j = bank / 64;
        const uint64_t bit = uint64_t(1) << (bank % 64);
        uint32_t k = 0;
        while (k < layers && (m_want[size_t(k) * words + j] & bit)) ++k;
        if (k == layers) {
            std::fill_n(&m_want[size_t(k) * words], words, 0);
            ++layers;
        }
        m_want[size_t(k) * words + j] |= bit;
    }
    return words == 1 ? grant<true>(layers, ready) : grant<false>(layers, ready);
}

template <bool OneWord>
uint64_t BankSchedule::grant(uint32_t layers, uint64_t ready) {
    const uint32_t words = OneWord ? 1 : m_words;
    uint64_t* want = m_want.data();
    uint64_t* granted = m_grant.data();
    // Cycles before the window were forgotten when a later booking moved it: never book them.
    uint64_t cycle = ready > m_base ? ready : m_base;
    for (;; ++cycle) {
        // Banks free for the whole occupancy from this cycle on get their next request.
        bool any = false;
        for (uint32_t j = 0; j < words; ++j) granted[j] = want[j];
        for (uint32_t i = 0; i < m_occupancy; ++i) {
            const uint64_t* bits = busy<OneWord>(cycle + i);
            for (uint32_t j = 0; j < words; ++j) granted[j] &= ~bits[j];
        }
        for (uint32_t j = 0; j < words; ++j) any |= granted[j] != 0;
        if (!any) continue;
        for (uint32_t i = 0; i < m_occupancy; ++i) {
            uint64_t* bits = busy<OneWord>(cycle + i);
            for (uint32_t j = 0; j < words; ++j) bits[j] |= granted[j];
        }
        // One request fewer for each granted bank: layer k keeps a granted bank only if layer
        // k + 1 has it.
        for (uint32_t k = 0; k + 1 < layers; ++k)
            for (uint32_t j = 0; j < words; ++j)
                want[k * words + j] &= ~granted[j] | want[(k + 1) * words + j];
        for (uint32_t j = 0; j < words; ++j) want[(layers - 1) * words + j] &= ~granted[j];
        bool left = false;
        for (uint32_t j = 0; j < words; ++j) left |= want[j] != 0;
        if (!left) return cycle;
        while (layers > 1) {
            bool top = false;
            for (uint32_t j = 0; j < words; ++j) top |= want[(layers - 1) * words + j] != 0;
            if (top) break;
            --layers;
        }
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
