#pragma once
// The analytic timing model: a closed form over the trace's operation counts and stream-length
// histograms. The profile is gathered once per trace (a TraceSink); evaluating a configuration
// against it takes microseconds, so a sweep can price thousands of configurations per render.
//
// What it knows exactly: lane groups per width, id-stream alignment, compute, partition
// comparator passes, pipeline fill. What it estimates: bank conflicts (balls into bins,
// scaled by how sparse the stream is in its buffer), partition moves (an i.i.d. mask with the
// measured pass rate), and scene-data latency (per cache level, a miss rate from the working
// sets of a pass and of the frame against the level's capacity). Its error is measured
// against the cycle-level model, never assumed (tests/hw_model, sfx accuracy). Not in the
// closed form: the op window across ops (cores.op_window > 1), which only the cycle-level
// model's dispatcher has; a calibration on sampled passes (--calibration) carries its effect.

#include <cstdint>
#include <map>
#include <set>
#include <tuple>
#include <vector>
#include <unordered_set>

#include "hw_model/hw_config.h"
#include "hw_model/op_costs.h"
#include "hw_model/prediction.h"
#include "hw_model/workload_shape.h"

namespace sfx {

class TraceProfile : public TraceSink {
public:
    struct Bucket {
        uint64_t ops = 0;
        uint64_t passed = 0;  // sum of pass counts
        uint64_t failed_candidates = 0;  // sum of StreamOp::failed_candidates
        // Sum of the lanes a filter's branch predictor misses (mispredicted_lanes; the rarer
        // outcome's where the trace has no lanes).
        uint64_t mispredicted = 0;
        // Ops whose lanes a CPU core's material sort placed (placed_by_material_sort).
        uint64_t placed = 0;
        uint64_t fetches = 0;  // ops with a scene object
    };
    // (secondary, kind, stream length) -> bucket.
    using Key = std::tuple<bool, OpKind, uint32_t>;

    // Scene-data lines (k_line_bytes) fetched: spatial locality (sibling nodes, the triangles
    // of a leaf) is what the caches live on, so distinct lines, not objects, are counted.
    static constexpr uint32_t k_line_bytes = 64;
    struct Footprint {
        uint64_t fetches = 0;
        uint64_t pass_distinct = 0;   // sum over passes of distinct lines in the pass
        uint64_t frame_distinct = 0;  // distinct lines over the frame
    };

    explicit TraceProfile(const WorkloadShape& shape);
    void begin_pass(const TilePass& p) override;
    void op(const StreamOp& op) override;
    void end_pass(const TilePass& p) override;

    const std::map<Key, Bucket>& buckets() const { return m_buckets; }
    const Footprint& footprint() const { return m_footprint; }
    uint64_t passes() const { return m_passes; }
    uint32_t slots() const { return m_slots; }

private:
    std::map<Key, Bucket> m_buckets;
    // Marks a line in a bitmap; true if it was not marked yet.
    static bool mark(std::vector<uint64_t>& bits, uint64_t line);

    SceneDataMap m_map;
    std::vector<uint32_t> m_scene_bytes;  // per OpKind, from the op cost table
    Footprint m_footprint;
    // Lines seen in the frame and in the current pass: bitmaps over the scene data (a few
    // hundred KiB even for millions of primitives), so counting costs no hashing per op.
    std::vector<uint64_t> m_frame_lines, m_pass_lines;
    std::vector<uint64_t> m_pass_touched;  // words of m_pass_lines to clear at the next pass
    uint64_t m_passes = 0;
    uint32_t m_slots = 0;
    OpKind m_previous = OpKind::count;  // the kind of the pass's op before
};

// `footprint`, when given, is the profile whose scene-data working sets price the fetches
// (the whole frame's, when `profile` holds only some of its passes).
FrameTiming analytic_timing(const HwConfig& config, const WorkloadShape& shape,
                            const TraceProfile& profile, const TraceProfile* footprint = nullptr);

// Expected busiest-bank load minus the conflict-free load, for `lanes` requests spread
// uniformly over `banks` banks (exact, from the multinomial distribution).
double expected_conflicts(uint32_t lanes, uint32_t banks);

// Expected number of ids a stable in-place partition moves, for `length` ids each passing
// independently with probability `pass_rate`.
double expected_moved_ids(uint32_t length, double pass_rate);

}  // namespace sfx
