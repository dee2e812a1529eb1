// The shared resources of the machine model against plain reference implementations.

#include "hw_model/machine_resources.h"

#include <catch2/catch.hpp>
#include <random>
#include <set>

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

TEST_CASE("slot server books exactly the cycles a never-forgetting bank would", "[machine]") {
    for (const uint32_t occupancy_max : {1u, 3u}) {
        std::mt19937 rng(7 + occupancy_max);
        SlotServer bank;
        ReferenceBank reference;
        uint64_t now = 0, max_backlog = 0;
        // Requests arrive near `now` (up to 100 cycles ahead), which moves forward at about the
        // rate the bank serves them, so bursts queue and the window slides many times.
        for (int i = 0; i < 20000; ++i) {
            const uint32_t occupancy = 1 + rng() % occupancy_max;
            const uint64_t ready = now + rng() % 100;
            const uint64_t got = reference.book(ready, occupancy);
            REQUIRE(bank.book(ready, occupancy) == got);
            max_backlog = std::max(max_backlog, got - now);
            now += rng() % (2 * occupancy_max + 1);
        }
        // The comparison means something only if bookings queued and the window moved on.
        CHECK(max_backlog > 100);
        CHECK(now > 20 * SlotServer::k_window);
        // The precondition of exactness: nothing still wanted fell out of the window.
        REQUIRE(max_backlog < SlotServer::k_window - 64);
    }
}

TEST_CASE("slot server jumps far ahead and never books a forgotten cycle", "[machine]") {
    SlotServer bank;
    CHECK(bank.book(5) == 5);
    CHECK(bank.book(5) == 6);
    CHECK(bank.book(1000000) == 1000000);  // the window moves; cycle 5 is forgotten
    CHECK(bank.book(1000000) == 1000001);
    CHECK(bank.book(3) >= 1000000 - SlotServer::k_window);  // before the window: never reused
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
