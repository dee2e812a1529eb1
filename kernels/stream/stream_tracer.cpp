#include "kernels/stream/stream_tracer.h"

#include <x86intrin.h>

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "base/host_clock.h"
#include "kernels/camera.h"
#include "kernels/reference/reference_tracer.h"
#include "kernels/stream/entry_point.h"
#include "kernels/stream/hit_point_reorder.h"
#include "kernels/stream/ray_grid.h"
#include "kernels/stream/stream_filter.h"
#include "kernels/stream/stream_kernels.h"

namespace sfx {

namespace {

// The ray buffers of one stream, one array per field group (structure of arrays). A slot is a
// path: a path carries one ray at a time, so its next ray goes to the same slot of the
// next-generation buffer, and streams are lists of slots.
struct RayBuffers {
    uint32_t capacity = 0;
    std::vector<PathState> path;
    std::vector<Ray> ray[2];      // current and next generation
    TraversalRays trav;           // the filters' fields, t included
    std::vector<RayPrecomp> pre;  // the full primitive tests' constants
    std::vector<Hit> hit;
    std::vector<uint8_t> any_hit;  // shadow ray: any hit in (0, t_max) occludes it
    std::vector<SurfaceHit> surf;
    // Id lists and masks have k_stream_padding elements of room: compress writes whole vectors.
    std::vector<uint32_t> ids, next_ids, trav_ids, scratch, scratch2, positions;
    std::vector<uint8_t> mask;
    std::vector<uint32_t> op_tally;  // TraversalJob::op_tally

    void ensure(uint32_t n) {
        if (n <= capacity) return;
        capacity = n;
        path.resize(n);
        ray[0].resize(n);
        ray[1].resize(n);
        Ray unit;
        unit.dir = {0.f, 0.f, 1.f};
        trav.resize(n);
        pre.resize(n, RayPrecomp(unit));
        hit.resize(n);
        any_hit.resize(n);
        surf.resize(n);
        const uint32_t padded = n + k_stream_padding;
        ids.resize(padded);
        next_ids.resize(padded);
        trav_ids.resize(padded);
        scratch.resize(padded);
        scratch2.resize(padded);
        positions.resize(size_t(k_leaf_batch) * padded);
        mask.resize(padded);
        op_tally.assign(op_tally_size(n), 0);
    }
};

// The ray buffers tracers leave (release_kept_ray_buffers): a tracer takes a set from here and
// gives it back, so that a render finds the buffers of the render before it, as the timing
// model's warm frame does (predict() in sweeps/host_calibration.h). Made with each render's
// tracers until 2026-12-05, they were value-initialised every render, a cost the model does not
// price: on an AMD Zen 5 VM (AVX2, furnace 64 x 64) 55 K TSC ticks of a 1.6 M frame at tile 64,
// 13 K at tile 32, and a 64-pixel tile's 1.35 MB of zeros swept the L2 before the frame began.
class RayBufferPool {
  public:
    std::unique_ptr<RayBuffers> take() {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (m_free.empty()) return std::make_unique<RayBuffers>();
        std::unique_ptr<RayBuffers> kept = std::move(m_free.back());
        m_free.pop_back();
        return kept;
    }
    void give(std::unique_ptr<RayBuffers> buffers) {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_free.push_back(std::move(buffers));
    }

    void clear() {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_free.clear();
    }

  private:
    std::mutex m_mutex;
    std::vector<std::unique_ptr<RayBuffers>> m_free;
};

RayBufferPool& ray_buffer_pool() {
    static RayBufferPool pool;
    return pool;
}

// Stable partition of ids[0, len) by mask (passing ids first, in order; failing ones after,
// through `spill`) for the scalar traversals of the seed options (the RayGrid walk, the
// reordering's proxy hierarchy). Returns the passing count; `negative` counts the passing
// rays whose direction is negative on `axis` (the front-child vote).
uint32_t partition_and_vote(uint32_t* ids, uint32_t len, const uint8_t* mask, uint32_t* spill,
                            const RayPrecomp* pre, int axis, uint32_t& negative) {
    uint32_t passed = 0, spilled = 0;
    for (uint32_t j = 0; j < len; ++j) {
        const uint32_t id = ids[j];
        if (!mask[j]) {
            spill[spilled++] = id;
            continue;
        }
        ids[passed++] = id;
        negative += pre[id].dir[axis] < 0.f;
    }
    std::copy(spill, spill + spilled, ids + passed);
    return passed;
}

// How much of each op a trace policy reports (stream_filter.h).
template <class Trace>
constexpr TraceDetail trace_detail() {
    return !Trace::k_enabled ? TraceDetail::none
           : Trace::k_lanes  ? TraceDetail::lanes
                             : TraceDetail::counts;
}

// The stage clock's ticks in a generation's traversal: in leaves, and in the one-ray and
// few-ray loops less their leaves (TraversalJob::leaf_tsc, short_loops).
struct TraversalClock {
    uint64_t leaf = 0;
    ShortLoopClock short_loops;
};

// Fig. 3: test the stream against the node's box, filter, stop on empty; at a leaf intersect
// each primitive with the sub-stream; else the front child, then the back child. Closest-hit
// rays tighten their t as they find hits; shadow rays leave the stream once occluded.
// The front child is chosen by a majority of the passing rays' direction signs on the split
// axis: independent of the order of the stream, and for one ray the reference's choice.
// Every stream on the stack is a prefix of the traversal stream: filters move passing ids to
// the front and only permute inside a prefix, so (node, length) names a stream.
// `entry`: the node the stream enters at (the root, or a primary entry point whose subtree
// holds every leaf the stream's rays can reach). The loop is the back end's
// (StreamKernels::traverse), so its box filter and leaf tests run at the host's width without a
// table call.
template <class Trace>
void traverse(const StreamKernels& kernels, const Bvh& bvh, RayBuffers& b, uint32_t n,
              uint16_t generation, Trace& trace, uint32_t entry = 0,
              TraversalClock* clock = nullptr) {
    if (n == 0) return;
    TraversalJob job = traversal_job(bvh, b);
    job.ids = b.trav_ids.data();
    job.n = n;
    job.shared_origin = shared_origin(job.rays, job.ids, n);
    job.entry = entry;
    job.sink = nullptr;
    if constexpr (Trace::k_enabled) job.sink = trace.sink;
    job.generation = generation;
    job.leaf_tsc = clock ? &clock->leaf : nullptr;
    job.short_loops = clock ? &clock->short_loops : nullptr;
    kernels.traverse[int(trace_detail<Trace>())](job);
}

// Loads rays[ids[i]] for traversal; invalid rays (NaN/Inf, zero direction) stay out of the
// stream and miss, as in Bvh::intersect. Returns the traversal stream length.
uint32_t load_rays(RayBuffers& b, const Ray* rays, uint32_t n) {
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t id = b.ids[i];
        if (set_up_ray(rays[id], b.path[id].kind == RayKind::shadow, id, b.any_hit[id], b.hit[id],
                       b.pre[id], b.trav))
            b.trav_ids[m++] = id;
    }
    return m;
}

}  // namespace

struct StreamTracer::Impl {
    const Scene& scene;
    const Bvh& bvh;
    RenderSettings settings;
    const StreamKernels& kernels;
    CameraFrame camera;
    std::vector<uint32_t> material_rays;  // per material: rays of the stream that hit it
    std::vector<uint32_t> present;        // materials hit in this generation, in id order
    std::vector<uint32_t> material_next;  // per material: where its next ray goes in the sort
    // Every slot a pass reads, it writes first: a kept set's last contents never show.
    std::unique_ptr<RayBuffers> kept = ray_buffer_pool().take();
    RayBuffers& b = *kept;
    // Hit-point reordering (RenderSettings::reorder): the simplified hierarchy and its buffers.
    std::unique_ptr<HitPointReorder> reorder;
    struct ReorderBuffers {
        std::vector<RayPrecomp> pre;
        std::vector<float> t, entry;  // per slot: nearest proxy entry so far, this node's entry
        std::vector<uint64_t> key;
        std::vector<uint32_t> ids, spill, merged;
        std::vector<uint8_t> mask, ones;
        std::vector<std::pair<uint32_t, uint32_t>> stack;
    } rb;
    // RayGrid batching (RenderSettings::batching): the cell cut, per-slot walk state, queues.
    std::unique_ptr<RayGrid> grid;
    struct GridBuffers {
        std::vector<float> last_entry, best_entry;  // per slot: the cell it was in, the next one
        std::vector<uint32_t> last_cell, best_cell;
        std::vector<uint32_t> ids, spill, pushed;
        std::vector<uint8_t> mask, ones;
        std::vector<std::pair<uint32_t, uint32_t>> stack;
        std::vector<std::vector<uint32_t>> open;  // per cell: its partially filled queue
        std::vector<std::pair<uint32_t, std::vector<uint32_t>>> full;  // full queues, in order
        std::vector<std::vector<uint32_t>> empty;                      // storage to reuse
    } gb;

    Impl(const Scene& s, const Bvh& h, const RenderSettings& r)
        : scene(s),
          bvh(h),
          settings(r),
          kernels(stream_kernels(resolve_isa(r.isa))),
          camera(s.camera, r.width, r.height),
          material_rays(s.materials.size(), 0),
          material_next(s.materials.size(), 0) {
        if (r.reorder == RayReorder::hit_point)
            reorder = std::make_unique<HitPointReorder>(h, r.reorder_lod_ppm);
        if (r.batching == RayBatching::raygrid && !h.nodes().empty()) {
            grid = std::make_unique<RayGrid>(h, r.batching_cell_prims);
            gb.open.resize(grid->cell_count());
        }
    }
    ~Impl() { ray_buffer_pool().give(std::move(kept)); }
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    // The cell walk of RayGrid for ids[0, n): each ray's next cell after (last_entry,
    // last_cell), the smallest (entry, cell) beyond it among the cut's boxes its slab test
    // passes with its current t. A stream filter over the nodes above the cut, branch and
    // bound per ray: a node passes a ray if the ray enters it no later than its best cell so
    // far and leaves it no earlier than its last cell (one raygrid_walk op per node). Then the
    // rays that found a cell are appended to its queue (one raygrid_enqueue op); the others
    // are done with this generation.
    template <class Trace>
    void grid_walk(const uint32_t* ids, uint32_t n, uint16_t generation, Trace& trace) {
        GridBuffers& g = gb;
        const BvhNodes& nodes = bvh.nodes();
        TraversalRays& rays = b.trav;
        for (uint32_t i = 0; i < n; ++i) {
            g.ids[i] = ids[i];
            g.best_entry[ids[i]] = INFINITY;
            g.best_cell[ids[i]] = RayGrid::k_no_cell;
        }
        g.stack.clear();
        if (n) g.stack.push_back({0u, n});
        while (!g.stack.empty()) {
            const auto [node_index, len] = g.stack.back();
            g.stack.pop_back();
            const BvhNode& node = nodes[node_index];
            const uint32_t cell = grid->cell_of(node_index);
            uint32_t passed = 0;
            for (uint32_t j = 0; j < len; ++j) {
                const uint32_t id = g.ids[j];
                const float e = intersect_box(b.pre[id], node.bounds, rays.t(id));
                bool pass = e != INFINITY;
                if (pass && cell != RayGrid::k_no_cell) {
                    const auto key = std::make_pair(e, cell);
                    pass = key > std::make_pair(g.last_entry[id], g.last_cell[id]) &&
                           key < std::make_pair(g.best_entry[id], g.best_cell[id]);
                    if (pass) g.best_entry[id] = e, g.best_cell[id] = cell;
                } else if (pass) {
                    pass = e <= g.best_entry[id] &&
                           RayGrid::box_exit(b.pre[id], node.bounds) >= g.last_entry[id];
                }
                g.mask[j] = pass;
                passed += pass;
            }
            trace.op(OpKind::raygrid_walk, generation, node_index, g.ids.data(), len, g.mask.data(),
                     passed);
            if (passed == 0 || cell != RayGrid::k_no_cell) continue;
            uint32_t negative = 0;
            partition_and_vote(g.ids.data(), len, g.mask.data(), g.spill.data(), b.pre.data(),
                               node.axis, negative);
            const bool right_first = 2 * negative > passed;
            const uint32_t left = BvhNode::left(node_index), right = node.right();
            g.stack.push_back({right_first ? left : right, passed});
            g.stack.push_back({right_first ? right : left, passed});
        }
        uint32_t pushed = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t id = ids[i], cell = g.best_cell[id];
            if (cell == RayGrid::k_no_cell) continue;
            g.last_entry[id] = g.best_entry[id];
            g.last_cell[id] = cell;
            g.pushed[pushed++] = id;
            std::vector<uint32_t>& q = g.open[cell];
            if (q.capacity() == 0 && !g.empty.empty()) {
                q = std::move(g.empty.back());
                g.empty.pop_back();
            }
            q.push_back(id);
            if (q.size() >= settings.batching_queue) {  // decoupled from the cell, traced first
                g.full.emplace_back(cell, std::move(q));
                q = {};
            }
        }
        if (pushed)
            trace.op(OpKind::raygrid_enqueue, generation, k_no_object, g.pushed.data(), pushed,
                     g.ones.data(), pushed);
    }

    // A generation's traversal stream trav_ids[0, n) by RayGrid (Algorithm 1): every ray to
    // its first cell's queue, then queues traced against their cell's subtree, full ones
    // first, then the partial ones, largest first (ties: lower cell), each followed by the
    // walk of its rays to their next cells, until every queue is empty.
    template <class Trace>
    void traverse_batched(uint32_t n, uint16_t generation, RenderStats& stats, Trace& trace,
                          TraversalClock* clock) {
        GridBuffers& g = gb;
        if (g.ids.size() < b.capacity) {
            g.last_entry.resize(b.capacity);
            g.best_entry.resize(b.capacity);
            g.last_cell.resize(b.capacity);
            g.best_cell.resize(b.capacity);
            g.ids.resize(b.capacity);
            g.spill.resize(b.capacity);
            g.pushed.resize(b.capacity);
            g.mask.resize(b.capacity);
            g.ones.assign(b.capacity, 1);
        }
        std::vector<uint32_t> stream(b.trav_ids.begin(), b.trav_ids.begin() + n);
        for (uint32_t id : stream) {
            g.last_entry[id] = -INFINITY;
            g.last_cell[id] = 0;
        }
        grid_walk(stream.data(), n, generation, trace);
        size_t next_full = 0;
        while (true) {
            uint32_t cell = RayGrid::k_no_cell;
            std::vector<uint32_t> q;
            if (next_full < g.full.size()) {
                cell = g.full[next_full].first;
                q = std::move(g.full[next_full].second);
                ++next_full;
                ++stats.batch_full_queues;
            } else {
                size_t largest = 0;
                for (uint32_t c = 0; c < g.open.size(); ++c)
                    if (g.open[c].size() > largest) largest = g.open[c].size(), cell = c;
                if (cell == RayGrid::k_no_cell) break;
                q = std::move(g.open[cell]);
                g.open[cell] = {};
            }
            ++stats.batch_queues;
            stats.batch_queued_rays += q.size();
            const uint32_t len = uint32_t(q.size());
            std::copy(q.begin(), q.end(), b.trav_ids.begin());
            traverse(kernels, bvh, b, len, generation, trace, grid->cell_node(cell), clock);
            grid_walk(q.data(), len, generation, trace);
            q.clear();
            g.empty.push_back(std::move(q));
        }
        g.full.clear();
    }

    // The generation's traversal: plain (Fig. 3 from `entry`), or batched for secondary rays.
    template <class Trace>
    void traverse_generation(uint32_t n, uint16_t generation, uint32_t entry, RenderStats& stats,
                             Trace& trace, TraversalClock* clock) {
        if (grid && generation > 0)
            traverse_batched(n, generation, stats, trace, clock);
        else
            traverse(kernels, bvh, b, n, generation, trace, entry, clock);
    }

    // Moon et al.'s reordering of the stream ids[0, n) before it is traced: approximate hit
    // points by a traversal of the simplified hierarchy (reorder_lod_test ops, Fig. 3's
    // filter over the proxies' tree), their keys (one reorder_key op over the stream), and a
    // bottom-up 2-way merge sort of the stream by key (one reorder_sort op per merge pass,
    // listing the stream in that pass's order; the paper's sort, Sec. 5). Stable, so equal
    // keys keep their order and the result never depends on anything but the stream.
    template <class Trace>
    void reorder_stream(uint32_t* ids, uint32_t n, const Ray* rays, uint16_t generation,
                        Trace& trace) {
        if (n < 2) return;
        ReorderBuffers& r = rb;
        if (r.pre.size() < b.capacity) {
            Ray unit;
            unit.dir = {0.f, 0.f, 1.f};
            r.pre.resize(b.capacity, RayPrecomp(unit));
            r.t.resize(b.capacity);
            r.entry.resize(b.capacity);
            r.key.resize(b.capacity);
            r.ids.resize(b.capacity);
            r.spill.resize(b.capacity);
            r.merged.resize(b.capacity);
            r.mask.resize(b.capacity);
            r.ones.assign(b.capacity, 1);
        }
        const BvhNodes& nodes = bvh.nodes();
        uint32_t m = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t id = ids[i];
            r.key[id] = HitPointReorder::k_no_key;
            if (!ray_is_valid(rays[id])) continue;
            r.pre[id] = RayPrecomp(rays[id]);
            r.t[id] = rays[id].t_max;
            r.ids[m++] = id;
        }
        r.stack.clear();
        if (m && !nodes.empty()) r.stack.push_back({0u, m});
        while (!r.stack.empty()) {
            const auto [node_index, len] = r.stack.back();
            r.stack.pop_back();
            const BvhNode& node = nodes[node_index];
            for (uint32_t j = 0; j < len; ++j) {
                const uint32_t id = r.ids[j];
                r.entry[id] = intersect_box(r.pre[id], node.bounds, r.t[id]);
                r.mask[j] = r.entry[id] != INFINITY;
            }
            trace.op(OpKind::reorder_lod_test, generation, node_index, r.ids.data(), len,
                     r.mask.data(), uint32_t(std::count(r.mask.begin(), r.mask.begin() + len, 1)));
            uint32_t negative = 0;
            const uint32_t passed = partition_and_vote(r.ids.data(), len, r.mask.data(),
                                                       r.spill.data(), r.pre.data(), node.axis,
                                                       negative);
            if (passed == 0) continue;
            if (reorder->is_proxy(node_index)) {
                // A proxy box hit from outside: the nearest so far is the approximate hit.
                for (uint32_t j = 0; j < passed; ++j) {
                    const uint32_t id = r.ids[j];
                    if (r.entry[id] > 0.f && r.entry[id] < r.t[id]) r.t[id] = r.entry[id];
                }
                continue;
            }
            const bool right_first = 2 * negative > passed;
            const uint32_t left = BvhNode::left(node_index), right = node.right();
            r.stack.push_back({right_first ? left : right, passed});
            r.stack.push_back({right_first ? right : left, passed});
        }
        for (uint32_t i = 0; i < m; ++i) {
            const uint32_t id = r.ids[i];
            const Ray& ray = rays[id];
            const float t =
                r.t[id] < ray.t_max ? r.t[id] : reorder->scene_exit(r.pre[id], ray.t_max);
            if (std::isfinite(t)) r.key[id] = reorder->key(ray.org + ray.dir * t);
        }
        trace.op(OpKind::reorder_key, generation, k_no_object, ids, n, r.ones.data(), n);
        uint32_t* src = ids;
        uint32_t* dst = r.merged.data();
        const auto by_key = [&](uint32_t a, uint32_t c) { return r.key[a] < r.key[c]; };
        for (uint32_t width = 1; width < n; width *= 2) {
            for (uint32_t lo = 0; lo < n; lo += 2 * width) {
                const uint32_t mid = std::min(n, lo + width), hi = std::min(n, lo + 2 * width);
                std::merge(src + lo, src + mid, src + mid, src + hi, dst + lo, by_key);
            }
            std::swap(src, dst);
            trace.op(OpKind::reorder_sort, generation, k_no_object, src, n, r.ones.data(), n);
        }
        if (src != ids) std::copy(src, src + n, ids);
    }

    // AEPSA for the tile's primary stream (trav_ids[0, n)): bounds the rays by a frustum (the
    // frustum_bounds op over the stream), searches the entry point (one frustum_test op per
    // node tested, one lane: the frustum) and returns it.
    template <class Trace>
    uint32_t primary_entry_point(uint32_t n, RenderStats& stats, Trace& trace) {
        if (n == 0) return 0;
        uint32_t* ids = b.trav_ids.data();
        FrustumProxy frustum;
        frustum.build(n, [&](uint32_t i) -> const RayPrecomp& { return b.pre[ids[i]]; });
        if constexpr (Trace::k_enabled) std::fill(b.mask.begin(), b.mask.begin() + n, uint8_t(1));
        trace.op(OpKind::frustum_bounds, 0, k_no_object, ids, n, b.mask.data(), n);
        const EntryPoint e = find_entry_point(bvh, frustum, [&](uint32_t node, bool overlapped) {
            const uint8_t passed = overlapped;
            trace.op(OpKind::frustum_test, 0, node, ids, 1, &passed, passed);
        });
        ++stats.entry_searches;
        stats.entry_depth_sum += e.depth;
        return e.node;
    }

    template <class Trace>
    void run(const TileRect& rect, uint32_t tile_index, uint32_t sample, Vec3* sums,
             RenderStats& stats, Trace& trace, TraceSink* sink, RayObserver* observer);
};

template <class Trace>
void StreamTracer::Impl::run(const TileRect& rect, uint32_t tile_index, uint32_t sample, Vec3* sums,
                             RenderStats& stats, Trace& trace, TraceSink* sink,
                             RayObserver* observer) {
    const uint32_t w = rect.x1 - rect.x0, h = rect.y1 - rect.y0, count = w * h;
    b.ensure(count);
    TilePass info;
    info.tile = tile_index;
    info.x0 = rect.x0;
    info.y0 = rect.y0;
    info.x1 = rect.x1;
    info.y1 = rect.y1;
    info.sample = sample;
    info.slot_count = count;
    if constexpr (Trace::k_enabled) sink->begin_pass(info);

    uint32_t* ids = b.ids.data();
    uint8_t* mask = b.mask.data();
    uint32_t* scratch = b.scratch.data();
    PathState* path = b.path.data();
    const SurfaceHit* surf = b.surf.data();
    const Hit* hit = b.hit.data();
    const uint8_t* any_hit = b.any_hit.data();
    const uint32_t max_depth = settings.max_depth;
    const bool clock = settings.stage_clock;
    const uint64_t pass_start = clock ? __rdtsc() : 0;
    uint64_t traverse_tsc = 0;
    // With the stage clock, the pass is timed in laps (RenderStats::shading_op_tsc and the
    // stages): each read of the TSC ends one part and starts the next, so that the parts tile
    // the pass and each read's cost falls in the parts on either side of it. With a read at the
    // start and one at the end of each part (until 2026-12-05), the two reads between
    // consecutive parts ran back to back, about 20 TSC ticks a part in no part but the shading
    // stage's rest, more of them the smaller the tile: on cornell 128 x 128 at AVX2 (Zen 5),
    // that rest took 131 / 64 / 51 K ticks at tiles 16 / 32 / 64, and 205 / 84 / 57 K with each
    // read doubled; in laps 38-41 K at every tile (the sums into the image).
    uint64_t lap_mark = pass_start;
    auto lap = [&](uint64_t& ticks) {
        if (!clock) return;
        const uint64_t now = __rdtsc();
        ticks += now - lap_mark;
        lap_mark = now;
    };
    // With the part clock, the frame is timed in parts (RenderStats::part_tsc): each generation
    // of the pass, then its end.
    const bool parts = settings.part_clock;
    uint64_t part_mark = parts ? __rdtsc() : 0;
    auto close_frame_part = [&] {
        if (!parts) return;
        const uint64_t now = __rdtsc();
        stats.part_tsc.push_back(now - part_mark);
        stats.part_start_tsc.push_back(part_mark);
        part_mark = now;
    };

    // Camera: the input buffer gets one primary ray per pixel of the tile.
    int cur = 0;
    for (uint32_t slot = 0; slot < count; ++slot) {
        const uint32_t x = rect.x0 + slot % w, y = rect.y0 + slot / w;
        PathState& p = path[slot];
        p = PathState{};
        p.key = {settings.seed, y * settings.width + x, sample};
        b.ray[cur][slot] = camera.generate(p.key);
        ids[slot] = slot;
        mask[slot] = 1;
    }
    stats.camera_rays += count;
    trace.op(OpKind::camera, 0, k_no_object, ids, count, mask, count);
    lap(stats.shading_op_tsc[size_t(OpKind::camera)]);

    uint32_t n = count;
    uint16_t generation = 0;
    while (n > 0) {
        const Ray* rays = b.ray[cur].data();
        Ray* next = b.ray[cur ^ 1].data();
        if (reorder) {
            reorder_stream(ids, n, rays, generation, trace);
            lap(stats.shading_rest_tsc);
        }
        const uint32_t traversal_rays = load_rays(b, rays, n);
        lap(stats.ray_setup_tsc);
        // The entry search (its frustum tests are traversal ops) is in the traversal's lap.
        uint32_t entry = 0;
        if (generation == 0 && settings.primary_entry == PrimaryEntry::aepsa)
            entry = primary_entry_point(traversal_rays, stats, trace);
        if (clock) {
            TraversalClock ticks;
            uint64_t spent = 0;
            traverse_generation(traversal_rays, generation, entry, stats, trace, &ticks);
            lap(spent);
            stats.stage_tsc[0] += spent - ticks.leaf;
            stats.stage_tsc[1] += ticks.leaf;
            for (int l = 0; l < 2; ++l) {
                stats.short_loop_tsc[l] += ticks.short_loops.ticks[l];
                stats.short_loop_leaf_tsc[l] += ticks.short_loops.leaf_ticks[l];
            }
            traverse_tsc += spent;
        } else {
            traverse_generation(traversal_rays, generation, entry, stats, trace, nullptr);
        }
        if (observer)
            for (uint32_t i = 0; i < n; ++i) {
                const uint32_t id = ids[i];
                observer->ray(path[id], rays[id], hit[id], any_hit[id] && hit[id].valid());
            }

        // The shading filter stack (Fig. 4) over the generation's stream; each filter's lap
        // holds the bookkeeping since the lap before it.
        uint32_t pushed = 0;
        uint32_t* next_ids = b.next_ids.data();
        auto run_filter = [&](OpKind kind, uint32_t object, uint32_t* s, uint32_t len,
                              auto&& test) {
            const uint32_t passed =
                filter(kernels, trace, kind, generation, object, s, len, mask, scratch, test);
            lap(stats.shading_op_tsc[size_t(kind)]);
            return passed;
        };
        uint32_t* s = ids;
        uint32_t len = n;
        const uint32_t shadows =
            run_filter(OpKind::shadow_filter, k_no_object, s, len, [&](uint32_t id) {
                if (!any_hit[id]) return false;
                finish_shadow(path[id], hit[id].valid());
                return true;
            });
        s += shadows;
        len -= shadows;
        const uint32_t misses =
            run_filter(OpKind::miss_filter, k_no_object, s, len, [&](uint32_t id) {
                if (hit[id].valid()) return false;
                shade_miss(path[id], scene);
                return true;
            });
        s += misses;
        len -= misses;
        // The hits' surfaces, for the emission filter and the stack below. Timing models
        // price this as part of the emission filter (OpKindInfo::reads_hit_primitive), as the
        // microbenchmarks time it: in the emission filter's lap.
        compute_surfaces(scene, rays, hit, s, len, b.surf.data());
        run_filter(OpKind::emission_filter, k_no_object, s, len, [&](uint32_t id) {
            const Material& m = scene.materials[surf[id].material];
            if (!m.emissive()) return false;
            shade_emission(path[id], m);
            return true;
        });  // light hits reflect too: every hit goes on
        std::fill(material_rays.begin(), material_rays.end(), 0u);
        len = run_filter(OpKind::depth_filter, k_no_object, s, len, [&](uint32_t id) {
            if (!may_scatter(path[id], max_depth)) return false;
            ++material_rays[surf[id].material];  // a by-product of the test's gather
            return true;
        });
        present.clear();
        for (uint32_t m = 0; m < material_rays.size(); ++m)
            if (material_rays[m]) present.push_back(m);

        auto material = [&](uint32_t id) -> const Material& {
            return scene.materials[surf[id].material];
        };
        auto push = [&](uint32_t id, bool shadow) {
            next_ids[pushed++] = id;
            ++(shadow ? stats.shadow_rays : stats.extension_rays);
        };
        // The material filters below leave the stream stably sorted by material, in
        // `present` order. Without a trace of lanes nothing needs their masks, so one counting
        // sort does it here and each filter's op carries only its counts.
        if constexpr (!Trace::k_lanes) {
            if (present.size() > 1) {
                uint32_t start = 0;
                for (const uint32_t m : present) {
                    material_next[m] = start;
                    start += material_rays[m];
                }
                for (uint32_t i = 0; i < len; ++i)
                    scratch[material_next[surf[s[i]].material]++] = s[i];
                std::copy(scratch, scratch + len, s);
            }
        }
        lap(stats.shading_op_tsc[size_t(OpKind::material_filter)]);
        // One sub-stack per material (a shader instance: its constants are uniform over the
        // lanes), for the materials this generation hit; the last one is what is left.
        for (size_t j = 0; j < present.size(); ++j) {
            const uint32_t mat = present[j];
            const MaterialKind kind = scene.materials[mat].kind;
            uint32_t g = len;
            if (j + 1 < present.size()) {
                if constexpr (Trace::k_lanes) {
                    g = run_filter(OpKind::material_filter, mat, s, len,
                                   [&](uint32_t id) { return surf[id].material == mat; });
                } else {
                    g = material_rays[mat];
                    trace.op(OpKind::material_filter, generation, mat, s, len, nullptr, g);
                }
            }
            switch (kind) {
                case MaterialKind::lambertian: {
                    const bool ambient = !is_black(scene.ambient);
                    if (ambient)
                        run_filter(OpKind::ambient, k_no_object, s, g, [&](uint32_t id) {
                            add_ambient(path[id], material(id), scene);
                            return true;
                        });
                    const uint32_t direct = run_filter(
                        OpKind::lambertian_choice, k_no_object, s, g,
                        [&](uint32_t id) { return lambertian_takes_direct(path[id], scene); });
                    run_filter(OpKind::lambertian_direct, k_no_object, s, direct, [&](uint32_t id) {
                        if (!lambertian_direct(path[id], scene, material(id), surf[id], next[id]))
                            return false;
                        push(id, true);
                        return true;
                    });
                    if (!ambient)  // with ambient light, the indirect group ends here
                        run_filter(OpKind::lambertian_indirect, k_no_object, s + direct, g - direct,
                                   [&](uint32_t id) {
                                       if (!lambertian_indirect(path[id], scene, material(id),
                                                                surf[id], next[id]))
                                           return false;
                                       push(id, false);
                                       return true;
                                   });
                    break;
                }
                case MaterialKind::dielectric:
                    run_filter(OpKind::dielectric, k_no_object, s, g, [&](uint32_t id) {
                        if (!dielectric_scatter(path[id], material(id), surf[id], rays[id],
                                                next[id]))
                            return false;
                        push(id, false);
                        return true;
                    });
                    break;
                case MaterialKind::glossy:
                    run_filter(OpKind::glossy, k_no_object, s, g, [&](uint32_t id) {
                        if (!glossy_scatter(path[id], material(id), surf[id], rays[id], next[id]))
                            return false;
                        push(id, false);
                        return true;
                    });
                    break;
            }  // no default: -Werror=switch makes a new MaterialKind a compile error here
            s += g;
            len -= g;
        }

        std::swap(b.ids, b.next_ids);
        ids = b.ids.data();
        n = pushed;
        cur ^= 1;
        ++generation;
        close_frame_part();
    }

    // Each path ends exactly once per pass; passes come in sample order, so each pixel sums
    // its samples in the reference tracer's order.
    for (uint32_t slot = 0; slot < count; ++slot)
        sums[slot] += sanitize_radiance(path[slot].radiance, stats);
    lap(stats.shading_rest_tsc);
    if (clock) stats.stage_tsc[2] += lap_mark - pass_start - traverse_tsc;
    close_frame_part();
    info.generations = generation;
    if constexpr (Trace::k_enabled) sink->end_pass(info);
}

StreamTracer::StreamTracer(const Scene& scene, const Bvh& bvh, const RenderSettings& settings)
    : m_impl(std::make_unique<Impl>(scene, bvh, settings)) {}

StreamTracer::~StreamTracer() = default;

void StreamTracer::trace_pass(const TileRect& rect, uint32_t tile_index, uint32_t sample,
                              Vec3* sums, RenderStats& stats, TraceSink* sink,
                              RayObserver* observer) {
    if (sink && !sink->counts_only()) {
        SinkTrace trace{sink};
        m_impl->run(rect, tile_index, sample, sums, stats, trace, sink, observer);
    } else if (sink) {
        CountTrace trace{sink};
        m_impl->run(rect, tile_index, sample, sums, stats, trace, sink, observer);
    } else {
        NoTrace trace;
        m_impl->run(rect, tile_index, sample, sums, stats, trace, sink, observer);
    }
}

void release_kept_ray_buffers() {
    ray_buffer_pool().clear();
}

RenderResult render_stream(const Scene& scene, const Bvh& bvh, const RenderSettings& settings,
                           TraceSink* sink) {
    const auto start = HostClock::now();
    RenderResult result;
    result.image = Image(settings.width, settings.height);
    const std::vector<TileRect> tiles = make_tiles(settings.width, settings.height, settings.tile);
    uint32_t threads =
        settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
    threads = std::min<uint32_t>(threads, uint32_t(tiles.size()));
    if (sink) {
        TraceHeader header;
        if (!sink->counts_only()) header.scene_hash = scene_hash(scene);
        static_cast<TraceFrame&>(header) = settings;
        sink->begin_frame(header);
    }

    std::mutex mutex;  // guards the tracer pool and the stats
    std::vector<std::unique_ptr<StreamTracer>> pool;
    // With a sink and several threads, each pass is recorded, then replayed when every
    // earlier tile has been replayed: the trace comes in tile order whatever the threads.
    // Tiles are handed out in increasing order, so the tile waited for is always running.
    std::mutex order_mutex;
    std::condition_variable order_cv;
    uint32_t turn = 0;
    // Counts are sums, so each tile counts for itself and the counts are added: no ordering.
    CountingSink* const counting = dynamic_cast<CountingSink*>(sink);
    const bool ordered = sink && threads > 1 && !counting;

    parallel_for(uint32_t(tiles.size()), threads, [&](uint32_t t) {
        std::unique_ptr<StreamTracer> tracer;
        {
            std::lock_guard<std::mutex> lock(mutex);
            if (!pool.empty()) {
                tracer = std::move(pool.back());
                pool.pop_back();
            }
        }
        if (!tracer) tracer = std::make_unique<StreamTracer>(scene, bvh, settings);
        // Hands the turn on even if this tile throws, so no other tile waits forever.
        struct TurnGuard {
            bool active;
            uint32_t tile;
            std::mutex& m;
            std::condition_variable& cv;
            uint32_t& turn;
            ~TurnGuard() {
                if (!active) return;
                std::unique_lock<std::mutex> lock(m);
                cv.wait(lock, [&] { return turn == tile; });
                turn = tile + 1;
                cv.notify_all();
            }
        } guard{ordered, t, order_mutex, order_cv, turn};

        const TileRect& r = tiles[t];
        const uint32_t w = r.x1 - r.x0, count = w * (r.y1 - r.y0);
        std::vector<Vec3> sums(count, Vec3(0.f));
        RenderStats local;
        TraceRecorder recorder;
        std::unique_ptr<CountingSink> tile_counts;
        if (counting && threads > 1)
            tile_counts = std::make_unique<CountingSink>(counting->widths());
        TraceSink* const direct = tile_counts ? tile_counts.get() : sink;
        for (uint32_t s = 0; s < settings.spp; ++s) {
            if (!ordered) {
                tracer->trace_pass(r, t, s, sums.data(), local, direct);
                continue;
            }
            tracer->trace_pass(r, t, s, sums.data(), local, &recorder);
            std::unique_lock<std::mutex> lock(order_mutex);
            order_cv.wait(lock, [&] { return turn == t; });
            recorder.replay(*sink);
        }
        for (uint32_t slot = 0; slot < count; ++slot)
            result.image.at(r.x0 + slot % w, r.y0 + slot / w) = sums[slot] / float(settings.spp);
        std::lock_guard<std::mutex> lock(mutex);
        result.stats += local;
        if (tile_counts) *counting += *tile_counts;
        pool.push_back(std::move(tracer));
    });
    if (sink) sink->end_frame();
    result.stats.host_seconds = seconds_since(start);
    return result;
}

void stream_intersect(const Bvh& bvh, const std::vector<Ray>& rays, std::vector<Hit>& hits,
                      TraceSink* sink, Isa isa) {
    constexpr uint32_t k_stream = 4096;  // the paper's largest stream (64 x 64)
    const StreamKernels& kernels = stream_kernels(resolve_isa(isa));
    RayBuffers b;
    b.ensure(k_stream);
    hits.resize(rays.size());
    for (size_t begin = 0; begin < rays.size(); begin += k_stream) {
        const uint32_t n = uint32_t(std::min<size_t>(k_stream, rays.size() - begin));
        for (uint32_t i = 0; i < n; ++i) {
            b.ids[i] = i;
            b.any_hit[i] = 0;
        }
        const uint32_t m = load_rays(b, rays.data() + begin, n);
        TilePass info;
        info.tile = uint32_t(begin / k_stream);
        info.slot_count = n;
        info.generations = 1;
        if (sink && !sink->counts_only()) {
            SinkTrace trace{sink};
            sink->begin_pass(info);
            traverse(kernels, bvh, b, m, 0, trace);
            sink->end_pass(info);
        } else if (sink) {
            CountTrace trace{sink};
            sink->begin_pass(info);
            traverse(kernels, bvh, b, m, 0, trace);
            sink->end_pass(info);
        } else {
            NoTrace trace;
            traverse(kernels, bvh, b, m, 0, trace);
        }
        std::copy(b.hit.begin(), b.hit.begin() + n, hits.begin() + begin);
    }
}

}  // namespace sfx
