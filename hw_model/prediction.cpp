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

OpMix& OpMix::operator+=(const OpMix& o) {
    visit(*this, o, [](const CounterInfo&, uint64_t& x, uint64_t y) { x += y; });
    return *this;
}

StageTiming& StageTiming::operator+=(const StageTiming& o) {
    visit(*this, o, [](const CounterInfo&, uint64_t& x, uint64_t y) { x += y; });
    return *this;
}

FrameTiming& FrameTiming::operator+=(const FrameTiming& o) {
    visit(*this, o, [](const CounterInfo&, uint64_t& x, uint64_t y) { x += y; });
    return *this;
}

void FrameTiming::add_scaled(const FrameTiming& o, double weight) {
    visit(*this, o, [weight](const CounterInfo&, uint64_t& x, uint64_t y) {
        x += uint64_t(std::llround(double(y) * weight));
    });
}

FrameTiming timing_between(const FrameTiming& a, const FrameTiming& b) {
    FrameTiming d = b;
    FrameTiming::visit(d, a, [](const CounterInfo&, uint64_t& x, uint64_t y) { x -= y; });
    return d;
}

void fit_stalls_to_cycles(FrameTiming& t, uint32_t units) {
    double busy = 0.0;
    for (const auto& by_stage : t.stages)
        for (const StageTiming& s : by_stage) busy += double(s.busy_cycles);
    const double stalled = double(t.stalls.total());
    if (stalled <= 0.0) return;
    const double f = std::max(0.0, double(units) * double(t.cycles) - busy) / stalled;
    auto scale = [f](uint64_t& v) { v = uint64_t(std::llround(double(v) * f)); };
    StallCycles::visit(t.stalls, t.stalls,
                       [&](const CounterInfo&, uint64_t& v, const uint64_t&) { scale(v); });
    for (auto& by_stage : t.stages)
        for (StageTiming& s : by_stage) {
            scale(s.stall_cycles);
            scale(s.scene_memory_cycles);
        }
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

    for (uint32_t k = 0; k < k_op_stage_count; ++k) {
        StageTiming all = timing.stages[0][k];
        all += timing.stages[1][k];
        const std::string st = to_string(OpStage(k));
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
    StallCycles::visit(st, st, [&](const CounterInfo& c, uint64_t v, uint64_t) {
        add("stall_cycles." + c.name(), double(v) * unit_scale, c.unit, c.description);
    });
    add("stall_cycles.total", double(st.total()) * unit_scale, "cycles", "all stall cycles");
    // G&R 4.2's "theoretical maximum achievable frame rate ... assuming no stalls or
    // dependencies of any kind": the frame's busy cycles alone, every unit issuing every cycle.
    // Its groups are the trace's, partly empty where streams are short (Table 3's ideal
    // utilization is a property of the workload, not a stall), so this is the paper's figure;
    // the rate with every lane of every group busy as well is printed beside it.
    double busy = 0.0, busy_full_lanes = 0.0;
    for (const auto& by_stage : timing.stages)
        for (const StageTiming& t : by_stage) {
            busy += double(t.busy_cycles);
            if (t.groups > 0)
                busy_full_lanes += double(t.busy_cycles) * double(t.lanes) /
                                   (double(t.groups) * double(config.simd.width));
        }
    const double rate = fps() * frame_cycles();  // frames per second per frame-cycle
    add("fps_stall_free", ratio(rate, busy * unit_scale), "frames/s",
        "frame rate with every stall hidden (G&R 4.2's theoretical maximum)");
    add("fps_stall_free_full_lanes", ratio(rate, busy_full_lanes * unit_scale), "frames/s",
        "frame rate with every stall hidden and every SIMD lane of every group busy");

    const double mix_total = double(timing.mix.total());
    OpMix::visit(timing.mix, timing.mix, [&](const CounterInfo& c, uint64_t v, uint64_t) {
        add("op_mix." + c.name() + "_percent", 100.0 * ratio(double(v), mix_total), "%",
            c.description);
    });
    add("op_mix.instructions", mix_total, "instructions", "SIMD instructions per frame");

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
    if (config.branch_predictor.kind != "none") {
        add("branch_predictor.mispredictions", double(timing.branch_mispredictions), "branches",
            "traversal branches the core's branch predictor mispredicted");
        add("branch_predictor.cycles", double(timing.branch_cycles), "cycles",
            "unit-cycles the mispredictions cost (part of the busy cycles)");
    }
    if (config.ray_buffer.storage == "l1d") {
        // A CPU core's traversal by the native tracer's loop (TraversalLoop, kernels/trace.h):
        // what `sfx calibrate --check` compares with the tracer's own clock.
        const char* loops[3] = {"one_ray", "few_ray", "stream"};
        for (int l = 0; l < 3; ++l)
            add(std::string("traversal_loop_cycles.") + loops[l],
                double(timing.traversal_loop_cycles[l]) * unit_scale, "cycles",
                std::string("box tests' unit-cycles in the native tracer's ") + loops[l] + " loop");
        for (int l = 0; l < 3; ++l)
            add(std::string("traversal_loop_branch_cycles.") + loops[l],
                double(timing.traversal_loop_branch_cycles[l]) * unit_scale, "cycles",
                std::string("of those, what their mispredicted branches cost"));
        for (int l = 0; l < 3; ++l)
            add(std::string("traversal_loop_memory_cycles.") + loops[l],
                double(timing.traversal_loop_memory_cycles[l]) * unit_scale, "cycles",
                std::string("of those, their wait for scene data"));
        for (int l = 0; l < 3; ++l)
            add(std::string("intersection_loop_cycles.") + loops[l],
                double(timing.intersection_loop_cycles[l]) * unit_scale, "cycles",
                std::string("intersection ops' unit-cycles in the leaf code of the native "
                            "tracer's ") +
                    loops[l] + " loop");
        // And its shading stage by op kind, which the tracer's stage clock also splits.
        for (uint32_t k = 0; k < k_op_kind_count; ++k)
            if (stage_of(OpKind(k)) == OpStage::shading && timing.op_cycles[k] > 0)
                add(std::string("op_cycles.") + k_op_kinds[k].name,
                    double(timing.op_cycles[k]) * unit_scale, "cycles",
                    std::string("unit-cycles of the ") + k_op_kinds[k].name + " ops");
    }
    for (size_t i = 0; i < timing.cache_misses.size() && i < config.scene_memory.caches.size(); ++i)
        add("scene_cache." + config.scene_memory.caches[i].name + ".misses",
            double(timing.cache_misses[i]), "accesses",
            "misses of scene-data cache level " + config.scene_memory.caches[i].name);
    add("trace.box_tests_per_ray.primary", box_tests_per_ray[0], "lanes",
        "box-test lanes per camera ray");
    add("trace.box_tests_per_ray.secondary", box_tests_per_ray[1], "lanes",
        "box-test lanes per secondary ray");
    add("trace.entry_depth", entry_depth, "levels",
        "mean BVH depth at which primary streams enter (root 0)");
    for (uint32_t g = 0; g < k_bounces; ++g) {
        const std::string b = "trace.bounce" + std::to_string(g) + ".";
        const std::string of = g == 0 ? "camera rays" : "rays of bounce " + std::to_string(g);
        add(b + "rays_per_node", rays_per_node[g], "rays",
            "mean box-test stream length (rays per visited node), " + of);
        add(b + "rays_per_leaf", rays_per_leaf[g], "rays",
            "mean primitive-test stream length (rays per visited leaf), " + of);
        add(b + "box_tests_per_ray", bounce_box_tests_per_ray[g], "lanes",
            "box-test lanes per ray, " + of);
    }
    add("trace.batching.mean_queue_length", batch_mean_queue, "rays",
        "RayGrid: mean rays per traced queue");
    add("trace.batching.full_queue_share", batch_full_share, "",
        "RayGrid: share of traced queues that were full");
    add("trace.batching.lanes_per_ray", batch_lanes_per_ray, "lanes",
        "RayGrid: cell-walk and enqueue lanes per secondary ray");

    // Area and energy: the action counts priced with the node's technology table (area_energy.h).
    const TechTable& t = tech_table_for(config.tech.node, "tech.node");
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
    // Average power over the frame, mJ per frame over seconds per frame: W.
    auto watts = [&](double mj) { return seconds > 0 ? mj * 1e-3 / seconds : 0.0; };
    add("power.w", watts(energy_mj), "W", "average power while rendering");
    add("power.leakage_w", watts(ae.leakage_mj()), "W", "static (leakage) share of the average power");
    for (const UnitCost& u : ae.units) {
        add("power." + u.unit + ".dynamic_w", watts(u.dynamic_mj), "W",
            "dynamic power of " + u.unit + " (its actions' energy over the frame's time)");
        if (u.unit != "dram")
            add("power." + u.unit + ".static_w", watts(u.leakage_mj), "W",
                "static (leakage) power of " + u.unit);
    }
    add("fps_per_mm2", ratio(fps(), area), "frames/s/mm2", "frame rate per on-chip area");
    add("frames_per_joule", ratio(1.0, energy_mj * 1e-3), "frames/J", "frames per joule");
    return s;
}

}  // namespace sfx
