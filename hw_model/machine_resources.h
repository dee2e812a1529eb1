#pragma once
// Shared resources of the machine model as plain classes, tested without a SystemC kernel. A
// resource that many requests share keeps its bookings (gem5 keeps a port's busy-until): each
// request books it at the cycle it is ready and learns when it is served, so contention between
// units emerges from what every unit in flight asks for. SystemC processes (hw_model/systemc)
// book them at their own simulated time.

#include <array>
#include <cstdint>

namespace sfx {

// A server that accepts one request per cycle and keeps each for `occupancy` cycles (a ray-
// buffer bank: occupancy 1 when pipelined, the access latency when not). Booked cycles are kept
// exactly, holes included, in a window of k_window cycles: a request takes the first free cycle
// at or after it is ready, whichever unit booked the others.
class SlotServer {
  public:
    static constexpr uint32_t k_window = 512;

    // The first cycle >= ready from which `occupancy` cycles are free; books them.
    uint64_t book(uint64_t ready, uint32_t occupancy = 1) {
        // The common case, a free bank inside the window, without the general search.
        if (occupancy == 1 && ready >= m_base && ready < m_base + k_window) {
            const uint64_t offset = ready - m_base;
            uint64_t& word = m_bits[(m_head + offset / 64) % k_words];
            const uint64_t bit = uint64_t(1) << (offset % 64);
            if (!(word & bit)) {
                word |= bit;
                return ready;
            }
        }
        return book_slow(ready, occupancy);
    }

  private:
    uint64_t book_slow(uint64_t ready, uint32_t occupancy);
    bool is_free(uint64_t cycle) const;
    void mark(uint64_t cycle);
    void slide_to(uint64_t last);  // moves the window forward until `last` lies in it

    static constexpr uint32_t k_words = k_window / 64;
    uint64_t m_base = 0;  // first cycle of the window, a multiple of 64
    uint32_t m_head = 0;  // ring index of the word holding m_base
    std::array<uint64_t, k_words> m_bits{};
};

// A pool with a capacity per cycle (the address-generation units: addresses per cycle; the
// interconnect: words per core cycle). Work takes what each cycle has left from the cycle it is
// ready, so a later request may use capacity an earlier-booked one left free. Bookings are kept
// per cycle in a window of k_window cycles, like SlotServer's.
class CapacityServer {
  public:
    static constexpr uint32_t k_window = 1024;
    explicit CapacityServer(double per_cycle) : m_per_cycle(per_cycle) { m_used.fill(0.0); }

    // Serves `amount` from cycle `ready` on; returns the cycle in which its last part is served
    // (it is usable from the next one). Zero work returns `ready`.
    uint64_t serve(uint64_t ready, double amount);
    double per_cycle() const { return m_per_cycle; }
    double work() const { return m_work; }

  private:
    void slide_to(uint64_t cycle);
    double& used(uint64_t cycle) { return m_used[(m_head + (cycle - m_base)) % k_window]; }

    double m_per_cycle;
    uint64_t m_base = 0;
    uint32_t m_head = 0;
    std::array<double, k_window> m_used;
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
