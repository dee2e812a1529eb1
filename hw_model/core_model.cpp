#include "hw_model/core_model.h"

#include <algorithm>
#include <cmath>

namespace sfx {
namespace {

uint64_t ceil_cycle(double t) {
    return uint64_t(std::ceil(t - 1e-9));
}

// Cycles a bank is held by one access: one when pipelined, else the whole access latency.
uint32_t bank_occupancy(const RayBufferConfig& c) {
    return c.pipelined ? 1 : c.access_latency_cycles;
}

uint64_t overlap(uint64_t a0, uint64_t a1, uint64_t b0, uint64_t b1) {
    const uint64_t lo = std::max(a0, b0), hi = std::min(a1, b1);
    return hi > lo ? hi - lo : 0;
}

}  // namespace

CoreModel::CoreModel(const HwConfig& config, const OpCostTable& costs, const SceneDataMap& map,
                     uint32_t record_words, uint32_t slot_capacity, uint32_t core_index,
                     std::shared_ptr<SceneMemoryModel> scene_memory)
    : m_config(config),
      m_costs(costs),
      m_map(map),
      m_core(core_index),
      m_l1d(config.ray_buffer.storage == "l1d"),
      m_mesh_hits(config.scene_memory.hit_reads == "mesh"),
      m_record_bytes(record_words * 4),
      m_scene_hidden(scene_latency_in_costs(config)),
      m_hit_read_hidden(hit_read_latency_hidden(config)),
      m_layout(config.ray_buffer, record_words, slot_capacity),
      m_banks{BankSchedule(config.ray_buffer.banks, bank_occupancy(config.ray_buffer)),
              BankSchedule(config.ray_buffer.banks, bank_occupancy(config.ray_buffer))},
      m_agu(double(config.agu.count) * config.agu.addresses_per_cycle),
      m_interconnect(double(config.interconnect.width_words) * config.clock.interconnect_mhz /
                     config.clock.core_mhz),
      m_scratchpad(double(config.scratchpad.ports)),
      m_crossing_cycles(uint64_t(std::ceil(config.interconnect.mux_levels * config.clock.core_mhz /
                                               config.clock.interconnect_mhz -
                                           1e-9))),
      m_scene_memory(std::move(scene_memory)),
      m_unit_free(config.simd.units, 0),
      m_unit_carry(config.simd.units, 0.0),
      m_unit_stage(config.simd.units, 0) {
    if (config.branch_predictor.kind == "tage") m_predictor = std::make_unique<TagePredictor>();
}

const std::vector<uint8_t>& CoreModel::node_leaf() const {
    static const std::vector<uint8_t> unknown;
    return m_map.node_leaf ? *m_map.node_leaf : unknown;
}

void CoreModel::warm_branches(const PassBuffer& pass) {
    if (!m_predictor) return;
    std::vector<uint32_t> untimed;  // a pass in flight keeps its own counts
    replay_traversal_branches(pass, traversal_loops(pass, width()), width(), node_leaf(),
                              *m_predictor, untimed);
}

const OpProfile& CoreModel::profile(uint32_t op) const {
    return m_costs[m_pass->at(op).kind];
}

void CoreModel::begin_pass(const PassBuffer* pass, uint64_t now) {
    m_pass = pass;
    m_pass_start = now;
    m_beyond_tlb = m_l1d ? beyond_tlb_fraction(pass->pass().slot_count,
                                               slot_bytes_of(m_config.ray_buffer, m_record_bytes),
                                               m_config.ray_buffer.dtlb_pages)
                         : 0.0;
    const size_t n = pass->size();
    m_scene_ready.assign(n, 0);
    m_scene_arrival.assign(n, 0);
    m_scene_requested.assign(n, 0);
    m_group_scene_offset.assign(n, k_none);
    m_group_scene_ready.clear();
    m_group_lane_stall.clear();
    m_group_beyond_offset.assign(n, k_none);
    m_group_beyond_lanes.clear();
    m_groups_left.assign(n, 0);
    m_mispredicted_lanes.assign(n, 0);
    m_placed_by_sort.assign(n, 0);
    for (uint32_t i = 1; i < n; ++i)
        m_placed_by_sort[i] = m_costs[pass->at(i).kind].measured &&
                              placed_by_material_sort(pass->at(i).kind, pass->at(i - 1).kind);
    m_op_completion.assign(n, now);
    std::fill(m_unit_free.begin(), m_unit_free.end(), now);
    m_partition_free = std::max(m_partition_free, now);
    m_timing = FrameTiming();
    m_timing.passes = 1;
    m_loop = traversal_loops(*pass, width());
    m_enters_loop.assign(n, 0);
    for (uint32_t i = 0; i < n; ++i) {
        const int32_t producer = pass->producer(i);
        const TraversalLoop from = producer < 0 ? TraversalLoop::stream : m_loop[size_t(producer)];
        m_enters_loop[i] = pass->at(i).kind == OpKind::box_test && from == TraversalLoop::stream &&
                           m_loop[i] != TraversalLoop::stream;
    }
    m_mispredicted.assign(n, 0);
    if (m_predictor)
        replay_traversal_branches(*pass, m_loop, width(), node_leaf(), *m_predictor,
                                  m_mispredicted);
    else if (m_config.branch_predictor.kind == "unseen_ops")  // a frame's traversals: unseen
        for (uint32_t i = 0; i < n; ++i) m_mispredicted[i] = is_traversal_op(pass->at(i).kind);
    for (const uint32_t m : m_mispredicted) m_timing.branch_mispredictions += m;
}

void CoreModel::touch_ray_lines(uint32_t index, const StreamOp& op, uint64_t now) {
    // The ray buffers of a core whose buffers are its L1D (storage l1d: the native tracer's
    // RayBuffers, kernels/stream/stream_tracer.cpp) are read through the same caches as the
    // scene data, and evict it: each lane's lane_ray_bytes (a traversal record, one line, or
    // the rest of a slot). They lie in an address range of their own, far above any
    // scene's (SceneDataMap), slot after slot; a line the lane before touched last is not
    // touched again. A tile of 64 x 64 at 330 bytes a slot is 1.3 MiB, more than a Zen 5
    // core's L2.
    constexpr uint64_t k_records = uint64_t(1) << 44, k_slots = uint64_t(1) << 45;
    constexpr uint64_t k_line = k_ray_line_bytes;
    const bool record = op.stage != OpStage::shading;
    const uint64_t bytes =
        lane_ray_bytes(op.stage, slot_bytes_of(m_config.ray_buffer, m_record_bytes));
    const uint32_t page_bytes = lane_page_bytes_of(m_config.ray_buffer, m_record_bytes, op.stage);
    // A lane pays for its ray data beyond the L1D (beyond_l1_per_lane_cycles) where the caches
    // did not hold a line of it in the first level and it opens a 4 KiB page of its arrays, and
    // beyond_l2_per_lane_cycles as well where the second level did not hold one either (the
    // prefetchers bring the rest of a page's ascending lines: k_prefetch_page_bytes; a slot's
    // arrays: lane_page_bytes), and beyond_l1_skipping_per_lane_cycles where the first level
    // did not hold it in a page the lane before opened and it skips lines past the lane
    // before's (lane_skips_lines: a next-line prefetch does not bring them); and, where it opens
    // a page at all, beyond_tlb_per_lane_cycles for the pass's share of slots beyond the DTLB's
    // reach (m_beyond_tlb, the fit's beyond_tlb_share); counted per group. The
    // fit expects the same of its microbenchmarks (beyond_cache_share). A slot's traversal record:
    // what a box or leaf test reads, and a made ray's set-up writes.
    const auto record_address = [](uint32_t slot) {
        return k_records + uint64_t(slot) * k_traversal_record_bytes;
    };
    const uint32_t n = width();
    m_group_beyond_offset[index] = m_group_beyond_lanes.size();
    uint64_t last = ~uint64_t(0);  // the line touched last
    for (uint32_t i = 0; i < op.length; ++i) {
        if (i % n == 0) m_group_beyond_lanes.push_back({});
        const uint64_t address =
            record ? record_address(op.slots[i]) : k_slots + op.slots[i] * bytes;
        const uint64_t first_line = address / k_line, last_line = (address + bytes - 1) / k_line;
        const uint64_t from = first_line == last ? first_line + 1 : first_line;
        const uint32_t level =
            from <= last_line
                ? m_scene_memory->touch_other(m_core, from * k_line,
                                              uint32_t((last_line - from + 1) * k_line), now)
                : 0;
        const bool opens_page = lane_opens_page(op.slots, i, page_bytes);
        m_group_beyond_lanes.back().pages += opens_page;
        if (level > 0 && opens_page) {
            ++m_group_beyond_lanes.back().l1;
            m_group_beyond_lanes.back().l2 += level > 1;
        } else if (level > 0 && lane_skips_lines(op.slots, i, page_bytes)) {
            ++m_group_beyond_lanes.back().l1_skipping;
        }
        last = last_line;
    }
    // A ray an op makes is set up for the next traversal with the op (its cost holds the
    // set-up, kernels/stream/stream_microbench.h), which writes the slot's traversal record:
    // the record's line is the traversal's own (k_records), left in the caches for it.
    if (record || !op_info(op.kind).pushes_rays || !op.passed) return;
    for (uint32_t i = 0; i < op.length; ++i)
        if (op.passed[i])
            m_scene_memory->touch_other(m_core, record_address(op.slots[i]),
                                        k_traversal_record_bytes, now);
}

void CoreModel::dispatch_op(uint32_t index, uint64_t now) {
    const StreamOp op = m_pass->at(index);
    const OpProfile& p = m_costs[op.kind];
    // An op whose lanes the material sort placed does no work (placed_by_material_sort).
    if (m_l1d && op.slots && !m_placed_by_sort[index]) touch_ray_lines(index, op, now);
    const uint32_t n = width();
    const uint64_t groups = (uint64_t(op.length) + n - 1) / n;
    const uint64_t mix_before = m_timing.mix.total();
    m_groups_left[index] = uint32_t(groups);
    m_mispredicted_lanes[index] =
        p.measured
            ? mispredicted_lanes(op.pass_count, op.length,
                                 op.passed ? outcome_changes(op.passed, op.length) : op.length)
            : 0;
    StageTiming& stage = m_timing.stages[op.generation > 0][uint32_t(op.stage)];
    stage.ops += 1;
    stage.lanes += op.length;
    stage.groups += groups;
    // The op mix in Table 5's classes. G&R 4.1: "the integer operations required by address
    // fetch are subsumed by the load and store operations": a gathered word's address vector
    // is a load, a scattered word's a store.
    const bool fetches = p.scene_bytes && op.object != k_no_object;
    OpMix& mix = m_timing.mix;
    mix.load += groups * (1 + p.gather_words.size()) + (fetches ? 1 : 0);
    mix.compute += groups * p.compute_instructions;
    mix.scatter_gather += groups * p.gather_words.size();
    ActionCounts& act = m_timing.actions;  // ACTIONS: counted beside the timing (area_energy)
    if (p.partitions) {
        const PartitionCost part =
            partition_cost(m_config.partition, n, op.length, m_pass->moved_ids(index));
        mix.partition += part.compare_cycles;
        mix.store += part.move_cycles;
        act.partition_compares += op.length;  // ACTIONS: the moved ids are read and written
        act.partition_moves += part.moved_ids;
        act.bank_reads += part.moved_ids;
        act.bank_writes += part.moved_ids;
    }
    if (p.partitions) {
        // G&R Fig. 5: a group's mask is stored when any lane passed (`if (anytrue(mask))
        // store(mask_end, mask)`), for the partition to read.
        for (uint32_t first = 0; first < op.length; first += n) {
            const uint32_t lanes = std::min(n, op.length - first);
            mix.store += std::any_of(op.passed + first, op.passed + first + lanes,
                                     [](uint8_t v) { return v != 0; });
        }
    }
    if (p.lane_scene_reads && op.length > 0) {
        // Each lane's hit primitive, gathered from the scene: an address vector per word.
        mix.load += groups * p.lane_scene_words;
        mix.scatter_gather += groups * p.lane_scene_words;
        act.agu_addresses += uint64_t(op.length) * p.lane_scene_words;  // ACTIONS
    }
    if (p.pushes_rays) mix.store += (uint64_t(op.pass_count) + n - 1) / n;
    if (p.pushes_rays) act.bank_writes += op.pass_count;  // ACTIONS: next generation's ids
    if (is_option_kind(op.kind)) mix.option += mix.total() - mix_before;
}

void CoreModel::request_scene(uint32_t index, uint64_t now) {
    if (m_scene_requested[index]) return;  // prefetched: the earlier request stands
    m_scene_requested[index] = 1;
    m_scene_arrival[index] = now;
    const StreamOp op = m_pass->at(index);
    const OpProfile& p = m_costs[op.kind];
    const uint32_t* hits = m_pass->lane_hits(index);
    if (p.lane_scene_reads && hits && op.length > 0) {
        // Every lane's hit primitive, requested with the op (the address units run ahead of
        // the SIMD units, G&R 4.1; assumed: as soon as the op is dispatched); a group waits
        // for its slowest lane. A CPU core works through its lanes one after another and
        // leaves a measured share of their latency beyond an L2 hit exposed (its cost holds an
        // L1D hit; its prefetches cover an L2 hit, hit_read_latency_hidden): that share of
        // their sum is what a group adds.
        const uint32_t n = width();
        const double share = p.cost.hit_read_exposed_share;
        m_group_scene_offset[index] =
            m_l1d ? m_group_lane_stall.size() : m_group_scene_ready.size();
        SceneDataMap::Read reads[2];
        for (uint32_t first = 0; first < op.length; first += n) {
            uint64_t ready = now, beyond_l1 = 0;
            for (uint32_t i = first; i < std::min(op.length, first + n); ++i) {
                if (hits[i] == k_no_object) continue;
                if (m_l1d) {
                    beyond_l1 += hit_latency_beyond(*m_scene_memory, m_map, m_core, hits[i],
                                                    m_mesh_hits, now, m_hit_read_hidden);
                    continue;
                }
                const uint32_t count = m_map.hit_reads(hits[i], m_mesh_hits, reads);
                for (uint32_t r = 0; r < count; ++r)
                    ready = std::max(ready, m_scene_memory->read(m_core, reads[r].address,
                                                                 reads[r].bytes, now));
            }
            if (m_l1d)
                m_group_lane_stall.push_back(uint64_t(std::llround(share * double(beyond_l1))));
            else
                m_group_scene_ready.push_back(ready);
        }
    }
    if (!p.scene_bytes || op.object == k_no_object || op.length == 0 || m_placed_by_sort[index]) {
        m_scene_ready[index] = 0;
        return;
    }
    const uint64_t ready =
        m_scene_memory->read(m_core, m_map.address(op.kind, op.object), p.scene_bytes, now);
    m_scene_arrival[index] = ready;
    uint64_t exposed = ready > now + m_scene_hidden ? ready - now - m_scene_hidden : 0;
    if (m_l1d && op.kind == OpKind::box_test && m_loop[index] != TraversalLoop::stream)
        // A CPU core's short loops run ahead of a node's read to the next ones'
        // (OpCostConfig::node_read_exposed_share); its arrival still gates the right child's.
        exposed = uint64_t(std::llround(p.cost.node_read_exposed_share * double(exposed)));
    m_scene_ready[index] = now + exposed;
}

void CoreModel::request_child_scene(uint32_t producer, uint32_t consumer, uint64_t now) {
    const StreamOp parent = m_pass->at(producer), child = m_pass->at(consumer);
    const bool from_index = parent.kind == OpKind::box_test && child.kind == OpKind::box_test &&
                            child.object == left_child_index(parent.object);
    request_scene(consumer, from_index ? now : std::max(now, m_scene_arrival[producer]));
}

uint64_t CoreModel::book_words(uint32_t buffer, const std::vector<uint32_t>& words,
                               const uint32_t* slots, uint32_t lanes, uint64_t issue,
                               const std::vector<uint64_t>* ready_at, uint64_t& conflict_cycles,
                               uint64_t& address_cycles) {
    uint64_t last_grant = issue, at = issue;
    // Every word's lanes go to the slots' banks, turned by the word's offset.
    BankSchedule& banks = m_banks[buffer];
    m_lane_banks.resize(lanes);
    for (uint32_t i = 0; i < lanes; ++i) m_lane_banks[i] = m_layout.slot_bank(slots[i]);
    banks.set_lanes(m_lane_banks.data(), lanes);
    for (size_t w = 0; w < words.size(); ++w) {
        if (w > 0) at += 1;  // one word's requests leave the access side per cycle
        if (ready_at) {
            const uint64_t addresses = (*ready_at)[w];
            if (addresses > at) {
                if (w > 0) address_cycles += addresses - at;
                at = addresses;
            }
        }
        // A conflict delays this word; later words queue behind it in the same banks, so only
        // the growth of the last grant is charged, once, below.
        last_grant = std::max(last_grant, banks.book_lanes(m_layout.field_rotation(words[w]), at));
    }
    const uint32_t occupancy = bank_occupancy(m_config.ray_buffer);
    const uint64_t ideal =
        at + (uint64_t(lanes + m_layout.banks() - 1) / m_layout.banks() - 1) * occupancy;
    if (last_grant > ideal) conflict_cycles += last_grant - ideal;
    return last_grant;
}

uint64_t CoreModel::cross(uint64_t ready, uint64_t words, uint64_t& wait_cycles) {
    if (words == 0) return ready;
    // An idle interconnect moves them in ceil(words / rate) cycles.
    const uint64_t alone = ready + m_interconnect.idle_cycles(words) - 1;
    const uint64_t last =
        m_config.interconnect.contention ? m_interconnect.serve(ready, double(words)) : alone;
    if (last > alone) wait_cycles += last - alone;
    return last + 1 + m_crossing_cycles;
}

uint64_t CoreModel::fetch(GroupToken& t, uint64_t now) {
    const StreamOp op = m_pass->at(t.op);
    const OpProfile& p = m_costs[op.kind];
    const uint32_t* slots = op.slots + t.first;
    const uint32_t buffer = op.generation % 2;
    // The group's ids: a contiguous run of the id stream, one buffer line per cycle.
    const RayBufferModel::Contiguous ids = m_layout.access_contiguous(t.first, t.lanes);
    t.alignment = ids.alignment_cycles;
    const uint64_t ids_done = now + ids.cycles;
    const size_t gathers = p.gather_words.size();
    // ACTIONS: ids and gathered words out of the banks, their addresses and interconnect hops.
    ActionCounts& act = m_timing.actions;
    const uint64_t gathered = uint64_t(t.lanes) * gathers;
    act.bank_reads += t.lanes + gathered;
    act.agu_addresses += gathered;
    act.interconnect_word_hops += gathered * m_config.interconnect.mux_levels;
    act.busy_cycles[size_t(HwUnit::ray_buffer)] += ids.cycles + gathers;
    act.busy_cycles[size_t(HwUnit::agu)] += m_agu.idle_cycles(gathered);
    act.busy_cycles[size_t(HwUnit::interconnect)] += m_interconnect.idle_cycles(gathered);
    if (m_l1d) {
        // A CPU core: the lanes' loads are part of the op's measured cost, issued with it.
        t.data_ready = now;
        return now;
    }
    if (gathers == 0) {
        t.data_ready = ids_done;
        return ids_done;
    }
    // Addresses: one per gathered lane word, on the core's address-generation units, which
    // every SIMD unit's access side shares; a word's requests leave the cycle after its
    // addresses are done. What a busier pool adds over an idle one is address stall.
    std::vector<uint64_t>& ready_at = m_ready_at;
    ready_at.resize(gathers);
    for (size_t w = 0; w < gathers; ++w) ready_at[w] = m_agu.serve(ids_done, double(t.lanes)) + 1;
    const uint64_t alone = ids_done + m_agu.idle_cycles(t.lanes);  // the first word's
    if (ready_at[0] > alone) t.address += ready_at[0] - alone;
    const uint64_t first_issue = ready_at[0];
    const uint64_t last_grant = book_words(buffer, p.gather_words, slots, t.lanes, first_issue,
                                           &ready_at, t.conflict, t.address);
    const uint64_t out = last_grant + m_layout.latency();
    // The gathered words cross the interconnect as they leave the banks.
    const uint64_t arrival =
        cross(first_issue + m_layout.latency(), uint64_t(t.lanes) * gathers, t.interconnect);
    t.data_ready = std::max(out + m_crossing_cycles, arrival);
    m_timing.field_accesses += gathers;
    const uint64_t issue_done = first_issue + gathers;  // the last word's requests have left
    return std::max(issue_done, ids_done);
}

uint64_t CoreModel::scene_ready(const GroupToken& t) const {
    uint64_t ready = m_scene_ready[t.op];  // 0 for an op without scene data (request_scene)
    if (m_group_scene_offset[t.op] != k_none && !m_l1d)
        ready = std::max(ready, m_group_scene_ready[m_group_scene_offset[t.op] + t.first / width()]);
    return ready;
}

CoreModel::Executed CoreModel::execute(const GroupToken& t, uint32_t unit, uint64_t now) {
    const StreamOp op = m_pass->at(t.op);
    const OpProfile& p = m_costs[op.kind];
    StageTiming& stage = m_timing.stages[op.generation > 0][uint32_t(op.stage)];
    Executed e;
    const uint64_t stage_before = stage.busy_cycles + stage.stall_cycles;
    const uint64_t scene_memory_before = stage.scene_memory_cycles;
    e.start = std::max(now, t.data_ready);
    e.start = std::max(e.start, scene_ready(t));
    charge_idle(m_unit_free[unit], e.start, t, stage);
    if (m_l1d && m_group_scene_offset[t.op] != k_none) {
        // A CPU core's exposed share of its lanes' hit-primitive reads (request_scene).
        const uint64_t lanes_stall =
            m_group_lane_stall[m_group_scene_offset[t.op] + t.first / width()];
        m_timing.stalls.scene_memory += lanes_stall;
        stage.scene_memory_cycles += lanes_stall;
        stage.stall_cycles += lanes_stall;
        e.start += lanes_stall;
    }

    uint32_t passed = 0;
    if (p.measured)
        for (uint32_t i = 0; i < t.lanes; ++i) passed += op.passed[t.first + i];
    // The shares of its lanes that pay for ray data beyond the L1D and beyond the L2
    // (touch_ray_lines).
    const BeyondLanes beyond =
        m_group_beyond_offset[t.op] != k_none && t.lanes > 0
            ? m_group_beyond_lanes[m_group_beyond_offset[t.op] + t.first / width()]
            : BeyondLanes{};
    const double group_lanes = std::max(1u, t.lanes);
    // Fractional measured cycles: the unit carries the remainder to its next group.
    const double exact =
        m_unit_carry[unit] +
        (m_placed_by_sort[t.op]
             ? 0.0
             : p.issue_cycles(m_config.datapath, op.length, m_mispredicted_lanes[t.op], t.lanes,
                              passed, t.first == 0, beyond.l1 / group_lanes,
                              beyond.l2 / group_lanes, op.failed_candidates,
                              beyond.l1_skipping / group_lanes,
                              m_beyond_tlb * beyond.pages / group_lanes)) +
        (t.first == 0 && m_enters_loop[t.op] ? p.loop_entry_cycles(m_loop[t.op]) : 0.0) +
        (t.first == 0 && op.starts_traversal ? p.traversal_start_cycles() : 0.0) +
        // A call cold: a shading filter's (the material sort's once, on its first filter) and a
        // traversal's start.
        (t.first == 0 && (stage_of(op.kind) == OpStage::shading ? !m_placed_by_sort[t.op]
                                                                : op.starts_traversal)
             ? p.cold_call_cycles()
             : 0.0) +
        (t.first == 0 && op.starts_traversal && op.origin_shared ? p.shared_origin_cycles(op.length)
                                                                 : 0.0);
    // The op's mispredicted branches, on its first group.
    const double mispredicted =
        t.first == 0
            ? m_mispredicted[t.op] *
                  (op.kind == OpKind::box_test
                       ? m_config.branch_predictor.mispredict_cycles_in(size_t(m_loop[t.op]))
                       : m_config.branch_predictor.mispredict_cycles)
            : 0.0;
    const uint64_t branch_cycles = uint64_t(std::llround(mispredicted));
    m_timing.branch_cycles += branch_cycles;
    const uint64_t busy = uint64_t(std::max(0.0, std::floor(exact + mispredicted)));
    m_unit_carry[unit] = exact + mispredicted - double(busy);
    e.issue_end = e.start + busy;
    const uint64_t result =
        e.start + ceil_cycle(p.result_cycles(m_config.datapath, double(busy)));
    stage.busy_cycles += busy;
    const uint64_t group_cycles = stage.busy_cycles + stage.stall_cycles - stage_before;
    m_timing.op_cycles[size_t(op.kind)] += group_cycles;
    if (op.kind == OpKind::box_test) {
        m_timing.traversal_loop_cycles[size_t(m_loop[t.op])] += group_cycles;
        m_timing.traversal_loop_branch_cycles[size_t(m_loop[t.op])] += branch_cycles;
        m_timing.traversal_loop_memory_cycles[size_t(m_loop[t.op])] +=
            stage.scene_memory_cycles - scene_memory_before;
    }
    if (op.stage == OpStage::intersection)
        m_timing.intersection_loop_cycles[size_t(m_loop[t.op])] += group_cycles;
    m_unit_free[unit] = e.issue_end;
    // ACTIONS: the group's instructions and lanes; its mask word through the scratchpad.
    ActionCounts& act = m_timing.actions;
    act.simd_instructions[size_t(op.kind)] += p.compute_instructions;
    act.simd_lane_ops[size_t(op.kind)] += uint64_t(t.lanes) * p.compute_instructions;
    act.busy_cycles[size_t(HwUnit::simd)] += busy;
    act.scratchpad_accesses += 1;
    act.busy_cycles[size_t(HwUnit::scratchpad)] += 1;
    m_unit_stage[unit] = uint8_t((op.generation > 0) * k_op_stage_count + uint32_t(op.stage));

    if (m_l1d) {
        // A CPU core: the mask stays in a register; stores and compress-stores are in the
        // measured cost.
        e.completion = result;
        return finish_group(t, e);
    }
    // The mask goes through the scratchpad to the partition unit.
    e.completion = m_scratchpad.serve(result, 1.0) + 1;
    // Conditional scatters of the passing lanes: into the current buffer, or the next
    // generation's for an op that pushes rays.
    if (!p.scatter_words.empty()) {
        m_scratch.clear();
        for (uint32_t i = 0; i < t.lanes; ++i)
            if (op.passed[t.first + i]) m_scratch.push_back(op.slots[t.first + i]);
        if (!m_scratch.empty()) {
            const uint32_t lanes = uint32_t(m_scratch.size());
            const size_t words = p.scatter_words.size();
            const uint64_t addresses = m_agu.serve(result, double(lanes) * double(words)) + 1;
            uint64_t waits = 0, conflicts = 0, unused = 0;
            const uint64_t at_banks = cross(addresses, uint64_t(lanes) * words, waits);
            const uint32_t buffer = (op.generation + (p.pushes_rays ? 1 : 0)) % 2;
            const uint64_t last = book_words(buffer, p.scatter_words, m_scratch.data(), lanes,
                                             at_banks, nullptr, conflicts, unused);
            e.completion = std::max(e.completion, last + 1);
            m_timing.field_accesses += words;
            m_timing.mix.scatter_gather += words;
            m_timing.mix.store += words;  // each scattered word's address vector
            const uint64_t scattered = uint64_t(lanes) * words;  // ACTIONS
            act.bank_writes += scattered;
            act.agu_addresses += scattered;
            act.interconnect_word_hops += scattered * m_config.interconnect.mux_levels;
            act.busy_cycles[size_t(HwUnit::ray_buffer)] += words;
        }
    }
    return finish_group(t, e);
}

CoreModel::Executed CoreModel::finish_group(const GroupToken& t, Executed e) {
    m_op_completion[t.op] = std::max(m_op_completion[t.op], e.completion);
    if (--m_groups_left[t.op] == 0) {
        e.op_done = true;
        e.op_completion = m_op_completion[t.op];
    }
    return e;
}

void CoreModel::charge_idle(uint64_t from, uint64_t start, const GroupToken& t,
                            StageTiming& stage) {
    if (start <= from) return;
    const uint64_t idle = start - from;
    StallCycles& s = m_timing.stalls;
    stage.stall_cycles += idle;
    // 1. The dispatcher held this op for the previous op's partition.
    const uint64_t part = overlap(from, start, t.partition_start, t.partition_end);
    s.partition += part;
    uint64_t rest = idle - part;
    // 2. Before the group was released: waiting for the previous op's masks (when it waited on
    //    a partition) or for work at all (fewer groups in flight than units).
    const uint64_t released = std::max(from, std::min(start, t.dispatched));
    const uint64_t before = std::min(rest, released - from > part ? released - from - part : 0);
    if (t.partition_end > 0)
        s.pipeline_fill += before;
    else
        s.unit_idle += before;
    rest -= before;
    // 3. Scene data later than the ray data.
    const uint64_t ready = scene_ready(t);
    const uint64_t data_or_idle = std::max(released, t.data_ready);
    const uint64_t scene = ready > data_or_idle ? std::min(rest, ready - data_or_idle) : 0;
    s.scene_memory += scene;
    stage.scene_memory_cycles += scene;
    rest -= scene;
    // 4. The fetch's excess over an ideal fetch, by cause; what remains is its ideal latency.
    const uint64_t excess = t.alignment + t.conflict + t.address + t.interconnect;
    if (excess > 0 && rest > 0) {
        const uint64_t take = std::min(rest, excess);
        const uint64_t a = take * t.alignment / excess, c = take * t.conflict / excess,
                       d = take * t.address / excess;
        s.alignment += a;
        s.bank_conflict += c;
        s.address_fetch += d;
        s.interconnect += take - a - c - d;
        rest -= take;
    }
    s.pipeline_fill += rest;
}

uint64_t CoreModel::partition(uint32_t index, uint64_t ready) {
    const StreamOp op = m_pass->at(index);
    const PartitionCost part =
        partition_cost(m_config.partition, width(), op.length, m_pass->moved_ids(index));
    const uint64_t start = std::max(ready, m_partition_free);
    m_partition_free = start + part.cycles();
    m_timing.actions.busy_cycles[size_t(HwUnit::partition)] += part.cycles();  // ACTIONS
    return m_partition_free;
}

FrameTiming CoreModel::end_pass(uint64_t end) {
    for (uint32_t u = 0; u < units(); ++u) {
        if (end <= m_unit_free[u]) continue;
        const uint64_t tail = end - m_unit_free[u];
        const uint8_t st = m_unit_stage[u];
        m_timing.stages[st / k_op_stage_count][st % k_op_stage_count].stall_cycles += tail;
        m_timing.stalls.pipeline_fill += tail;
    }
    m_timing.cycles = end - m_pass_start;
    return m_timing;
}

}  // namespace sfx
