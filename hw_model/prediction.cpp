#include "hw_model/prediction.h"

#include "hw_model/area_energy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sfx {

const char* to_string(Fidelity f) {
    switch (f) {
        case Fidelity::analytic:
            return "analytic";
        case Fidelity::sampled:
            return "sampled";
        case Fidelity::full:
            return "full";
    }
    return "?";
}

Fidelity parse_fidelity(const std::string& text) {
    if (text == "analytic") return Fidelity::analytic;
    if (text == "sampled") return Fidelity::sampled;
    if (text == "full") return Fidelity::full;
    throw std::invalid_argument("fidelity must be analytic, sampled or full, not '" + text + "'");
}

StallCycles& StallCycles::operator+=(const StallCycles& o) {
    bank_conflict += o.bank_conflict;
    alignment += o.alignment;
    address_fetch += o.address_fetch;
    partition += o.partition;
    scene_memory += o.scene_memory;
    interconnect += o.interconnect;
    pipeline_fill += o.pipeline_fill;
    unit_idle += o.unit_idle;
    return *this;
}

OpMix& OpMix::operator+=(const OpMix& o) {
    load += o.load;
    store += o.store;
    compute += o.compute;
    scatter_gather += o.scatter_gather;
    partition += o.partition;
    option += o.option;
    return *this;
}

StageTiming& StageTiming::operator+=(const StageTiming& o) {
    ops += o.ops;
    lanes += o.lanes;
    groups += o.groups;
    busy_cycles += o.busy_cycles;
    stall_cycles += o.stall_cycles;
    return *this;
}

FrameTiming& FrameTiming::operator+=(const FrameTiming& o) {
    cycles += o.cycles;
    stalls += o.stalls;
    mix += o.mix;
    for (int s = 0; s < 2; ++s)
        for (uint32_t k = 0; k < k_op_stage_count; ++k) stages[s][k] += o.stages[s][k];
    field_accesses += o.field_accesses;
    conflicted_accesses += o.conflicted_accesses;
    if (cache_hits.size() < o.cache_hits.size()) {
        cache_hits.resize(o.cache_hits.size());
        cache_misses.resize(o.cache_misses.size());
    }
    for (size_t i = 0; i < o.cache_hits.size(); ++i) {
        cache_hits[i] += o.cache_hits[i];
        cache_misses[i] += o.cache_misses[i];
    }
    dram_reads += o.dram_reads;
    passes += o.passes;
    actions += o.actions;
    return *this;
}

namespace {
// Applies f(counter of this, counter of o) to every counter of a FrameTiming pair.
template <class F>
void for_each_counter(FrameTiming& t, const FrameTiming& o, F f) {
    f(t.cycles, o.cycles);
    f(t.stalls.bank_conflict, o.stalls.bank_conflict);
    f(t.stalls.alignment, o.stalls.alignment);
    f(t.stalls.address_fetch, o.stalls.address_fetch);
    f(t.stalls.partition, o.stalls.partition);
    f(t.stalls.scene_memory, o.stalls.scene_memory);
    f(t.stalls.interconnect, o.stalls.interconnect);
    f(t.stalls.pipeline_fill, o.stalls.pipeline_fill);
    f(t.stalls.unit_idle, o.stalls.unit_idle);
    f(t.mix.load, o.mix.load);
    f(t.mix.store, o.mix.store);
    f(t.mix.compute, o.mix.compute);
    f(t.mix.scatter_gather, o.mix.scatter_gather);
    f(t.mix.partition, o.mix.partition);
    f(t.mix.option, o.mix.option);
    for (int s = 0; s < 2; ++s)
        for (uint32_t k = 0; k < k_op_stage_count; ++k) {
            f(t.stages[s][k].ops, o.stages[s][k].ops);
            f(t.stages[s][k].lanes, o.stages[s][k].lanes);
            f(t.stages[s][k].groups, o.stages[s][k].groups);
            f(t.stages[s][k].busy_cycles, o.stages[s][k].busy_cycles);
            f(t.stages[s][k].stall_cycles, o.stages[s][k].stall_cycles);
        }
    f(t.field_accesses, o.field_accesses);
    f(t.conflicted_accesses, o.conflicted_accesses);
    t.cache_hits.resize(std::max(t.cache_hits.size(), o.cache_hits.size()));
    t.cache_misses.resize(std::max(t.cache_misses.size(), o.cache_misses.size()));
    for (size_t i = 0; i < o.cache_hits.size(); ++i) {
        f(t.cache_hits[i], o.cache_hits[i]);
        f(t.cache_misses[i], o.cache_misses[i]);
    }
    f(t.dram_reads, o.dram_reads);
    f(t.passes, o.passes);
    ActionCounts::for_each(t.actions, o.actions, f);
}
}  // namespace

void FrameTiming::add_scaled(const FrameTiming& o, double weight) {
    for_each_counter(*this, o, [weight](uint64_t& a, uint64_t b) {
        a += uint64_t(std::llround(double(b) * weight));
    });
}

FrameTiming timing_between(const FrameTiming& a, const FrameTiming& b) {
    FrameTiming d = b;
    for_each_counter(d, a, [](uint64_t& x, uint64_t y) { x -= y; });
    return d;
}

double Prediction::frame_cycles() const {
    return double(timing.cycles) / double(std::max(1u, config.cores.count));
}

double Prediction::frame_seconds() const {
    return frame_cycles() / (config.clock.core_mhz * 1e6);
}

double Prediction::fps() const {
    const double s = frame_seconds();
    return s > 0.0 ? 1.0 / s : 0.0;
}

namespace {
double ratio(double a, double b) {
    return b > 0.0 ? a / b : 0.0;
}
}  // namespace

std::vector<Stat> Prediction::stats() const {
    std::vector<Stat> s;
    auto add = [&](std::string name, double value, std::string unit, std::string description) {
        s.push_back({std::move(name), value, std::move(unit), std::move(description)});
    };
    add("fps", fps(), "frames/s", "predicted frame rate");
    add("frame_cycles", frame_cycles(), "cycles", "cycles per frame (core-cycles over cores)");
    add("frame_seconds", frame_seconds(), "s", "predicted time per frame");
    add("host_seconds", host_seconds, "s", "host time to obtain this prediction");
    add("error.relative", error_relative, "",
        "relative half-width of the frame-cycle interval (<0: unknown)");
    add("passes.total", double(total_passes), "passes", "tile passes in the frame");
    add("passes.timed", double(sample_passes), "passes", "tile passes timed by the model");
    add("tile", double(tile), "pixels", "tile edge: the initial stream is tile^2 rays");
    add("bytes_per_ray", double(bytes_per_ray), "bytes", "ray record size in the ray buffer");

    static const char* k_stage_names[] = {"traversal", "intersection", "shading"};
    for (uint32_t k = 0; k < k_op_stage_count; ++k) {
        StageTiming all = timing.stages[0][k];
        all += timing.stages[1][k];
        const std::string st = k_stage_names[k];
        // Effective utilization: the ideal (lanes over issued lane slots) times the share of
        // the stage's cycles that issue work; a stall cycle issues nothing.
        auto effective = [](double ideal, const StageTiming& t) {
            return ideal * ratio(double(t.busy_cycles), double(t.busy_cycles + t.stall_cycles));
        };
        add("simd_utilization." + st, effective(ideal_utilization_all[k], all), "",
            "effective SIMD utilization, all rays");
        add("ideal_simd_utilization." + st, ideal_utilization_all[k], "",
            "ideal SIMD utilization from the trace, all rays");
        for (int sec = 0; sec < 2; ++sec) {
            const std::string kind = sec ? "secondary" : "primary";
            add("simd_utilization." + kind + "." + st,
                effective(ideal_utilization[sec][k], timing.stages[sec][k]), "",
                "effective SIMD utilization, " + kind + " rays");
            add("ideal_simd_utilization." + kind + "." + st, ideal_utilization[sec][k], "",
                "ideal SIMD utilization, " + kind + " rays");
        }
        add("stage_cycles." + st,
            double(all.busy_cycles + all.stall_cycles) /
                double(std::max(1u, config.simd.units) * std::max(1u, config.cores.count)),
            "cycles", "cycles spent in the " + st + " stage");
        add("stream_length." + st, ratio(double(all.lanes), double(all.ops)), "rays",
            "average stream length of the stage's operations");
    }

    // Stall and stage cycles are SIMD-unit cycles; shown per unit of the frame, so that the
    // causes and the busy cycles of a stage add up to the frame's cycles.
    const double unit_scale =
        1.0 / double(std::max(1u, config.simd.units) * std::max(1u, config.cores.count));
    const StallCycles& st = timing.stalls;
    auto stall = [&](const char* name, uint64_t v, const char* what) {
        add(std::string("stall_cycles.") + name, double(v) * unit_scale, "cycles", what);
    };
    stall("bank_conflict", st.bank_conflict, "waiting on a busy ray-buffer bank");
    stall("alignment", st.alignment, "SIMD groups not aligned to buffer lines");
    stall("address_fetch", st.address_fetch, "address generation behind the data path");
    stall("partition", st.partition, "in-place stream partition");
    stall("scene_memory", st.scene_memory, "waiting for scene data");
    stall("interconnect", st.interconnect, "interconnect contention");
    stall("pipeline_fill", st.pipeline_fill, "waiting out bank, interconnect and datapath latency");
    stall("unit_idle", st.unit_idle, "a SIMD unit with no group released to it");
    stall("total", st.total(), "all stall cycles");

    const double mix_total = double(timing.mix.total());
    add("op_mix.load_percent", 100.0 * ratio(double(timing.mix.load), mix_total), "%",
        "loads (Table 5)");
    add("op_mix.store_percent", 100.0 * ratio(double(timing.mix.store), mix_total), "%",
        "stores (Table 5)");
    add("op_mix.compute_percent", 100.0 * ratio(double(timing.mix.compute), mix_total), "%",
        "compute on ray data (Table 5)");
    add("op_mix.scatter_gather_percent",
        100.0 * ratio(double(timing.mix.scatter_gather), mix_total), "%",
        "scatters and gathers (Table 5)");
    add("op_mix.partition_percent", 100.0 * ratio(double(timing.mix.partition), mix_total), "%",
        "partition (Table 5)");
    add("op_mix.instructions", mix_total, "instructions", "SIMD instructions per frame");
    add("op_mix.option_percent", 100.0 * ratio(double(timing.mix.option), mix_total), "%",
        "instructions of the ops a workload option adds (its own overhead)");

    add("ray_buffer.bank_conflict_rate",
        ratio(double(timing.conflicted_accesses), double(timing.field_accesses)), "",
        "share of field accesses that waited on a bank");
    for (size_t i = 0; i < timing.cache_hits.size() && i < config.scene_memory.caches.size(); ++i) {
        const double h = double(timing.cache_hits[i]), m = double(timing.cache_misses[i]);
        add("scene_cache." + config.scene_memory.caches[i].name + ".hit_rate", ratio(h, h + m), "",
            "hit rate of scene-data cache level " + config.scene_memory.caches[i].name);
    }
    add("scene_memory.dram_reads", double(timing.dram_reads), "lines",
        "scene-data lines read from DRAM");
    for (size_t i = 0; i < timing.cache_misses.size() && i < config.scene_memory.caches.size(); ++i)
        add("scene_cache." + config.scene_memory.caches[i].name + ".misses",
            double(timing.cache_misses[i]), "accesses",
            "misses of scene-data cache level " + config.scene_memory.caches[i].name);
    add("workload.box_tests_per_ray.primary", box_tests_per_ray[0], "lanes",
        "box-test lanes per camera ray");
    add("workload.box_tests_per_ray.secondary", box_tests_per_ray[1], "lanes",
        "box-test lanes per secondary ray");
    add("workload.entry_depth", entry_depth, "levels",
        "mean BVH depth at which primary streams enter (root 0)");

    // Area and energy: the action counts priced with the technology table (area_energy.h).
    const TechTable& t = tech ? *tech : default_tech_table();
    const AreaEnergy ae = evaluate_area_energy(config, timing.actions, uint64_t(std::llround(frame_cycles())), t);
    add("tech.node_nm", t.node_nm, "nm", "process node of the technology table");
    for (const UnitCost& u : ae.units)
        if (u.unit != "dram")
            add("area." + u.unit + "_mm2", u.area_mm2, "mm2", "area of " + u.unit);
    const double area = ae.total_area_mm2(), energy_mj = ae.total_energy_mj();
    add("area.total_mm2", area, "mm2", "on-chip area");
    for (const UnitCost& u : ae.units)
        add("energy." + u.unit + "_per_frame_mj", u.energy_mj(), "mJ",
            "energy of " + u.unit + " per frame, dynamic and leakage");
    add("energy.total_per_frame_mj", energy_mj, "mJ", "energy per frame");
    const double seconds = frame_seconds();
    add("power.w", seconds > 0 ? energy_mj * 1e-3 / seconds : 0.0, "W", "average power while rendering");
    add("power.leakage_w", seconds > 0 ? ae.leakage_mj() * 1e-3 / seconds : 0.0, "W",
        "leakage share of the average power");
    add("fps_per_mm2", ratio(fps(), area), "frames/s/mm2", "frame rate per on-chip area");
    add("frames_per_joule", ratio(1.0, energy_mj * 1e-3), "frames/J", "frames per joule");
    return s;
}

}  // namespace sfx
