#pragma once
// Arithmetic of the banked ray buffers, the address-generation units and the partition unit,
// in plain classes that tests exercise without a SystemC kernel (the SystemC modules wrap them).
//
// Layout: words are interleaved across banks word by word. With `soa` records (the paper's
// ray streams), field word w of slot s lives at word w * capacity + s, so the same field of
// consecutive slots sits in consecutive banks; with `aos` records it lives at
// s * record_words + w. A gather of one field word for a group of lanes costs as many cycles
// as the busiest bank has requests (one access per bank per cycle when pipelined;
// access_latency cycles each when not), plus the pipeline fill once per chain.

#include <cstdint>
#include <vector>

#include "hw_model/hw_config.h"
#include "kernels/trace.h"

namespace sfx {

// Ray slots in one buffer of `config` for records of `record_bytes`; never fewer than a pass's
// `pass_slots` (a tile's rays always have their slots).
uint32_t buffer_slots(const RayBufferConfig& config, uint32_t record_bytes, uint32_t pass_slots);

class RayBufferModel {
public:
    RayBufferModel(const RayBufferConfig& config, uint32_t record_words, uint32_t slot_count);

    uint32_t bank_of(uint32_t field_word, uint32_t slot) const {
        const uint64_t word = m_aos ? uint64_t(slot) * m_record_words + field_word
                                    : uint64_t(field_word) * m_slot_count + slot;
        return bank_mod(word);
    }
    // bank_of(field_word, slot) == (slot_bank(slot) + field_rotation(field_word)) % banks(): a
    // word's address is a slot's part plus a field's, so one field's lanes fall in the slots'
    // banks turned by the field's offset.
    uint32_t slot_bank(uint32_t slot) const {
        return bank_mod(m_aos ? uint64_t(slot) * m_record_words : uint64_t(slot));
    }
    uint32_t field_rotation(uint32_t field_word) const {
        return bank_mod(m_aos ? uint64_t(field_word) : uint64_t(field_word) * m_slot_count);
    }

    // Issue cycles to access one field word of each lane's slot (a gather or a scatter of one
    // field), and how many of those cycles are bank-conflict stalls (beyond the conflict-free
    // ceil(lanes / banks)). The pipeline fill is not included: see fill_cycles().
    struct Access {
        uint64_t cycles = 0;
        uint64_t conflict_cycles = 0;
    };
    Access access_field(uint32_t field_word, const uint32_t* slots, uint32_t lanes) const;
    // The same for `words` field words of the same lanes, one after another. In both layouts a
    // field word's banks are the first word's shifted by a constant (mod banks), so every word
    // costs what the first does: computed once, exactly.
    Access access_fields(uint32_t words, const uint32_t* slots, uint32_t lanes) const {
        if (words == 0) return {};
        Access a = access_field(0, slots, lanes);
        a.cycles *= words;
        a.conflict_cycles *= words;
        return a;
    }

    // Contiguous read of `lanes` words starting at word `offset` of a line-organised stream
    // (the ray-id stream): one line per cycle; a run that straddles lines or starts off a line
    // boundary stalls (the SIMD alignment overhead of the paper's widths 8 and 12).
    struct Contiguous {
        uint64_t cycles = 0;
        uint64_t alignment_cycles = 0;
    };
    Contiguous access_contiguous(uint64_t offset, uint32_t lanes) const;

    // Latency a chain of pipelined accesses pays once (zero when accesses do not overlap,
    // since each already occupies its bank for the whole latency).
    uint32_t fill_cycles() const { return m_pipelined ? m_latency - 1 : 0; }
    uint32_t banks() const { return m_banks; }
    uint32_t latency() const { return m_latency; }
    bool pipelined() const { return m_pipelined; }
    uint32_t line_words() const { return m_line_words; }

private:
    uint32_t bank_mod(uint64_t word) const {
        return m_bank_mask ? uint32_t(word & m_bank_mask) : uint32_t(word % m_banks);
    }

    uint32_t m_banks, m_line_words, m_latency, m_slot_count, m_record_words;
    uint32_t m_bank_mask = 0;  // banks - 1 when banks is a power of two: no division per lane
    int32_t m_line_shift = -1;  // log2(line_words) when it is a power of two, else -1
    bool m_pipelined, m_aos;
    mutable std::vector<uint16_t> m_per_bank;  // scratch: zero between calls
};

// Address generation: `count` units, each computing `addresses_per_cycle` addresses per cycle.
// Address work runs beside the data path; only its excess over the data work stalls.
inline uint64_t address_cycles(const AguConfig& agu, uint64_t addresses) {
    const uint64_t per_cycle = uint64_t(agu.count) * agu.addresses_per_cycle;
    return (addresses + per_cycle - 1) / per_cycle;
}

// In-place partition of a stream by its mask (SIMD comparators, Sec. 3.3): the comparator pass
// compares width * comparators_per_lane mask lanes per cycle; then every id that must move (a passing id
// behind a failing one, in a stable partition) is written once, `width` ids per cycle.
struct PartitionCost {
    uint64_t compare_cycles = 0;
    uint64_t moved_ids = 0;
    uint64_t move_cycles = 0;
    uint64_t cycles() const { return compare_cycles + move_cycles; }
};
PartitionCost partition_cost(const PartitionConfig& config, uint32_t width, const uint8_t* passed,
                             uint32_t length);
// The same from the number of ids a stable partition moves, which no configuration changes
// (a pass buffer computes it once per operation for every configuration).
PartitionCost partition_cost(const PartitionConfig& config, uint32_t width, uint32_t length,
                             uint32_t moved_ids);
uint32_t stable_partition_moves(const uint8_t* passed, uint32_t length);

// Ray buffers in a CPU core's L1D (storage l1d): the share of `slots` slots of `slot_bytes`
// that a cache of `cache_kib` (the L1D, or the L2 behind it) cannot hold; a random lane misses
// it with that probability.
double beyond_cache_fraction(uint32_t slots, uint32_t slot_bytes, uint32_t cache_kib);
// The hardware prefetchers follow a stream of ascending loads within a 4 KiB page and stop
// at its end ("Does not prefetch across 4K boundary": Intel's Optimization Reference Manual,
// the streamer; AMD's guides say only that theirs fetch lines in ascending or descending
// order, so the same page is assumed there, not documented): a lane
// whose slot starts in another page than the lane before it's (a stream's slots ascend) waits
// for its line, and the lanes after it in that page find theirs prefetched.
constexpr uint32_t k_prefetch_page_bytes = 4096;
// The line the caches move a ray buffer's bytes in: 64 bytes on every host described so far
// (sysfs cache/index*/coherency_line_size, the host files' line_bytes).
constexpr uint64_t k_ray_line_bytes = 64;
// Whether lane i of a stream of `slots` (ascending) opens a page of an array of `lane_bytes` a
// slot: its slot starts in another page than the slot before it's (the stream's first lane
// does).
inline bool lane_opens_page(const uint32_t* slots, uint32_t i, uint32_t lane_bytes) {
    auto page = [&](uint32_t j) { return uint64_t(slots[j]) * lane_bytes / k_prefetch_page_bytes; };
    return i == 0 || page(i) != page(i - 1);
}
// Whether lane i of such a stream, in a page the lane before opened, skips lines: its slot's
// first line lies beyond the line after the lane before's last one, where a next-line prefetch
// of the lane before's lines does not reach.
inline bool lane_skips_lines(const uint32_t* slots, uint32_t i, uint32_t lane_bytes) {
    if (i == 0) return false;
    const uint64_t first = uint64_t(slots[i]) * lane_bytes / k_ray_line_bytes;
    const uint64_t before_last =
        (uint64_t(slots[i - 1]) * lane_bytes + lane_bytes - 1) / k_ray_line_bytes;
    return first > before_last + 1;
}
// How many of the lanes [first, first + lanes) open one (lane_opens_page).
uint32_t lanes_opening_pages(const uint32_t* slots, uint32_t first, uint32_t lanes,
                             uint32_t lane_bytes);
// The same expected of a stream of `lanes` slots drawn at random from `slots` (the pages the
// stream touches: each page's share untouched is hypergeometric).
double expected_lanes_opening_pages(uint32_t lanes, uint32_t slots, uint32_t lane_bytes);
// The bytes of its slot a lane of an op of `stage` reads on a CPU core (the native tracer's
// per-slot arrays, kernels/stream/stream_tracer.cpp): a traversal or intersection op its
// traversal record (16 floats, one line: traversal_field in kernels/stream/stream_kernels.h,
// which sweeps/host_calibration.cpp checks), a shading op the rest of its slot (`slot_bytes`
// less that record, which is the traversal's array: of the shading stage only the set-up of
// the rays an op makes writes it, CoreModel::touch_ray_lines; until 2026-11-29 a shading lane
// read its whole slot in an address range of its own, so a frame's ray lines held each record
// twice: a small part of why the model prices 64-pixel tiles 3-7 points dearer against
// smaller ones than the host runs them; a slot no bigger than a record is read whole). Its
// pages are those of that array.
constexpr uint32_t k_traversal_record_bytes = 64;
uint32_t lane_ray_bytes(OpStage stage, uint32_t slot_bytes);
// The bytes a slot holds in each array a lane of `stage` reads, as the page geometry above
// sees them (lane_opens_page): a traversal record is one array; a shading lane's bytes
// (lane_ray_bytes) lie in `slot_arrays` arrays of the native tracer's structure of arrays
// (RayBufferConfig::slot_arrays), taken as of equal size. A lane then opens a page of one
// array about as often as it opens a page of each, and pays beyond_l1_per_lane_cycles, which
// the microbenchmarks' sparse lanes (a new page of every array) fix, where that happens. On an
// AMD Zen 5 VM (2026-12-02), priced as one array of its 266 bytes, a frame's dense shading
// streams paid a sparse lane's cost at every 15th lane: cornell's shading at tile 32 came out
// 3-4 % over tile 16's where the host ran it no dearer, and its tile ranking upside down.
uint32_t lane_page_bytes(OpStage stage, uint32_t slot_bytes, uint32_t slot_arrays);
// A random stream's share of lanes that pay for ray data beyond the L1D (or, with the L2's
// `cache_kib`, beyond the L2 as well), as the op costs' fit
// prices its microbenchmarks: those opening a page of an array of `lane_bytes` a slot the op
// reads (lane_page_bytes; expected), times beyond_cache_fraction of the whole slots (`slot_bytes`:
// the microbenchmarks read every array of the buffer before they time, so the L1D holds a share of
// each). The cycle level asks its caches instead (CoreModel::touch_ray_lines). On this
// project's AMD host (2026-11-28) the dense streams of a frame paid nearly none of what its
// sparse microbenchmark streams did: priced by beyond_cache_fraction alone, cornell's 64 x 64
// frames came out 7-15 % over the measured.
double beyond_cache_share(uint32_t lanes, uint32_t slots, uint32_t slot_bytes, uint32_t lane_bytes,
                          uint32_t cache_kib);
// Of a stream of `lanes` slots drawn at random from `slots`, the lanes expected in a page the lane
// before opened that skip lines (lane_skips_lines): each lane's slot the lane before's d slots on
// with probability q (1 - q)^(d - 1), q = (lanes - 1) / (slots - 1). None of a stream of every
// slot; of a sparse one, nearly all of its few lanes in an opened page.
double expected_lanes_skipping_lines(uint32_t lanes, uint32_t slots, uint32_t lane_bytes);
// The same stream's share of lanes beyond the cache that skip lines in a page the lane before
// opened (beyond_cache_fraction's lanes: beyond_l1_skipping_per_lane_cycles).
double beyond_cache_skipping_share(uint32_t lanes, uint32_t slots, uint32_t slot_bytes,
                                   uint32_t lane_bytes, uint32_t cache_kib);
// The share of a pass's `slots` slots (of `slot_bytes` each, every array of the buffer) beyond
// the reach of a first-level DTLB of `dtlb_pages` 4 KiB pages, as beyond_cache_fraction prices a
// cache of that size: a lane that opens a page of its array there misses the DTLB whether or
// not the L1D holds its line (RayBufferConfig::dtlb_pages; 0: none beyond).
double beyond_tlb_fraction(uint32_t slots, uint32_t slot_bytes, uint32_t dtlb_pages);
// A random stream's share of lanes that open a page beyond that reach, as the op costs' fit
// prices its microbenchmarks (beyond_tlb_per_lane_cycles): the expected lanes opening a page
// of an array of `lane_bytes` a slot (lane_page_bytes) times beyond_tlb_fraction. The cycle
// level counts the lanes that open a page instead (CoreModel::touch_ray_lines).
double beyond_tlb_share(uint32_t lanes, uint32_t slots, uint32_t slot_bytes, uint32_t lane_bytes,
                        uint32_t dtlb_pages);
// A slot's bytes in a configuration's buffer: ray_buffer.slot_bytes (the native tracer's, on
// a host), else the scene's ray record (`record_bytes`).
uint32_t slot_bytes_of(const RayBufferConfig& buffer, uint32_t record_bytes);
// lane_page_bytes of a configuration's buffer (slot_bytes_of, ray_buffer.slot_arrays).
uint32_t lane_page_bytes_of(const RayBufferConfig& buffer, uint32_t record_bytes, OpStage stage);
// The closed form's share of a pass's `slots` slots beyond an l1d buffer for an op of `stage`:
// beyond_cache_fraction of the array it reads (lane_ray_bytes of slot_bytes_of), as if that array
// alone filled the L1D (or, given `cache_kib`, that cache: the L2 behind it); 0 for banked
// buffers.
double slots_beyond_cache(const RayBufferConfig& buffer, uint32_t record_bytes, uint32_t slots,
                          OpStage stage, uint32_t cache_kib = 0);

}  // namespace sfx
