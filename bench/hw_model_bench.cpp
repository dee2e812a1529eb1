// Speed of the cycle-level hardware model, measured side by side in one run:
//  1. simulated cycles per host second of the concurrent SystemC model (width 16, 32 banks, 1
//     SIMD unit, 1 core) against an empty clocked SystemC process (an sc_clock driving one
//     SC_METHOD) over as many cycles — target >= 2x; also at 4 units and at 4 cores (their
//     simulated cycles: the frame's, core-cycles over cores);
//  2. the cost of each extra hardware configuration timed on the same trace, as a fraction of
//     the first configuration's cost (functional render included) — target <= 25 % (issue 32).
//     Configurations with the same scene-data lookups (these four) share one cache simulation;
//     the rest of a configuration's cost is its own: its lane groups through its SystemC
//     processes (about half the time, in the kernel) and its bookings;
//  3. the floor under (2): the render with its trace (to a sink that keeps nothing) and each
//     configuration's CoreModel arithmetic alone (fetch, execute and partition of every lane
//     group, one after another, no SystemC processes), and the figure of (2) they would give
//     if the kernel cost nothing. As long as every configuration books its own lane groups,
//     (2) cannot go below it.
// Usage: sfx_bench_hw_model [scene] [WxH] [spp] [repetitions]

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <systemc>
#include <vector>

#include "base/convergence.h"
#include "base/host_clock.h"
#include "hw_model/core_model.h"
#include "hw_model/pass_buffer.h"
#include "hw_model/systemc/systemc_timing.h"
#include "kernels/bvh.h"
#include "kernels/stream/stream_tracer.h"
#include "sweeps/point_group.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

struct EmptyClocked : sc_core::sc_module {
    sc_core::sc_in<bool> clk;
    uint64_t ticks = 0;
    SC_HAS_PROCESS(EmptyClocked);
    explicit EmptyClocked(sc_core::sc_module_name n) : sc_module(n) {
        SC_METHOD(tick);
        sensitive << clk.pos();
        dont_initialize();
    }
    void tick() { ++ticks; }
};

// Host seconds for `cycles` cycles of an sc_clock driving one empty SC_METHOD.
double empty_clocked_seconds(uint64_t cycles) {
    sc_core::sc_curr_simcontext = new sc_core::sc_simcontext();
    sc_core::sc_default_global_context = sc_core::sc_curr_simcontext;
    sc_core::sc_clock clock("clock", 2, sc_core::SC_NS);
    EmptyClocked m("empty");
    m.clk(clock);
    const auto t0 = HostClock::now();
    sc_core::sc_start(double(2 * cycles), sc_core::SC_NS);
    return seconds_since(t0);
}

// Records every pass of a render so timing can be measured without the tracer.
class PassRecorder : public TraceSink {
  public:
    void begin_pass(const TilePass& p) override {
        m_passes.emplace_back();
        m_passes.back().begin_pass(p);
    }
    void op(const StreamOp& o) override { m_passes.back().op(o); }
    void end_pass(const TilePass& p) override { m_passes.back().end_pass(p); }
    void replay(TraceSink& sink) const {
        for (const PassBuffer& b : m_passes) {
            sink.begin_pass(b.pass());
            for (size_t i = 0; i < b.size(); ++i) sink.op(b.at(i));
            sink.end_pass(b.pass());
        }
    }

    const std::vector<PassBuffer>& passes() const { return m_passes; }

  private:
    std::vector<PassBuffer> m_passes;
};

// Takes the whole trace (every op, as timing does) and keeps nothing: the render's share of (2).
class DiscardingSink : public TraceSink {
  public:
    void op(const StreamOp&) override {}
};

// Host seconds of each configuration's CoreModel arithmetic on the recorded passes, with no
// kernel: each op's groups are fetched and executed in order on the units in turn, and a
// partitioning op's partition follows its last group. The times are the model's own, but the
// order is not the processes' (nothing here is a prediction): only the cost is read. The
// configurations share one cache simulation, as in (2); the first pays for it.
std::vector<double> arithmetic_seconds(const std::vector<HwConfig>& configs,
                                       const WorkloadShape& shape, const PassRecorder& recorded) {
    const RayRecordLayout layout(shape.features);
    const SceneDataMap map = scene_data_map(shape);
    const auto lookups = std::make_shared<SharedCacheLookups>(configs.front().scene_memory.caches);
    std::vector<std::unique_ptr<OpCostTable>> costs;
    std::vector<std::unique_ptr<CoreModel>> models;
    for (const HwConfig& c : configs) {  // every reader joins before the first lookup
        costs.push_back(std::make_unique<OpCostTable>(layout, c));
        models.push_back(std::make_unique<CoreModel>(
            c, *costs.back(), map, layout.words(), buffer_slots(c.ray_buffer, layout.bytes(), shape.slots()), 0,
            std::make_shared<SceneMemoryModel>(c.scene_memory, c.clock.core_mhz, 1, lookups)));
    }
    std::vector<double> seconds;
    for (size_t k = 0; k < configs.size(); ++k) {
        const HwConfig& c = configs[k];
        CoreModel& model = *models[k];
        const auto t0 = HostClock::now();
        uint64_t now = 0;
        for (const PassBuffer& pass : recorded.passes()) {
            model.begin_pass(&pass, now);
            uint32_t unit = 0;
            for (uint32_t i = 0; i < pass.size(); ++i) {
                const StreamOp op = pass.at(i);
                if (op.length == 0) continue;
                model.request_scene(i, now);
                model.dispatch_op(i);
                for (uint32_t first = 0; first < op.length; first += c.simd.width) {
                    GroupToken t;
                    t.op = i;
                    t.first = first;
                    t.lanes = std::min(c.simd.width, op.length - first);
                    t.dispatched = now;
                    now = std::max(now, model.fetch(t, now));
                    const CoreModel::Executed e = model.execute(t, unit, now);
                    now = std::max(now, e.issue_end);
                    unit = (unit + 1) % c.simd.units;
                    if (e.op_done && model.profile(i).partitions)
                        now = std::max(now, model.partition(i, e.op_completion));
                }
            }
            model.end_pass(now);
        }
        seconds.push_back(seconds_since(t0));
    }
    return seconds;
}

}  // namespace

extern "C" int sc_main(int, char**) {
    return 0;
}

int main(int argc, char** argv) {
    setenv("SC_COPYRIGHT_MESSAGE", "DISABLE", 1);
    const std::string scene_name = argc > 1 ? argv[1] : "atrium";
    const std::string res = argc > 2 ? argv[2] : "128x128";
    const uint32_t spp = argc > 3 ? uint32_t(std::atoi(argv[3])) : 4;
    const int reps = argc > 4 ? std::atoi(argv[4]) : 3;
    RenderSettings settings;
    std::sscanf(res.c_str(), "%ux%u", &settings.width, &settings.height);
    settings.spp = spp;
    settings.tile = 32;
    const Scene scene = load_scene(scene_name);
    settings.max_depth = scene.max_depth;
    const Bvh bvh(scene);
    const WorkloadShape shape = workload_shape(scene, bvh, settings);
    std::printf("scene %s %ux%u x %u spp, tile %u, width 16, 32 banks, %d repetitions (median)\n",
                scene_name.c_str(), settings.width, settings.height, spp, settings.tile, reps);

    PassRecorder recorded;
    render_stream(scene, bvh, settings, &recorded);
    HwConfig gr08;  // width 16, 32 banks

    // 1. Cycle-level model on recorded passes versus an empty clocked process.
    auto machine = [&](uint32_t units, uint32_t cores) {
        HwConfig c = gr08;
        c.simd.units = units;
        c.cores.count = cores;
        c.name = std::to_string(units) + " unit" + (units > 1 ? "s" : "") + ", " +
                 std::to_string(cores) + " core" + (cores > 1 ? "s" : "");
        return c;
    };
    for (const HwConfig& c : {machine(1, 1), machine(4, 1), machine(1, 4)}) {
        std::vector<double> model_s, empty_s;
        uint64_t cycles = 0;
        for (int r = 0; r < reps; ++r) {
            const auto t0 = HostClock::now();
            {
                SystemcTiming timing({c}, shape);
                recorded.replay(timing);
                cycles = timing.timing(0).cycles / c.cores.count;
            }
            model_s.push_back(seconds_since(t0));
            empty_s.push_back(empty_clocked_seconds(cycles));
        }
        const double model_rate = double(cycles) / median(model_s);
        const double empty_rate = double(cycles) / median(empty_s);
        std::printf("%s: %llu simulated cycles\n", c.name.c_str(), (unsigned long long)cycles);
        std::printf("  concurrent model        %.3g cycles/host s (%.3f s)\n", model_rate,
                    median(model_s));
        std::printf("  empty clocked process   %.3g cycles/host s (%.3f s)\n", empty_rate,
                    median(empty_s));
        std::printf("  ratio model/empty       %.2fx%s\n", model_rate / empty_rate,
                    c.simd.units == 1 && c.cores.count == 1 ? " (target >= 2x)" : "");
    }

    // 2. Extra configurations on one trace: render + K accelerators, K = 1..4.
    std::vector<HwConfig> configs;
    for (uint32_t w : {16u, 8u, 12u, 4u}) {
        HwConfig c = gr08;
        c.simd.width = w;
        c.name = "w" + std::to_string(w);
        configs.push_back(c);
    }
    // Interleaved (k = 1..4 within each repetition) so machine noise hits every k alike.
    std::vector<std::vector<double>> samples(configs.size());
    for (int r = 0; r < reps; ++r)
        for (size_t k = 1; k <= configs.size(); ++k) {
            const auto t0 = HostClock::now();
            SystemcTiming timing(std::vector<HwConfig>(configs.begin(), configs.begin() + k),
                                 shape);
            render_stream(scene, bvh, settings, &timing);
            samples[k - 1].push_back(seconds_since(t0));
        }
    std::vector<double> group_s(configs.size());
    for (size_t k = 1; k <= configs.size(); ++k) {
        group_s[k - 1] = median(samples[k - 1]);
        std::printf("render + %zu configuration%s %.3f s\n", k, k == 1 ? " " : "s", group_s[k - 1]);
    }
    const double extra = (group_s.back() - group_s.front()) / double(configs.size() - 1);
    std::printf("each extra configuration  %.1f %% of the first (target <= 25 %%)\n",
                100.0 * extra / group_s.front());

    // 3. The arithmetic floor of the extra configurations: with no kernel at all, the first
    //    configuration would cost the render plus its arithmetic, each extra one its arithmetic.
    std::vector<std::vector<double>> arithmetic(configs.size());
    std::vector<double> render_s;
    for (int r = 0; r < reps; ++r) {
        const auto t0 = HostClock::now();
        DiscardingSink discard;
        render_stream(scene, bvh, settings, &discard);
        render_s.push_back(seconds_since(t0));
        const std::vector<double> s = arithmetic_seconds(configs, shape, recorded);
        for (size_t k = 0; k < configs.size(); ++k) arithmetic[k].push_back(s[k]);
    }
    std::printf("render with its trace     %.3f s\n", median(render_s));
    double extra_floor = 0.0;
    for (size_t k = 0; k < configs.size(); ++k) {
        std::printf("CoreModel arithmetic alone, %-4s %.3f s\n", configs[k].name.c_str(),
                    median(arithmetic[k]));
        if (k > 0) extra_floor += median(arithmetic[k]) / double(configs.size() - 1);
    }
    std::printf("with no kernel cost, each extra configuration  %.1f %% of the first\n",
                100.0 * extra_floor / (median(render_s) + median(arithmetic[0])));
    return 0;
}
