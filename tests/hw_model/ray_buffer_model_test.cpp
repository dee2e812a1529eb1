// Exact costs of crafted accesses in the ray-buffer, address and partition arithmetic.

#include <catch2/catch.hpp>
#include <numeric>
#include <vector>

#include "hw_model/ray_buffer_model.h"

using namespace sfx;

TEST_CASE("Gathers: distinct banks cost one issue, one bank serialises every lane",
          "[hw_model]") {
    RayBufferConfig c;  // 32 banks, 2-cycle pipelined
    const RayBufferModel buffer(c, 24, 4096);
    std::vector<uint32_t> spread(16);
    std::iota(spread.begin(), spread.end(), 0u);  // consecutive slots: consecutive banks
    const auto clean = buffer.access_field(3, spread.data(), 16);
    CHECK(clean.cycles == 1);  // one issue; the fill is paid once per chain
    CHECK(buffer.fill_cycles() == 1);
    CHECK(clean.conflict_cycles == 0);

    for (uint32_t n : {2u, 8u, 16u}) {
        std::vector<uint32_t> same(n);
        for (uint32_t i = 0; i < n; ++i) same[i] = i * 32;  // every slot in bank 0
        const auto hot = buffer.access_field(3, same.data(), n);
        CHECK(hot.cycles == n);  // a stream whose ids all hit one bank costs n cycles
        CHECK(hot.conflict_cycles == n - 1);
    }

    c.pipelined = false;  // each access occupies its bank for the whole latency
    const RayBufferModel slow(c, 24, 4096);
    std::vector<uint32_t> two = {0, 32};
    CHECK(slow.access_field(0, two.data(), 2).cycles == 4);
    CHECK(slow.access_field(0, spread.data(), 16).cycles == 2);
    CHECK(slow.fill_cycles() == 0);

    // More lanes than banks: two requests per bank are not a conflict.
    std::vector<uint32_t> wide(64);
    std::iota(wide.begin(), wide.end(), 0u);
    CHECK(buffer.access_field(0, wide.data(), 64).conflict_cycles == 0);
}

TEST_CASE("Contiguous streams: widths that do not divide the line stall", "[hw_model]") {
    RayBufferConfig c;
    c.line_words = 16;
    const RayBufferModel buffer(c, 24, 4096);
    auto stream_stalls = [&](uint32_t width, uint32_t length) {
        uint64_t stalls = 0;
        for (uint64_t offset = 0; offset < length; offset += width)
            stalls += buffer.access_contiguous(offset, uint32_t(std::min<uint64_t>(width, length - offset)))
                          .alignment_cycles;
        return stalls;
    };
    CHECK(stream_stalls(16, 256) == 0);
    CHECK(stream_stalls(8, 256) == 16);   // every other group starts mid-line: 1 realign each
    // Width 12 groups start at 0, 12, 24, 36 (mod 48): 0 + 2 + 2 + 1 stall cycles per 4 groups.
    CHECK(stream_stalls(12, 48) == 5);
    CHECK(buffer.access_contiguous(4, 8).cycles == 2);  // in one line, but off its boundary
}

TEST_CASE("Partition: compare pass plus one write per moved id", "[hw_model]") {
    PartitionConfig c;
    c.comparators_per_lane = 1;  // width lanes per cycle
    const std::vector<uint8_t> sorted = {1, 1, 1, 0, 0};
    CHECK(partition_cost(c, 8, sorted.data(), 5).moved_ids == 0);
    CHECK(partition_cost(c, 8, sorted.data(), 5).cycles() == 1);
    const std::vector<uint8_t> mixed = {0, 1, 0, 1};  // stable: every id changes place
    CHECK(partition_cost(c, 2, mixed.data(), 4).moved_ids == 4);
    const std::vector<uint8_t> ends = {1, 0, 1, 0};  // the first and last ids stay
    const PartitionCost p = partition_cost(c, 1, ends.data(), 4);
    CHECK(p.moved_ids == 2);
    CHECK(p.move_cycles == 2);
    std::vector<uint8_t> long_mask(100, 1);
    CHECK(partition_cost(c, 16, long_mask.data(), 100).compare_cycles == 7);
}

TEST_CASE("Address generation: units times rate per cycle", "[hw_model]") {
    AguConfig a;
    a.count = 32;
    a.addresses_per_cycle = 1;
    CHECK(address_cycles(a, 0) == 0);
    CHECK(address_cycles(a, 32) == 1);
    CHECK(address_cycles(a, 33) == 2);
    a.addresses_per_cycle = 2;
    CHECK(address_cycles(a, 64) == 1);
}

TEST_CASE("Record layout: soa spreads consecutive slots, aos strides by the record size",
          "[hw_model]") {
    RayBufferConfig c;  // 32 banks
    std::vector<uint32_t> slots(16);
    std::iota(slots.begin(), slots.end(), 0u);
    const RayBufferModel soa(c, 24, 4096);
    c.layout = "aos";
    const RayBufferModel aos(c, 24, 4096);
    CHECK(soa.access_field(5, slots.data(), 16).conflict_cycles == 0);
    // 24-word records: slot * 24 mod 32 takes 4 values, so 16 slots queue 4 deep.
    CHECK(aos.access_field(5, slots.data(), 16).cycles == 4);
    CHECK(aos.access_fields(3, slots.data(), 16).conflict_cycles == 3 * 3);
    const RayBufferModel odd(c, 25, 4096);  // an odd record size spreads again
    CHECK(odd.access_field(0, slots.data(), 16).conflict_cycles == 0);
}

TEST_CASE("A field's banks are the slots' banks turned by the field's offset", "[hw_model]") {
    // Power-of-two and other bank counts, both layouts, slot counts that do and do not divide.
    for (const uint32_t banks : {32u, 12u, 64u}) {
        for (const char* layout : {"soa", "aos"}) {
            for (const uint32_t slot_count : {4096u, 1000u}) {
                RayBufferConfig c;
                c.banks = banks;
                c.layout = layout;
                const RayBufferModel buffer(c, 25, slot_count);
                INFO(banks << " banks, " << layout << ", " << slot_count << " slots");
                uint32_t wrong = 0;
                for (uint32_t word = 0; word < 25; ++word)
                    for (uint32_t slot = 0; slot < slot_count; slot += 7)
                        wrong += buffer.bank_of(word, slot) !=
                                 (buffer.slot_bank(slot) + buffer.field_rotation(word)) % banks;
                CHECK(wrong == 0);
            }
        }
    }
}
