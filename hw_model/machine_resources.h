#pragma once
// Shared resources of the machine model as plain classes, tested without a SystemC kernel. A
// resource that many requests share keeps its bookings (gem5 keeps a port's busy-until): each
// request books it at the cycle it is ready and learns when it is served, so contention between
// units emerges from what every unit in flight asks for. SystemC processes (hw_model/systemc)
// book them at their own simulated time.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sfx {

// The banks of one ray buffer. A bank accepts one request per cycle and keeps it for
// `occupancy` cycles (1 when pipelined, the access latency when not). A request takes the first
// cycle at or after it is ready from which its bank is free for `occupancy` cycles, whichever
// unit booked the others; requests to one bank queue in order.
//
// Bookings are kept as one bit per bank per cycle, cycle-major, so the lanes of a SIMD access
// (one request each, all ready in one cycle) are granted a whole cycle at a time with bit
// operations instead of a search per lane. The buffer keeps the last k_window cycles touched
// (a ring whose entries are tagged with their cycle, so moving on costs nothing); a request
// older than that waits until the window's first cycle. Requests come at or after the current
// simulated cycle and a few hundred cycles ahead at most, so nothing still wanted is forgotten
// (tests/hw_model/machine_resources_test.cpp checks that against a bank that never forgets).
class BankSchedule {
  public:
    static constexpr uint32_t k_window = 1024;

    BankSchedule(uint32_t banks, uint32_t occupancy);

    // The lanes of the next accesses: one request each, to bank lane_banks[i] turned by the
    // access's rotation (each field word of a group falls in the slots' banks turned by the
    // field's offset: RayBufferModel::field_rotation), so the lanes are sorted into banks once
    // per group.
    void set_lanes(const uint32_t* lane_banks, uint32_t count);
    // Books the lanes' requests to banks (lane_banks[i] + rotation) % banks, all ready at
    // `ready`; returns the cycle of the last grant (`ready` when there are no lanes).
    uint64_t book_lanes(uint32_t rotation, uint64_t ready);
    // set_lanes and book_lanes at rotation 0.
    uint64_t book(const uint32_t* banks, uint32_t count, uint64_t ready) {
        set_lanes(banks, count);
        return book_lanes(0, ready);
    }

  private:
    // Bank bits of `cycle` (moves the window to reach it; a stale entry reads as free).
    template <bool OneWord>
    uint64_t* busy(uint64_t cycle) {
        if (cycle >= m_base + k_window) m_base = cycle - (k_window - 1);
        const uint32_t ring = uint32_t(cycle % k_window);
        uint64_t* entry = &m_ring[size_t(ring) * (m_words + 1)];  // tag, then the bank bits
        if (entry[0] != cycle) {
            entry[0] = cycle;
            for (uint32_t j = 1; j <= (OneWord ? 1 : m_words); ++j) entry[j] = 0;
        }
        return entry + 1;
    }
    template <bool OneWord>
    uint64_t grant(uint32_t layers, uint64_t ready);
    uint64_t rotate(uint64_t bits, uint32_t by) const {  // within a ring of m_banks <= 64 bits
        if (by == 0) return bits;
        return ((bits << by) | (bits >> (m_banks - by))) & m_full;
    }

    static constexpr uint32_t k_fast_layers = 64;
    uint32_t m_banks, m_words, m_occupancy;
    uint64_t m_full;  // the bank bits of one word, when m_words is 1
    // The lanes: with pipelined banks, at most 64 of them and k_fast_layers requests per bank,
    // as bit layers (layer k: the banks with more than k requests; m_layers of them, as many
    // as the most requests to one bank: a tile's column of rays falls in one bank); else each
    // lane's bank.
    bool m_fast = true;
    uint32_t m_lane_count = 0;
    uint32_t m_layers = 0;
    uint64_t m_layer[k_fast_layers] = {};
    std::vector<uint32_t> m_lanes;
    uint64_t m_base = 0;            // first cycle of the window
    std::vector<uint64_t> m_ring;   // k_window entries: the cycle held, then m_words bank words
    std::vector<uint64_t> m_want;   // scratch: per layer k, the banks with more than k requests
    std::vector<uint64_t> m_grant;  // scratch: one cycle's grants
};

// A pool with a capacity per cycle (the address-generation units: addresses per cycle; the
// interconnect: words per core cycle). Work takes what each cycle has left from the cycle it is
// ready, so a later request may use capacity an earlier-booked one left free. Bookings are kept
// per cycle in a window of k_window cycles, tagged with their cycle like BankSchedule's.
class CapacityServer {
  public:
    static constexpr uint32_t k_window = 1024;
    explicit CapacityServer(double per_cycle)
        : m_per_cycle(per_cycle),
          m_whole(per_cycle >= 1.0 && per_cycle < 1e9 && per_cycle == std::floor(per_cycle)
                      ? uint64_t(per_cycle)
                      : 0) {
        m_tag.fill(~uint64_t(0));  // every entry stale: used() zeroes it when first touched
    }

    // Serves `amount` from cycle `ready` on; returns the cycle in which its last part is served
    // (it is usable from the next one). Zero work returns `ready`.
    uint64_t serve(uint64_t ready, double amount);
    double per_cycle() const { return m_per_cycle; }
    // Cycles an idle pool takes for `amount`: ceil(amount / per_cycle), in integers when the
    // capacity is whole (the same value; asked for every lane group, where a division and a
    // floating-point ceiling showed in profiles).
    uint64_t idle_cycles(uint64_t amount) const {
        if (m_whole > 0) return (amount + m_whole - 1) / m_whole;
        return uint64_t(std::ceil(double(amount) / m_per_cycle - 1e-9));
    }
    double work() const { return m_work; }

  private:
    void slide_to(uint64_t cycle) {
        if (cycle >= m_base + k_window) m_base = cycle - (k_window - 1);
    }
    // The capacity used in `cycle` (inside the window), made current.
    double& used(uint64_t cycle) {
        const uint32_t ring = uint32_t(cycle % k_window);
        if (m_tag[ring] != cycle) {
            m_tag[ring] = cycle;
            m_used[ring] = 0.0;
        }
        return m_used[ring];
    }

    double m_per_cycle;
    uint64_t m_whole;  // per_cycle when it is a whole number, else 0
    uint64_t m_base = 0;
    std::array<double, k_window> m_used;
    std::array<uint64_t, k_window> m_tag;  // the cycle each entry holds
    double m_work = 0.0;
};

// A pipe with a throughput (DRAM): work arriving at
// `ready` starts when the pipe is free, first come first served, and occupies it amount / rate
// cycles. Times are fractional cycles: 16 addresses on 32 units take half a cycle.
class RateServer {
  public:
    explicit RateServer(double per_cycle = 1.0) : m_per_cycle(per_cycle) {}
    // Returns the cycle the work starts; the pipe is busy until start + amount / per_cycle.
    double serve(double ready, double amount) {
        const double start = ready > m_free ? ready : m_free;
        m_free = start + amount / m_per_cycle;
        m_work += amount;
        return start;
    }
    double free_at() const { return m_free; }
    double per_cycle() const { return m_per_cycle; }
    double work() const { return m_work; }  // total amount served

  private:
    double m_per_cycle;
    double m_free = 0.0;
    double m_work = 0.0;
};

}  // namespace sfx
