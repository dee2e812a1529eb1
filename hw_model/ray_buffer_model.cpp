#include "hw_model/ray_buffer_model.h"

#include <algorithm>
#include <stdexcept>
#include <string_view>

namespace sfx {

uint32_t buffer_slots(const RayBufferConfig& config, uint32_t record_bytes, uint32_t pass_slots) {
    return std::max(uint32_t(uint64_t(config.kib) * 1024 / record_bytes), pass_slots);
}

RayBufferModel::RayBufferModel(const RayBufferConfig& config, uint32_t record_words,
                               uint32_t slot_count)
    : m_banks(config.banks), m_line_words(config.line_words),
      m_latency(config.access_latency_cycles), m_slot_count(slot_count),
      m_record_words(record_words), m_pipelined(config.pipelined), m_aos(config.layout == "aos"),
      m_per_bank(config.banks) {
    if (m_banks == 0 || m_line_words == 0 || m_latency == 0)
        throw std::invalid_argument("ray buffer: banks, line_words and latency must be >= 1");
    if ((m_banks & (m_banks - 1)) == 0) m_bank_mask = m_banks - 1;
    if ((m_line_words & (m_line_words - 1)) == 0) {
        m_line_shift = 0;
        while ((1u << m_line_shift) < m_line_words) ++m_line_shift;
    }
}

RayBufferModel::Access RayBufferModel::access_field(uint32_t field_word, const uint32_t* slots,
                                                    uint32_t lanes) const {
    Access a;
    if (lanes == 0) return a;
    uint32_t busiest = 0;
    for (uint32_t i = 0; i < lanes; ++i)
        busiest = std::max<uint32_t>(busiest, ++m_per_bank[bank_of(field_word, slots[i])]);
    for (uint32_t i = 0; i < lanes; ++i) m_per_bank[bank_of(field_word, slots[i])] = 0;
    // Even without conflicts a bank serves ceil(lanes / banks) requests.
    const uint32_t needed = (lanes + m_banks - 1) / m_banks;
    const uint32_t per_request = m_pipelined ? 1 : m_latency;
    a.cycles = uint64_t(busiest) * per_request;
    a.conflict_cycles = uint64_t(busiest - needed) * per_request;
    return a;
}

RayBufferModel::Contiguous RayBufferModel::access_contiguous(uint64_t offset,
                                                              uint32_t lanes) const {
    Contiguous c;
    if (lanes == 0) return c;
    // Per lane group of every op: shifts, not divisions, for lines of a power of two words.
    auto line_of = [&](uint64_t word) {
        return m_line_shift >= 0 ? word >> m_line_shift : word / m_line_words;
    };
    const uint64_t first = line_of(offset), last = line_of(offset + lanes - 1);
    const uint64_t lines = last - first + 1;
    const uint64_t ideal = line_of(lanes + m_line_words - 1);
    const uint64_t realign = first * m_line_words != offset ? 1 : 0;  // shift through the mux tree
    c.cycles = lines + realign;
    c.alignment_cycles = c.cycles - ideal;
    return c;
}

uint32_t stable_partition_moves(const uint8_t* passed, uint32_t length) {
    uint32_t pass_count = 0;
    for (uint32_t i = 0; i < length; ++i) pass_count += passed[i] ? 1 : 0;
    uint32_t next_pass = 0, next_fail = pass_count, moved = 0;
    for (uint32_t i = 0; i < length; ++i) {
        const uint32_t to = passed[i] ? next_pass++ : next_fail++;
        moved += to != i;
    }
    return moved;
}

PartitionCost partition_cost(const PartitionConfig& config, uint32_t width, uint32_t length,
                             uint32_t moved_ids) {
    PartitionCost p;
    p.moved_ids = moved_ids;
    // Compress: the SIMD unit wrote each group's ids as it executed it (OpCostTable counts
    // those instructions); nothing is left for a partition pass.
    if (std::string_view(config.kind) == "compress") return p;  // per op: no strlen, no call
    const uint64_t per_cycle = uint64_t(width) * config.comparators_per_lane;
    p.compare_cycles = (uint64_t(length) + per_cycle - 1) / per_cycle;
    p.moved_ids = moved_ids;
    p.move_cycles = (p.moved_ids + width - 1) / width;
    return p;
}

PartitionCost partition_cost(const PartitionConfig& config, uint32_t width, const uint8_t* passed,
                             uint32_t length) {
    return partition_cost(config, width, length, stable_partition_moves(passed, length));
}

double beyond_cache_fraction(uint32_t slots, uint32_t slot_bytes, uint32_t cache_kib) {
    const double bytes = double(slots) * slot_bytes;
    return bytes <= 0 ? 0.0 : std::max(0.0, 1.0 - double(cache_kib) * 1024.0 / bytes);
}

uint32_t lanes_opening_pages(const uint32_t* slots, uint32_t first, uint32_t lanes,
                             uint32_t lane_bytes) {
    uint32_t opening = 0;
    for (uint32_t i = first; i < first + lanes; ++i) opening += lane_opens_page(slots, i, lane_bytes);
    return opening;
}

double expected_lanes_opening_pages(uint32_t lanes, uint32_t slots, uint32_t lane_bytes) {
    lanes = std::min(lanes, slots);
    if (lanes == 0 || lane_bytes == 0) return 0.0;
    double pages = 0.0;
    for (uint32_t s = 0; s < slots;) {
        // The slots starting in s's page: untouched with probability C(slots - k, lanes) /
        // C(slots, lanes).
        const uint64_t page = uint64_t(s) * lane_bytes / k_prefetch_page_bytes;
        uint32_t k = 0;
        while (s + k < slots && uint64_t(s + k) * lane_bytes / k_prefetch_page_bytes == page) ++k;
        double untouched = 1.0;
        for (uint32_t j = 0; j < k && untouched > 0.0; ++j)
            untouched *= std::max(0.0, double(slots) - lanes - j) / double(slots - j);
        pages += 1.0 - untouched;
        s += k;
    }
    return pages;
}

uint32_t lane_ray_bytes(OpStage stage, uint32_t slot_bytes) {
    if (stage != OpStage::shading) return k_traversal_record_bytes;
    return slot_bytes > k_traversal_record_bytes ? slot_bytes - k_traversal_record_bytes
                                                 : slot_bytes;
}

uint32_t lane_page_bytes(OpStage stage, uint32_t slot_bytes, uint32_t slot_arrays) {
    const uint32_t bytes = lane_ray_bytes(stage, slot_bytes);
    if (stage != OpStage::shading || slot_arrays <= 1) return bytes;
    return std::max(1u, bytes / slot_arrays);
}

double beyond_cache_share(uint32_t lanes, uint32_t slots, uint32_t slot_bytes, uint32_t lane_bytes,
                          uint32_t cache_kib) {
    if (lanes == 0) return 0.0;
    return beyond_cache_fraction(slots, slot_bytes, cache_kib) *
           expected_lanes_opening_pages(lanes, slots, lane_bytes) / double(std::min(lanes, slots));
}

double beyond_tlb_fraction(uint32_t slots, uint32_t slot_bytes, uint32_t dtlb_pages) {
    return dtlb_pages == 0 ? 0.0 : beyond_cache_fraction(slots, slot_bytes, dtlb_pages * 4);
}

double beyond_tlb_share(uint32_t lanes, uint32_t slots, uint32_t slot_bytes, uint32_t lane_bytes,
                        uint32_t dtlb_pages) {
    // A cache of the reach's size would put the same lanes beyond it (0 pages: none, where a
    // cache of 0 KiB would put them all).
    return dtlb_pages == 0
               ? 0.0
               : beyond_cache_share(lanes, slots, slot_bytes, lane_bytes, dtlb_pages * 4);
}

double expected_lanes_skipping_lines(uint32_t lanes, uint32_t slots, uint32_t lane_bytes) {
    lanes = std::min(lanes, slots);
    if (lanes < 2 || lane_bytes == 0) return 0.0;
    const double q = double(lanes - 1) / double(slots - 1);
    double skipping = 0.0;  // over the slots, the chance that the lane before skips to it
    for (uint32_t s = 1; s < slots; ++s) {
        const uint64_t page = uint64_t(s) * lane_bytes / k_prefetch_page_bytes;
        double gap = q;  // the lane before d slots back
        for (uint32_t d = 1; d <= s && gap > 1e-9; ++d, gap *= 1.0 - q) {
            const uint32_t pair[2] = {s - d, s};
            if (uint64_t(pair[0]) * lane_bytes / k_prefetch_page_bytes != page) break;
            if (lane_skips_lines(pair, 1, lane_bytes)) skipping += gap;
        }
    }
    return skipping * double(lanes) / double(slots);
}

double beyond_cache_skipping_share(uint32_t lanes, uint32_t slots, uint32_t slot_bytes,
                                   uint32_t lane_bytes, uint32_t cache_kib) {
    if (lanes == 0) return 0.0;
    return beyond_cache_fraction(slots, slot_bytes, cache_kib) *
           expected_lanes_skipping_lines(lanes, slots, lane_bytes) / double(std::min(lanes, slots));
}

uint32_t slot_bytes_of(const RayBufferConfig& buffer, uint32_t record_bytes) {
    return buffer.slot_bytes ? buffer.slot_bytes : record_bytes;
}

uint32_t lane_page_bytes_of(const RayBufferConfig& buffer, uint32_t record_bytes, OpStage stage) {
    return lane_page_bytes(stage, slot_bytes_of(buffer, record_bytes), buffer.slot_arrays);
}

double slots_beyond_cache(const RayBufferConfig& buffer, uint32_t record_bytes, uint32_t slots,
                          OpStage stage, uint32_t cache_kib) {
    if (buffer.storage != "l1d") return 0.0;
    return beyond_cache_fraction(slots, lane_ray_bytes(stage, slot_bytes_of(buffer, record_bytes)),
                                 cache_kib ? cache_kib : buffer.kib);
}

}  // namespace sfx
