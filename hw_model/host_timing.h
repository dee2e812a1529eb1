#pragma once
// The host timing: a CPU core described as a hardware configuration (hw_model/
// host_description.h) predicts the native stream tracer's single-thread cycles from the
// workload trace. Each op costs what HwConfig::op_costs says for its kind (measured on
// microbenchmarks, never on frames), with lanes and groups at the configured SIMD width, the
// lanes' ray-buffer accesses beyond the L1D when the pass's ray buffer outgrows it, plus
// the op's scene data: a line that misses the L1D costs the measured latency of the level that
// holds it (minus the L1D's), through the configured caches. Out-of-order overlap, prefetch
// and frequency changes are not modelled (the calibration's microbenchmarks include what a
// short stream of one kind overlaps).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hw_model/cache_model.h"
#include "hw_model/hw_config.h"
#include "hw_model/op_costs.h"
#include "kernels/trace.h"

namespace sfx {

struct HostTimingResult {
    std::array<double, k_op_stage_count> stage_cycles{};  // includes scene_memory_cycles
    std::array<double, k_op_stage_count> scene_memory_cycles{};
    std::array<double, k_op_kind_count> kind_cycles{};
    uint64_t ops = 0, passes = 0;
    double frame_cycles() const { return stage_cycles[0] + stage_cycles[1] + stage_cycles[2]; }
};

// An op's cost from its profile, without scene data: n lanes, p passing, a fraction
// `beyond_l1` of the ray buffer outside the L1D (one lane: one_lane_cycles when measured).
double host_op_cycles(const OpCostConfig& cost, uint32_t width, uint32_t lanes, uint32_t passed,
                      double beyond_l1);

// The fraction of a ray buffer of `slots` records of `record_bytes` that the L1D (`l1d_kib`)
// cannot hold: random lanes miss it with that probability.
double beyond_l1_fraction(uint32_t slots, uint32_t record_bytes, uint32_t l1d_kib);

class HostTiming : public TraceSink {
  public:
    // `config` must carry op_costs (throws std::invalid_argument naming a kind the trace uses
    // that has none). `record_bytes`: the bytes per ray slot the tracer touches.
    HostTiming(const HwConfig& config, const SceneDataMap& scene, const OpCostTable& profiles,
               uint32_t record_bytes);
    void begin_pass(const TilePass& pass) override;
    void op(const StreamOp& op) override;
    const HostTimingResult& result() const { return m_result; }

  private:
    HwConfig m_config;
    SceneDataMap m_scene;
    const OpCostTable& m_profiles;
    uint32_t m_record_bytes;
    std::array<const OpCostConfig*, k_op_kind_count> m_costs{};
    std::vector<SetAssociativeCache> m_caches;
    std::vector<double> m_extra_cycles;  // per level, then DRAM: latency beyond the L1D's
    double m_beyond_l1 = 0.0;
    HostTimingResult m_result;
};

// One microbenchmark run of an op kind: what the cost formula sees, and the cycles measured.
struct OpCostSample {
    uint32_t lanes = 0, passed = 0;
    double beyond_l1 = 0.0;
    double cycles = 0.0;  // per op
};

// Fits an op kind's cost profile to its samples: least squares on relative error, every
// coefficient non-negative (a negative one is dropped and the rest refitted). Throws
// std::invalid_argument on no samples.
OpCostConfig fit_op_cost(const std::string& op, uint32_t width,
                         const std::vector<OpCostSample>& samples);

// The fit's relative error on its own samples: (median, worst) of |predicted - measured| /
// measured, a measurement under 100 cycles counting as 100 (the clock's steps).
std::pair<double, double> fit_error(const OpCostConfig& cost, uint32_t width,
                                    const std::vector<OpCostSample>& samples);

// One-ray traversals timed together (kernels/stream/stream_microbench.h): how many one-lane ops
// of each kind they made, and the cycles they took.
struct OneLaneSample {
    std::array<uint64_t, k_op_kind_count> ops{};
    double cycles = 0.0;
};

// The one-lane cost of every kind the samples make (OpCostConfig::one_lane_cycles; 0 for the
// rest): least squares on relative error, non-negative as in fit_op_cost. Throws
// std::invalid_argument on no samples.
std::array<double, k_op_kind_count> fit_one_lane_cycles(const std::vector<OneLaneSample>& samples);

// That fit's (median, worst) relative error on its own samples.
std::pair<double, double> one_lane_fit_error(const std::array<double, k_op_kind_count>& cycles,
                                             const std::vector<OneLaneSample>& samples);

}  // namespace sfx
