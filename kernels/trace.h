#pragma once
// The workload trace: the seam between the stream tracer and every timing model.
//
// Per tile pass (one sample of one tile), the stream tracer reports every stream operation in
// execution order: what was tested (kind, object), in which stage, against which ray slots (in
// stream order) and which of them passed. Nothing here knows how the tracer works; a hardware
// model needs only this header (and trace.cpp for the sinks and the file format).
//
// Stream filtering is independent of SIMD width, so one trace serves every width, bank count,
// latency and clock: a model chunks each op's slots into groups of N lanes itself.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace sfx {

enum class OpStage : uint8_t { traversal, intersection, shading };
constexpr uint32_t k_op_stage_count = 3;
const char* to_string(OpStage stage);

// What one stream operation does. Shading kinds are the Fig. 4 filter stack, in stack order.
enum class OpKind : uint8_t {
    camera,           // shading: generate the tile's primary rays (object: none)
    box_test,         // traversal: ray/box filter (object: BVH node index)
    triangle_test,    // intersection: ray/triangle test (object: global primitive id)
    sphere_test,      // intersection: ray/sphere test (object: global primitive id)
    shadow_filter,    // shading: extract shadow rays (passed); each adds its light unless occluded
    miss_filter,      // shading: extract rays that left the scene; passed = miss
    emission_filter,  // shading: the hits' surfaces, then light hits; passed = emissive
    depth_filter,     // shading: passed = the path may scatter (bounce < max depth)
    material_filter,  // shading: passed = the hit material is `object` (material id)
    ambient,          // shading: add the constant ambient term; all pass
    lambertian_choice,    // shading: passed = samples direct light (else indirect)
    lambertian_direct,    // shading: passed = a shadow ray was pushed to the next generation
    lambertian_indirect,  // shading: passed = a bounce ray was pushed
    dielectric,           // shading: passed = a reflected or refracted ray was pushed
    glossy,               // shading: passed = a glossy bounce ray was pushed
    // Primary entry search (PrimaryEntry::aepsa, kernels/stream/entry_point.h):
    frustum_bounds,  // traversal: reduce the tile's primary stream to a frustum; all pass
    frustum_test,    // traversal: the frustum (one lane) against a node's box (object: node)
    // Hit-point reordering (RayReorder::hit_point, kernels/stream/hit_point_reorder.h):
    reorder_lod_test,  // traversal: the simplified hierarchy's box filter (object: node)
    reorder_key,       // traversal: approximate hit point to a two-level Z-curve key; all pass
    reorder_sort,      // traversal: one merge pass of the sort by key; all pass
    // RayGrid batching (RayBatching::raygrid, kernels/stream/ray_grid.h):
    raygrid_walk,     // traversal: the cell walk's filter over a node above or at the cell cut
                      // (object: node); passed = the ray may find its next cell below it
    raygrid_enqueue,  // traversal: append the rays that found a next cell to its queue; all pass
    count
};
constexpr uint32_t k_op_kind_count = uint32_t(OpKind::count);

// Which scene feature makes a kind of operation exist (model only what a scene needs).
enum class OpFeature : uint8_t {
    always,
    triangles,
    spheres,
    lights,
    ambient,
    lambertian,
    lambertian_and_lights,
    dielectric,
    glossy,
    primary_entry_aepsa,  // workload options, not scene features: RenderSettings::primary_entry
    reorder_hit_point,    // RenderSettings::reorder
    batching_raygrid      // RenderSettings::batching
};

// The op table: everything about a kind of operation that does not depend on the hardware, in
// one place, read by the tracer's users and every timing model (the hardware's cost profile of
// each kind lives in hw_model/op_costs.cpp, keyed by the same enum).
struct OpKindInfo {
    const char* name;
    OpStage stage;
    bool partitions;   // the filter's mask partitions the stream in place (G&R 3.1)
    bool pushes_rays;  // passing lanes write a ray (and its id) to the next-generation buffer
    OpFeature feature;
    // Reads, per lane, the scene data of the primitive its ray hit (the hit's surface: its
    // triangle's vertices or its sphere), at an address that differs from lane to lane.
    bool reads_hit_primitive = false;
};
inline constexpr OpKindInfo k_op_kinds[k_op_kind_count] = {
    {"camera", OpStage::shading, false, true, OpFeature::always},
    {"box_test", OpStage::traversal, true, false, OpFeature::always},
    {"triangle_test", OpStage::intersection, false, false, OpFeature::triangles},
    {"sphere_test", OpStage::intersection, false, false, OpFeature::spheres},
    {"shadow_filter", OpStage::shading, true, false, OpFeature::lights},
    {"miss_filter", OpStage::shading, true, false, OpFeature::always},
    {"emission_filter", OpStage::shading, true, false, OpFeature::always, true},
    {"depth_filter", OpStage::shading, true, false, OpFeature::always},
    {"material_filter", OpStage::shading, true, false, OpFeature::always},
    {"ambient", OpStage::shading, false, false, OpFeature::ambient},
    {"lambertian_choice", OpStage::shading, true, false, OpFeature::lambertian},
    {"lambertian_direct", OpStage::shading, false, true, OpFeature::lambertian_and_lights},
    {"lambertian_indirect", OpStage::shading, false, true, OpFeature::lambertian},
    {"dielectric", OpStage::shading, false, true, OpFeature::dielectric},
    {"glossy", OpStage::shading, false, true, OpFeature::glossy},
    {"frustum_bounds", OpStage::traversal, false, false, OpFeature::primary_entry_aepsa},
    {"frustum_test", OpStage::traversal, false, false, OpFeature::primary_entry_aepsa},
    {"reorder_lod_test", OpStage::traversal, true, false, OpFeature::reorder_hit_point},
    {"reorder_key", OpStage::traversal, false, false, OpFeature::reorder_hit_point},
    {"reorder_sort", OpStage::traversal, false, false, OpFeature::reorder_hit_point},
    {"raygrid_walk", OpStage::traversal, true, false, OpFeature::batching_raygrid},
    {"raygrid_enqueue", OpStage::traversal, false, false, OpFeature::batching_raygrid},
};
inline const OpKindInfo& op_info(OpKind kind) {
    return k_op_kinds[size_t(kind)];
}
inline const char* to_string(OpKind kind) {
    return kind < OpKind::count ? op_info(kind).name : "?";
}
inline OpStage stage_of(OpKind kind) {
    return op_info(kind).stage;
}
// The kind called `name` (k_op_kinds), or OpKind::count if there is none.
inline OpKind op_kind_named(const std::string& name) {
    for (uint32_t k = 0; k < k_op_kind_count; ++k)
        if (name == k_op_kinds[k].name) return OpKind(k);
    return OpKind::count;
}
// The kind exists because of a workload option (a seed paper's alternative), not the scene.
inline bool is_option_kind(OpKind kind) {
    const OpFeature f = op_info(kind).feature;
    return f == OpFeature::primary_entry_aepsa || f == OpFeature::reorder_hit_point ||
           f == OpFeature::batching_raygrid;
}

constexpr uint32_t k_no_object = 0xffffffffu;

// The tracers' BVH is laid out depth first (kernels/bvh.h): a box test's node's left child is
// stored right after it, so its index follows from the node's, while the right child's index
// and a leaf's primitives are read from the node's record.
constexpr uint32_t left_child_index(uint32_t node) {
    return node + 1;
}

// The native tracer's loops by stream length: a stream of one ray runs its whole subtree in the
// one-ray loop (traverse_one), and, on back ends of k_few_ray_min_width lanes or more, a stream
// of 2 to k_few_ray_lanes rays in the few-ray loop (traverse_few: the rays' box fields in one
// register of k_few_ray_lanes lanes, each stream a mask of them, no ids partitioned), whose box
// tests are not the stream loop's. Neither changes an op, its order or a bit of the trace.
constexpr uint32_t k_few_ray_lanes = 4;
constexpr uint32_t k_few_ray_min_width = 8;
// An op the few-ray loop runs itself on a back end of `width` lanes: a box test of 2 to
// k_few_ray_lanes lanes (its leaves' tests are the stream loop's leaf code).
inline bool runs_in_few_ray_loop(OpKind kind, uint32_t length, uint32_t width) {
    return kind == OpKind::box_test && length >= 2 && length <= k_few_ray_lanes &&
           width >= k_few_ray_min_width;
}

// The lane groups an op of `length` lanes takes on a SIMD unit of `width` lanes.
inline uint32_t lane_groups(uint32_t length, uint32_t width) {
    return (length + width - 1) / width;
}

// The native tracer's loop that runs a box test: a stream of one ray runs its subtree in the
// one-ray loop, one of 2 to k_few_ray_lanes rays (a wide back end) in the few-ray loop, and every
// op below either is that loop's; `producer` is the loop of the op whose partition produced the
// stream (stream for a traversal's first op). Indexes RenderStats::short_loop_tsc.
enum class TraversalLoop : uint8_t { one_ray, few_ray, stream };
inline TraversalLoop traversal_loop(uint32_t length, uint32_t width, TraversalLoop producer) {
    if (producer != TraversalLoop::stream) return producer;
    if (length == 1) return TraversalLoop::one_ray;
    if (runs_in_few_ray_loop(OpKind::box_test, length, width)) return TraversalLoop::few_ray;
    return TraversalLoop::stream;
}

// One stream operation. `slots` and `passed` are views valid only during the sink call.
// Built by aggregate initialization in field order, so an emitter names every field it sets in
// one expression (and the kernels' copies stay inline).
struct StreamOp {
    OpKind kind = OpKind::box_test;
    OpStage stage = OpStage::traversal;
    uint16_t generation = 0;  // ray generation of the stream: 0 = camera rays
    uint32_t object = k_no_object;
    uint32_t length = 0;              // stream length (lanes that carry a ray)
    uint32_t pass_count = 0;          // how many slots passed
    const uint32_t* slots = nullptr;  // ray slots in stream order (slot < TilePass::slot_count)
    const uint8_t* passed = nullptr;  // per position in `slots`: 1 passed, 0 failed
    // Failing lanes that ran the op's full test: a triangle test's candidates (lanes its float
    // edge stage did not reject: the ray's line crosses the triangle) that found no closer hit,
    // behind the origin (a secondary ray's own surface) or beyond the ray's hit so far. Each
    // does about two thirds of a passing lane's work (OpCostConfig::
    // per_failed_candidate_cycles); 0 for every other kind.
    uint32_t failed_candidates = 0;
    // The box test a traversal starts with (its entry node's): a CPU core's traversal pays its
    // set-up there (OpCostConfig::traversal_start_cycles), once per traversal whatever its ops.
    bool starts_traversal = false;
    // Of an op that starts a traversal: its stream's rays all share one origin (a pinhole
    // camera's), so that the native tracer's check of that (shared_origin) read every lane's
    // origin (OpCostConfig::shared_origin_per_lane_cycles); otherwise it stopped at the first
    // that differed, in practice the second.
    bool origin_shared = false;
};

// One tile pass: one sample of every pixel of a tile, traced breadth-first to the end.
struct TilePass {
    uint32_t tile = 0;  // index into make_tiles(width, height, tile_size)
    uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    uint32_t sample = 0;
    uint32_t slot_count = 0;   // ray slots in the buffer: (x1-x0)*(y1-y0); slot = path
    uint32_t generations = 0;  // set at end_pass: how many generations were traced
};

// How the stream tracer enters the BVH with a tile's primary rays: at the root, or at the
// deepest node a frustum of the tile's rays proves enough (AEPSA, kernels/stream/entry_point.h).
// Never changes a hit, so never the image; adds the search's ops to the trace.
enum class PrimaryEntry : uint8_t { root, aepsa };
// Whether the stream tracer sorts each generation's stream by approximate hit point before
// tracing it (Moon et al., kernels/stream/hit_point_reorder.h). Never changes a bit of the
// image; reorders the trace's streams and adds the sort's ops.
enum class RayReorder : uint8_t { none, hit_point };
// Whether the stream tracer batches secondary rays in the cells of a cut of the BVH and traces
// each cell's queue against the cell's subtree (Bikker's RayGrid, kernels/stream/ray_grid.h).
// Never changes a bit of the image; splits the trace's secondary streams by cell and adds the
// queueing's ops.
enum class RayBatching : uint8_t { none, raygrid };

// Everything besides the scene that decides a render's trace, declared once: the tracers'
// RenderSettings derive from it and the trace header carries it, so a new such knob is one
// member here and one line in visit() (which is also its place in the trace file; a new field
// goes last, with a new TraceHeader::k_version).
struct TraceFrame {
    uint32_t width = 256;
    uint32_t height = 256;
    uint32_t spp = 4;
    uint32_t max_depth = 3;  // bounces after the camera ray (the scene's value unless overridden)
    uint32_t tile = 32;      // tile edge in pixels; the stream tracer's stream is tile^2 rays
    uint64_t seed = 0;
    PrimaryEntry primary_entry = PrimaryEntry::root;  // stream tracer only
    RayReorder reorder = RayReorder::none;            // stream tracer only
    uint32_t reorder_lod_ppm = 20000;  // simplified geometry: parts per million of the primitives
    RayBatching batching = RayBatching::none;  // stream tracer only
    uint32_t batching_queue = 384;             // raygrid: rays per queue (seeds/000 Sec. 3.5)
    uint32_t batching_cell_prims = 4096;       // raygrid: most primitives under one cell

    // Every field in trace-file order (version 1 ends after seed, version 2 after
    // reorder_lod_ppm).
    template <class V>
    void visit(V&& v) {
        v(width);
        v(height);
        v(spp);
        v(tile);
        v(max_depth);
        v(seed);
        v(primary_entry);
        v(reorder);
        v(reorder_lod_ppm);
        v(batching);
        v(batching_queue);
        v(batching_cell_prims);
    }
    static constexpr uint32_t k_version1_fields = 6;
    static constexpr uint32_t k_version2_fields = 9;
};

// What a trace is of; written at the head of a trace file. Version 2 added the seed papers'
// options (primary_entry, reorder, reorder_lod_ppm), version 3 RayGrid batching (batching,
// batching_queue, batching_cell_prims), version 4 each op's failed candidates, version 5 whether
// it starts a traversal, version 6 whether that traversal's rays share one origin (the same
// byte); an older file reads with the later fields' defaults (an op's failed candidates 0, no op
// starting a traversal, no stream sharing an origin).
struct TraceHeader : TraceFrame {
    static constexpr uint32_t k_version = 6;
    uint32_t version = k_version;
    uint64_t scene_hash = 0;  // workloads/scene.h's scene_hash()
};

// Receives a trace. Calls come from one thread at a time, in tile order, sample order.
class TraceSink {
  public:
    virtual ~TraceSink() = default;
    virtual void begin_frame(const TraceHeader&) {}
    virtual void begin_pass(const TilePass&) {}
    virtual void op(const StreamOp&) = 0;
    // `count` ops of kind `kind` and `length` lanes each (length > 0), with `passed` passing
    // lanes and `failed_candidates` (StreamOp::failed_candidates) among them, in place of
    // `count` op() calls: the stream tracer sends a traversal's ops this way, at the
    // traversal's end, to a sink that reads counts only (counts_only), which can add them at
    // once. Their objects, their places in the op order and how the passes and failed
    // candidates split among them are left unsaid; the traversal's first op still comes first,
    // by op(). The default calls op() for each.
    virtual void ops_of_length(OpKind kind, OpStage stage, uint16_t generation, uint32_t length,
                               uint32_t count, uint32_t passed, uint32_t failed_candidates);
    virtual void end_pass(const TilePass&) {}
    virtual void end_frame() {}
    // True if the sink reads counts only: never an op's slots or pass flags, nor the frame
    // header's scene hash. The stream tracer then leaves those null or zero, runs its filters
    // as without a trace (one pass, no mask) and hashes no scene.
    virtual bool counts_only() const { return false; }
};

// Counts lanes and ops: op counts, stream-length histograms and the ideal SIMD utilization
// for many widths at once, per stage, for primary (generation 0) and secondary rays apart.
class CountingSink : public TraceSink {
  public:
    struct StageCounts {
        uint64_t ops = 0;
        uint64_t lanes = 0;               // sum of stream lengths
        uint64_t passed = 0;              // sum of pass counts
        std::vector<uint64_t> groups;     // per width: sum of ceil(len / width)
        std::vector<uint64_t> histogram;  // stream lengths in buckets [2^k, 2^(k+1)), k < 32

        // Ideal utilization at widths[i]: lanes / (width * groups).
        double utilization(size_t width_index, uint32_t width) const;
        double average_length() const { return ops ? double(lanes) / double(ops) : 0.0; }
    };
    static constexpr uint32_t k_histogram_buckets = 32;

    explicit CountingSink(std::vector<uint32_t> widths);
    void begin_pass(const TilePass&) override;
    void op(const StreamOp& op) override;
    void ops_of_length(OpKind kind, OpStage stage, uint16_t generation, uint32_t length,
                       uint32_t count, uint32_t passed, uint32_t failed_candidates) override;
    void end_pass(const TilePass&) override;
    bool counts_only() const override { return true; }

    const std::vector<uint32_t>& widths() const { return m_widths; }
    // [secondary][stage]: secondary = generation > 0.
    const StageCounts& stage(bool secondary, OpStage s) const {
        return m_stages[secondary][uint32_t(s)];
    }
    uint64_t kind_ops(OpKind k) const;
    uint64_t kind_lanes(OpKind k) const;
    // Lanes of one kind in primary (generation 0) or secondary streams.
    uint64_t kind_lanes(OpKind k, bool secondary) const;
    uint64_t passes() const { return m_passes; }
    uint64_t generations() const { return m_generations; }
    // Rays traced: the lanes of each generation's first box test (its entry node: the root, or
    // a primary entry point).
    uint64_t rays() const;
    uint64_t rays(bool secondary) const;
    // Per generation (bounce; the last slot holds every later one): rays traced, box tests
    // (ops, lanes: rays per visited node, seeds/000 Tables 2 and 4) and primitive tests (each op
    // of a leaf carries the rays that reached it: rays per visited leaf).
    struct BounceCounts {
        uint64_t rays = 0, box_ops = 0, box_lanes = 0, prim_ops = 0, prim_lanes = 0;
        double rays_per_node() const { return box_ops ? double(box_lanes) / box_ops : 0.0; }
        double rays_per_leaf() const { return prim_ops ? double(prim_lanes) / prim_ops : 0.0; }
        double box_tests_per_ray() const { return rays ? double(box_lanes) / rays : 0.0; }
    };
    static constexpr uint32_t k_bounce_slots = 5;
    BounceCounts bounce(uint32_t generation) const;

    CountingSink& operator+=(const CountingSink& o);

  private:
    std::vector<uint32_t> m_widths;
    StageCounts m_stages[2][k_op_stage_count];
    // Ops and lanes per generation slot (as bounce()'s) and kind: every per-kind and per-bounce
    // figure is a sum of these, so an op adds to one of them only (the sink is on the path
    // tracer's hot path: hundreds of thousands of ops a frame).
    struct KindTally {
        uint64_t ops = 0, lanes = 0;
    };
    KindTally m_kinds[k_bounce_slots][k_op_kind_count];
    uint64_t m_rays[k_bounce_slots] = {};  // per generation slot
    uint64_t m_passes = 0, m_generations = 0;
    int32_t m_traced_generation = -1;  // the last generation of this pass whose rays were counted
};

// Writes the trace to a binary file (format in trace.cpp); memory stays one op at a time.
class TraceFileWriter : public TraceSink {
  public:
    explicit TraceFileWriter(const std::string& path);
    ~TraceFileWriter() override;
    void begin_frame(const TraceHeader& h) override;
    void begin_pass(const TilePass& p) override;
    void op(const StreamOp& op) override;
    void end_pass(const TilePass& p) override;
    void end_frame() override;
    uint64_t bytes_written() const { return m_bytes; }

  private:
    void write(const void* data, size_t n);
    std::string m_path, m_tmp;
    std::FILE* m_file = nullptr;
    uint64_t m_bytes = 0;
    std::vector<uint8_t> m_bits;
};

// Reads a trace file and replays it into a sink; returns its header. Throws on a bad file.
TraceHeader read_trace_file(const std::string& path, TraceSink& sink);

// Keeps one tile pass in memory and replays it into a sink (used to order traces of passes
// traced on several threads; also handy in tests).
class TraceRecorder : public TraceSink {
  public:
    void begin_pass(const TilePass& p) override;
    void op(const StreamOp& op) override;
    void end_pass(const TilePass& p) override;
    void replay(TraceSink& sink) const;  // the recorded pass, begin to end
    void clear();
    size_t op_count() const { return m_ops.size(); }

  private:
    struct Record {
        OpKind kind;
        OpStage stage;
        uint16_t generation;
        uint32_t object, length, pass_count, failed_candidates;
        bool starts_traversal, origin_shared;
        size_t offset;
    };
    TilePass m_pass;
    std::vector<Record> m_ops;
    std::vector<uint32_t> m_slots;
    std::vector<uint8_t> m_passed;
};

}  // namespace sfx
