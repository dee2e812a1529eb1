#include "hw_model/systemc/sequencer.h"

#include <algorithm>

namespace sfx {

Sequencer::Sequencer(sc_core::sc_module_name name, const OpCostTable& costs,
                     const SceneDataMap& map, uint32_t width, double core_mhz)
    : sc_module(name), m_costs(costs), m_map(map), m_width(width),
      m_period(1e3 / core_mhz, sc_core::SC_NS) {
    SC_THREAD(run);
}

void Sequencer::start(const PassBuffer* pass) {
    m_pass = pass;
    m_start.notify(sc_core::SC_ZERO_TIME);
}

void Sequencer::run() {
    for (;;) {
        wait(m_start);
        if (m_warming) {
            for (size_t i = 0; i < m_pass->size(); ++i) {
                const StreamOp op = m_pass->at(i);
                const OpProfile& p = m_costs[op.kind];
                if (p.scene_bytes && op.object != k_no_object && op.length)
                    scene_memory->read(i, m_map.address(op.kind, op.object), p.scene_bytes);
            }
            continue;
        }
        FrameTiming pass_timing;
        pass_timing.passes = 1;
        for (size_t i = 0; i < m_pass->size(); ++i) {
            const uint64_t cycles = time_op(i, m_pass->at(i), pass_timing);
            m_keeper.inc(m_period * double(cycles));
            if (m_keeper.need_sync()) m_keeper.sync();
        }
        m_keeper.sync();
        m_timing += pass_timing;
    }
}

static bool pushes_rays(OpKind k) {
    return k == OpKind::camera || k == OpKind::lambertian_direct ||
           k == OpKind::lambertian_indirect || k == OpKind::dielectric || k == OpKind::glossy;
}

uint64_t Sequencer::time_op(size_t index, const StreamOp& op, FrameTiming& t) {
    const uint32_t length = op.length;
    if (length == 0) return 0;
    const OpProfile& p = m_costs[op.kind];
    const uint32_t n = m_width;
    const uint64_t groups = (uint64_t(length) + n - 1) / n;
    uint64_t busy = 0, conflict = 0, align = 0, first_group = 0, field_accesses = 0,
             conflicted = 0;
    for (uint64_t g = 0; g < groups; ++g) {
        const uint32_t begin = uint32_t(g * n);
        const uint32_t lanes = std::min(n, length - begin);
        const uint32_t* slots = op.slots + begin;
        const RayBufferModel::Contiguous ids = ray_buffer->access_ids(begin, lanes);
        busy += ids.cycles - ids.alignment_cycles;
        align += ids.alignment_cycles;
        const uint32_t gathers = uint32_t(p.gather_words.size());
        if (gathers) {
            const RayBufferModel::Access a = ray_buffer->access_fields(gathers, slots, lanes);
            busy += a.cycles - a.conflict_cycles;
            conflict += a.conflict_cycles;
            field_accesses += gathers;
            conflicted += a.conflict_cycles > 0 ? gathers : 0;
        }
        if (g == 0) first_group = busy + conflict + align;
        if (!p.scatter_words.empty()) {
            m_scratch_slots.clear();
            for (uint32_t i = 0; i < lanes; ++i)
                if (op.passed[begin + i]) m_scratch_slots.push_back(slots[i]);
            const uint32_t scatters = uint32_t(p.scatter_words.size());
            if (!m_scratch_slots.empty()) {
                const RayBufferModel::Access a = ray_buffer->access_fields(
                    scatters, m_scratch_slots.data(), uint32_t(m_scratch_slots.size()));
                busy += a.cycles - a.conflict_cycles;
                conflict += a.conflict_cycles;
                field_accesses += scatters;
                conflicted += a.conflict_cycles > 0 ? scatters : 0;
            }
        }
    }
    busy += simd->execute(op.kind, groups, p.compute_instructions);
    const uint64_t data = busy + conflict + align;

    StallCycles stalls;
    stalls.bank_conflict = conflict;
    stalls.alignment = align;
    stalls.pipeline_fill =
        p.latency_cycles + ray_buffer->fill_cycles() + interconnect->crossing_cycles();
    const uint64_t words = uint64_t(length) * (p.gather_words.size() + 1) +
                           uint64_t(op.pass_count) * p.scatter_words.size();
    const uint64_t address_cycles = address->generate(words);
    stalls.address_fetch = address_cycles > data ? address_cycles - data : 0;
    if (p.scene_bytes && op.object != k_no_object) {
        const uint64_t latency = scene_memory->read(index, m_map.address(op.kind, op.object), p.scene_bytes);
        stalls.scene_memory = latency > first_group ? latency - first_group : 0;
    }
    PartitionCost part;
    if (p.partitions) {
        part = partition->partition(length, m_pass->moved_ids(index));
        stalls.partition = part.cycles();
    }
    // Filter masks go through the scratchpad (one word per group, written then read); it is
    // dual-ported and overlaps the data path, so only its excess stalls.
    const uint64_t scratch = scratchpad->access(2 * groups);
    stalls.interconnect = interconnect->transfer(words * 2, data) +  // data + address words
                          (scratch > data ? scratch - data : 0);

    OpMix& mix = t.mix;
    mix.load += groups + (p.scene_bytes && op.object != k_no_object ? 1 : 0);
    mix.compute += groups * p.compute_instructions;
    mix.scatter_gather += field_accesses;
    mix.partition += part.compare_cycles;
    mix.store += part.move_cycles;
    if (pushes_rays(op.kind)) mix.store += (uint64_t(op.pass_count) + n - 1) / n;

    const uint64_t total = data + stalls.pipeline_fill + stalls.address_fetch +
                           stalls.scene_memory + stalls.partition + stalls.interconnect;
    StageTiming& stage = t.stages[op.generation > 0][uint32_t(op.stage)];
    stage.ops += 1;
    stage.lanes += length;
    stage.groups += groups;
    stage.busy_cycles += busy;
    stage.stall_cycles += total - busy;
    t.stalls += stalls;
    t.field_accesses += field_accesses;
    t.conflicted_accesses += conflicted;
    t.cycles += total;
    return total;
}

}  // namespace sfx
