// The shared resources of the machine model against plain reference implementations.

#include "hw_model/machine_resources.h"

#include <catch2/catch.hpp>
#include <random>
#include <set>
#include <vector>

using namespace sfx;

namespace {

// A bank that never forgets: the first run of `occupancy` free cycles at or after `ready`.
struct ReferenceBank {
    std::set<uint64_t> booked;
    uint64_t book(uint64_t ready, uint32_t occupancy) {
        for (uint64_t cycle = ready;; ++cycle) {
            uint32_t run = 0;
            while (run < occupancy && !booked.count(cycle + run)) ++run;
            if (run < occupancy) continue;
            for (uint32_t i = 0; i < occupancy; ++i) booked.insert(cycle + i);
            return cycle;
        }
    }
};

}  // namespace

TEST_CASE("bank schedule grants a SIMD access's lanes as banks that never forget would",
          "[machine]") {
    // 32 and 64 banks take the one-word path; 100 the multi-word one. Lanes draw their banks from
    // a few, so several share a bank (up to 16 deep).
    for (const uint32_t bank_count : {32u, 64u, 100u}) {
        for (const uint32_t occupancy : {1u, 3u}) {
            std::mt19937 rng(bank_count * 10 + occupancy);
            BankSchedule schedule(bank_count, occupancy);
            std::vector<ReferenceBank> reference(bank_count);
            uint64_t now = 0, max_backlog = 0, shared = 0;
            for (int i = 0; i < 20000; ++i) {
                const uint32_t lanes = 1 + rng() % 16;
                const uint32_t spread = 1 + rng() % bank_count;  // banks the lanes draw from
                std::vector<uint32_t> banks(lanes);
                uint64_t expected = 0;
                const uint64_t ready = now + rng() % 100;
                std::vector<uint32_t> per_bank(bank_count, 0);
                for (uint32_t& b : banks) {
                    b = (uint32_t(rng()) % spread * 7) % bank_count;
                    shared += per_bank[b]++ > 0;
                    expected = std::max(expected, reference[b].book(ready, occupancy));
                }
                REQUIRE(schedule.book(banks.data(), lanes, ready) == expected);
                max_backlog = std::max(max_backlog, expected - now);
                now += rng() % (4 * occupancy + 1);
            }
            // The comparison means something only if lanes shared banks, bookings queued and
            // the window moved on many times.
            CHECK(shared > 10000);
            CHECK(max_backlog > 100);
            CHECK(now > 20 * BankSchedule::k_window);
            // The precondition of exactness: nothing still wanted fell out of the window.
            REQUIRE(max_backlog < BankSchedule::k_window);
        }
    }
}

TEST_CASE("bank schedule books lanes turned by a rotation as the turned banks", "[machine]") {
    for (const uint32_t bank_count : {32u, 24u, 64u, 100u}) {
        for (const uint32_t occupancy : {1u, 2u}) {
            std::mt19937 rng(bank_count + occupancy);
            BankSchedule turned(bank_count, occupancy), plain(bank_count, occupancy);
            uint64_t now = 0;
            for (int i = 0; i < 5000; ++i) {
                const uint32_t lanes = 1 + rng() % 16;
                std::vector<uint32_t> banks(lanes), rotated(lanes);
                for (uint32_t& b : banks) b = uint32_t(rng()) % (1 + rng() % bank_count);
                turned.set_lanes(banks.data(), lanes);
                // Several words of one group: the lanes set once, each word at its rotation.
                for (int w = 0; w < 3; ++w) {
                    const uint32_t rotation = uint32_t(rng()) % bank_count;
                    for (uint32_t l = 0; l < lanes; ++l)
                        rotated[l] = (banks[l] + rotation) % bank_count;
                    const uint64_t ready = now + rng() % 50;
                    REQUIRE(turned.book_lanes(rotation, ready) ==
                            plain.book(rotated.data(), lanes, ready));
                }
                now += rng() % (6 * occupancy);
            }
        }
    }
}

TEST_CASE("bank schedule queues lanes of one bank and never books a forgotten cycle",
          "[machine]") {
    BankSchedule schedule(32, 1);
    const uint32_t three[] = {3, 3, 3}, pair[] = {3, 4};
    CHECK(schedule.book(three, 3, 10) == 12);  // cycles 10, 11, 12
    CHECK(schedule.book(pair, 2, 10) == 13);   // bank 4 at 10, bank 3 next free at 13
    CHECK(schedule.book(pair, 0, 7) == 7);     // no request: its ready cycle
    CHECK(schedule.book(pair, 1, 1000000) == 1000000);  // the window moves; cycle 10 is forgotten
    CHECK(schedule.book(pair, 1, 1000000) == 1000001);
    CHECK(schedule.book(pair, 1, 5) >= 1000000 - BankSchedule::k_window);  // never reused
}

TEST_CASE("capacity server fills each cycle's capacity in order", "[machine]") {
    CapacityServer agus(32.0);
    CHECK(agus.serve(10, 16.0) == 10);  // half a cycle's capacity
    CHECK(agus.serve(10, 32.0) == 11);  // the other half of cycle 10, then half of 11
    CHECK(agus.serve(10, 0.0) == 10);   // zero work returns its ready cycle
    CHECK(agus.serve(10, 16.0) == 11);  // the rest of cycle 11
    CHECK(agus.serve(10, 1.0) == 12);
    CHECK(agus.work() == Approx(65.0));
}
