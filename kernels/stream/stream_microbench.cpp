#include "kernels/stream/stream_microbench.h"

#include <x86intrin.h>

#include <algorithm>
#include <iterator>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <stdexcept>

#include "base/cache_eviction.h"
#include "base/convergence.h"
#include "base/core_clock.h"
#include "base/core_contention.h"
#include "kernels/bvh.h"
#include "kernels/camera.h"
#include "kernels/intersect.h"
#include "kernels/path.h"
#include "kernels/stream/stream_filter.h"
#include "kernels/stream/stream_kernels.h"
#include "kernels/stream/stream_tracer.h"
#include "workloads/generators.h"

namespace sfx {

namespace {

// The element bytes of the stream tracer's RayBuffers (stream_tracer.cpp) that a slot indexes,
// its traversal record apart: path state, two ray generations, the full tests' constants, hit,
// any-hit flag, surface. Both figures below come from this one list.
constexpr uint32_t k_slot_array_bytes[] = {sizeof(PathState),  sizeof(Ray), sizeof(Ray),
                                           sizeof(RayPrecomp), sizeof(Hit), 1,
                                           sizeof(SurfaceHit)};

}  // namespace

uint32_t stream_slot_bytes() {
    // Those arrays, the filters' fields (the traversal record), six id lists and a mask.
    uint32_t bytes = uint32_t(traversal_field::record) * sizeof(float) + 6 * sizeof(uint32_t) + 1;
    for (const uint32_t b : k_slot_array_bytes) bytes += b;
    return bytes;
}

uint32_t stream_slot_arrays() {
    return uint32_t(std::size(k_slot_array_bytes));
}

namespace {

// A floor (Lambertian), a glossy panel, a glass sphere and a light over them. `dense`: the
// floor cut into 16 x 16 quads with 16 small glass spheres on it, for one-ray traversals deep
// enough and with enough sphere tests to tell the kinds' costs apart.
Scene synthetic_scene(bool dense = false) {
    Scene s;
    s.name = "microbench";
    Material floor, panel, glass, light;
    floor.kind = MaterialKind::lambertian;
    panel.kind = MaterialKind::glossy;
    glass.kind = MaterialKind::dielectric;
    light.kind = MaterialKind::lambertian;
    light.emission = Vec3(5.f);
    s.materials = {floor, panel, glass, light};
    SceneBuilder b(s);
    b.begin_object();
    const uint32_t floor_cuts = dense ? 16 : 1;
    const float cell = 8.f / float(floor_cuts);
    for (uint32_t i = 0; i < floor_cuts; ++i)
        for (uint32_t j = 0; j < floor_cuts; ++j)
            shapes::quad(b, Vec3(-4 + cell * float(i), 0, -4 + cell * float(j)), Vec3(cell, 0, 0),
                         Vec3(0, 0, cell), 0);
    b.begin_object();
    shapes::quad(b, Vec3(-3, 0, -3), Vec3(3, 0, 0), Vec3(0, 3, 0), 1);
    b.begin_object();
    shapes::quad(b, Vec3(-1, 4, -1), Vec3(2, 0, 0), Vec3(0, 0, 2), 3);
    b.begin_object();
    b.add_sphere(Vec3(1.5f, 1.f, 0.5f), 1.f, 2);
    if (dense)
        for (int i = 0; i < 16; ++i)
            b.add_sphere(Vec3(-3.5f + 0.5f * float(i), 0.2f, 2.5f - 0.4f * float(i % 4)), 0.2f, 2);
    s.camera.eye = Vec3(0, 2, 8);
    s.camera.look_at = Vec3(0, 1, 0);
    s.finalize(b.light_groups());
    return s;
}

// A cloud of small triangles at random in a box: a tree whose traversals follow no pattern, so
// that a branch predictor learns a batch's branches from that batch only.
Scene random_triangle_cloud(uint32_t triangles, uint64_t seed) {
    Scene s;
    s.name = "branch-microbench";
    Material surface, light;
    surface.kind = light.kind = MaterialKind::lambertian;
    light.emission = Vec3(5.f);
    s.materials = {surface, light};
    SceneBuilder b(s);
    b.begin_object();
    std::mt19937 rng{uint32_t(seed)};
    std::uniform_real_distribution<float> at(-2.f, 2.f), edge(-0.15f, 0.15f);
    for (uint32_t i = 0; i < triangles; ++i) {
        const Vec3 c(at(rng), 0.5f * at(rng) + 1.f, at(rng));
        const uint32_t v0 = b.add_vertex(c);
        const uint32_t v1 = b.add_vertex(c + Vec3(edge(rng), edge(rng), edge(rng)));
        const uint32_t v2 = b.add_vertex(c + Vec3(edge(rng), edge(rng), edge(rng)));
        b.add_triangle(v0, v1, v2, 0);
    }
    b.begin_object();
    shapes::quad(b, Vec3(-1, 4, -1), Vec3(2, 0, 0), Vec3(0, 0, 2), 1);
    s.camera.eye = Vec3(0, 2, 8);
    s.camera.look_at = Vec3(0, 1, 0);
    s.finalize(b.light_groups());
    return s;
}

struct Buffers {
    std::vector<PathState> path, saved_path;
    std::vector<Ray> ray, next, saved_ray;
    TraversalRays trav;                      // the filters' fields, t included
    std::vector<RayPrecomp> pre, saved_pre;  // the full primitive tests' constants
    std::vector<Hit> hit, saved_hit;
    std::vector<uint8_t> any_hit, mask, saved_any_hit;
    std::vector<SurfaceHit> surf, saved_surf;
    std::vector<uint32_t> ids, scratch, scratch2, positions;
    std::vector<uint32_t> op_tally;  // TraversalJob::op_tally

    // Calls f(element, bytes) for slot `id`'s element of each per-slot array of the pass (the
    // arrays of stream_slot_bytes besides the id lists and the mask).
    template <class F>
    void for_each_slot_element(uint32_t id, F&& f) {
        f(&path[id], sizeof(PathState));
        f(&ray[id], sizeof(Ray));
        f(&next[id], sizeof(Ray));
        f(&pre[id], sizeof(RayPrecomp));
        f(&hit[id], sizeof(Hit));
        f(&any_hit[id], sizeof(uint8_t));
        f(&surf[id], sizeof(SurfaceHit));
        f(trav.data() + size_t(id) * traversal_field::record,
          traversal_field::record * sizeof(float));
    }
    // The bytes of the arrays a repetition's timed calls and their set-up touch: all but the
    // saved rays, which only the deal reads.
    double timed_bytes() {
        double slot_bytes = 0.0;
        if (!ray.empty()) for_each_slot_element(0, [&](const void*, size_t n) { slot_bytes += n; });
        const auto bytes = [](const auto& v) { return double(v.size()) * sizeof(v[0]); };
        return slot_bytes * double(ray.size()) + bytes(mask) + bytes(ids) + bytes(scratch) +
               bytes(scratch2) + bytes(positions);
    }
};

// Every per-slot array and id list sized for `slots`, the rays left unset.
Buffers allocate_buffers(uint32_t slots) {
    Buffers b;
    b.path.resize(slots);
    b.ray.resize(slots);
    b.next.resize(slots);
    Ray unit;
    unit.dir = {0.f, 0.f, 1.f};
    b.trav.resize(slots);
    b.pre.resize(slots, RayPrecomp(unit));
    b.hit.resize(slots);
    b.any_hit.resize(slots);
    b.surf.resize(slots);
    const uint32_t padded = slots + k_stream_padding;
    b.ids.resize(padded);
    b.scratch.resize(padded);
    b.scratch2.resize(padded);
    b.positions.resize(padded);
    b.mask.resize(padded);
    b.op_tally.assign(op_tally_size(slots), 0);
    return b;
}

// Random rays from above the scene toward random points of it: a mix of hits on every
// material, misses and (every fourth) shadow rays.
Buffers make_buffers(const Scene& scene, const Bvh& bvh, uint32_t slots, std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    Buffers b = allocate_buffers(slots);
    for (uint32_t i = 0; i < slots; ++i) {
        Ray r;
        r.org = Vec3(3 * u(rng), 5.f + u(rng), 6.f + u(rng));
        const Vec3 target(4.5f * u(rng), 0.5f + u(rng), 4.5f * u(rng));
        r.dir = normalize(target - r.org);
        b.ray[i] = r;
        b.pre[i] = RayPrecomp(r);
        b.trav.set(i, b.pre[i], r.t_max);
        b.hit[i] = bvh.intersect(r);
        PathState& p = b.path[i];
        p.key = {7, i, 0};
        p.bounce = i % 3;
        p.kind = i % 4 == 3 ? RayKind::shadow : RayKind::extension;
        b.any_hit[i] = p.kind == RayKind::shadow;
        if (b.hit[i].valid()) b.surf[i] = surface_at(scene, r, b.hit[i]);
    }
    b.saved_path = b.path;
    b.saved_ray = b.ray;
    b.saved_pre = b.pre;
    b.saved_hit = b.hit;
    b.saved_any_hit = b.any_hit;
    b.saved_surf = b.surf;
    return b;
}

// Deals the buffer's rays (with their paths, hits and surfaces) to its slots in the order
// `deal`, so that a stream of the same slots meets other rays each time: a branch predictor
// learns a sequence of outcomes that repeats, and a frame's streams never repeat one.
// `hits`: shading filters read the hits the setup found; intersection tests start from none,
// as after the tracer's load_rays.
void deal_rays(Buffers& b, const std::vector<uint32_t>& deal, bool hits) {
    for (uint32_t i = 0; i < uint32_t(deal.size()); ++i) {
        const uint32_t from = deal[i];
        b.path[i] = b.saved_path[from];
        b.ray[i] = b.saved_ray[from];
        b.pre[i] = b.saved_pre[from];
        b.trav.set(i, b.pre[i], b.ray[i].t_max);
        b.hit[i] = hits ? b.saved_hit[from] : Hit{};
        b.any_hit[i] = b.saved_any_hit[from];
        b.surf[i] = b.saved_surf[from];
    }
}

// Reads a byte of every line of [p, p + bytes); returns their sum (kept, so not optimized out).
uint64_t touch_lines(const void* p, size_t bytes) {
    const auto* c = static_cast<const volatile uint8_t*>(p);
    uint64_t sum = 0;
    for (size_t o = 0; o < bytes; o += 64) sum += c[o];
    return sum + c[bytes - 1];
}

// Reads every line of each per-slot array of the pass (Buffers::for_each_slot_element) at each
// slot of `order`, so that the caches hold what a pass over the buffer leaves in them.
void touch_slots(Buffers& b, const std::vector<uint32_t>& order) {
    uint64_t touched = 0;
    for (uint32_t id : order)
        b.for_each_slot_element(id, [&](const void* p, size_t n) { touched += touch_lines(p, n); });
    if (touched == 1) b.mask[0] = 1;  // keeps the reads
}

// The rays an op made, ids[0, n) (the passing lanes, first after its partition), set up for the
// next generation's traversal in a loop of their own after the op, as the tracer's load_rays
// does (stream_tracer.cpp): a frame never sets a ray up in the loop that made it. Into the
// pass's own arrays, as load_rays does (the next deal restores them): arrays of their own added
// 43 % (141 bytes a slot) to what a repetition asks the caches to hold, which put a 4096-slot
// buffer beyond the 2 MiB L2 of an Intel Xeon VM (2026-12-06: the AVX2 camera's lanes, 8 of
// 4096 slots, 225 cycles each against 99 at 1024 slots; 103 with the set-up in the pass's arrays).
void set_up_made(Buffers& b, const uint32_t* ids, uint32_t n, bool shadow) {
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t id = ids[i];
        set_up_ray(b.next[id], shadow, id, b.any_hit[id], b.hit[id], b.pre[id], b.trav);
    }
}

// What a frame runs between two calls of one filter, for the cold calls: a pass of a 16 x 16
// tile of the scene through the stream tracer (its traversal and every filter), each time
// another sample.
class BetweenCalls {
  public:
    BetweenCalls(const Scene& scene, const Bvh& bvh, Isa isa)
        : m_tracer(scene, bvh, settings(isa)), m_sums(16 * 16) {}
    void operator()() {
        RenderStats stats;
        m_tracer.trace_pass({0, 0, 16, 16}, 0, m_sample++, m_sums.data(), stats, nullptr);
    }

  private:
    static RenderSettings settings(Isa isa) {
        RenderSettings s;
        s.width = s.height = s.tile = 16;
        s.spp = 1;
        s.threads = 1;
        s.isa = isa;
        return s;
    }
    StreamTracer m_tracer;
    std::vector<Vec3> m_sums;
    uint32_t m_sample = 0;
};

// One pair of single calls for cold_call_difference, in TSC ticks: `call(j)` on stream j, the
// streams taking turns pair by pair being the cold call's, so that what one costs over the
// other (its rays) cancels.
template <class Call>
void time_cold_then_warm(uint32_t pair, Call&& call, std::vector<double>& cold,
                         std::vector<double>& warm) {
    uint64_t tsc[3];
    tsc[0] = __rdtsc();
    for (uint32_t turn = 0; turn < 2; ++turn) {
        call((pair + turn) % 2);
        tsc[turn + 1] = __rdtsc();
    }
    cold.push_back(double(tsc[1] - tsc[0]));
    warm.push_back(double(tsc[2] - tsc[1]));
}

// TSC ticks of an empty timed region (subtracted from every measurement).
double tsc_overhead() {
    std::vector<double> t;
    for (int i = 0; i < 101; ++i) {
        const uint64_t a = __rdtsc();
        const uint64_t c = __rdtsc();
        t.push_back(double(c - a));
    }
    return median(t);
}

}  // namespace

double cold_call_difference(const std::vector<double>& cold, const std::vector<double>& warm) {
    // The TSC steps by tens of cycles on some hosts: one call's time is a multiple of the
    // step, and only a mean over calls whose start falls anywhere in it resolves less. Pairs
    // where either call took over four times its median were interrupted and are left out.
    if (cold.empty() || cold.size() != warm.size()) return 0.0;
    const double cold_limit = 4.0 * median(cold), warm_limit = 4.0 * median(warm);
    double sum = 0.0;
    uint32_t kept = 0;
    for (size_t i = 0; i < cold.size(); ++i) {
        if (cold[i] > cold_limit || warm[i] > warm_limit) continue;
        sum += cold[i] - warm[i];
        ++kept;
    }
    return kept ? sum / kept : 0.0;
}

std::vector<double> run_cold_traversal_microbenchmarks(Isa isa,
                                                       const std::vector<uint32_t>& lengths,
                                                       uint32_t pairs) {
    const Scene scene = synthetic_scene();
    const Bvh bvh(scene);
    const StreamKernels& kernels = stream_kernels(resolve_isa(isa));
    const double ticks_per_cycle = tsc_ticks_per_core_cycle(3, isa_width(resolve_isa(isa)));
    BetweenCalls trace_tile(scene, bvh, isa);
    std::mt19937 rng(13);
    const uint32_t slots = 256;
    Buffers b = make_buffers(scene, bvh, slots, rng);
    TraversalJob job = traversal_job(bvh, b);
    std::vector<uint32_t> order(slots);
    std::iota(order.begin(), order.end(), 0u);
    std::vector<double> out;
    for (const uint32_t n : lengths) {
        if (2 * n > slots) continue;
        std::vector<double> cold, warm;
        std::vector<uint32_t> streams[2];
        for (uint32_t pair = 0; pair < pairs; ++pair) {
            // Two streams of n rays each, in increasing order as the tracer's, other rays each
            // pair; set up from no hit as the tracer loads them.
            std::shuffle(order.begin(), order.end(), rng);
            for (uint32_t j = 0; j < 2; ++j) {
                streams[j].assign(order.begin() + j * n, order.begin() + (j + 1) * n);
                std::sort(streams[j].begin(), streams[j].end());
                streams[j].resize(n + k_stream_padding, 0u);
                for (uint32_t i = 0; i < n; ++i) {
                    const uint32_t id = streams[j][i];
                    b.ray[id] = b.saved_ray[id];
                    set_up_ray(b.ray[id], b.path[id].kind == RayKind::shadow, id, b.any_hit[id],
                               b.hit[id], b.pre[id], b.trav);
                }
            }
            trace_tile();
            time_cold_then_warm(
                pair,
                [&](uint32_t j) {
                    job.ids = streams[j].data();
                    job.n = n;
                    kernels.traverse[int(TraceDetail::none)](job);
                },
                cold, warm);
        }
        out.push_back(cold_call_difference(cold, warm) / ticks_per_cycle);
    }
    return out;
}

bool frame_streams_hold_hits_only(OpKind kind) {
    return stage_of(kind) == OpStage::shading && kind != OpKind::camera &&
           kind != OpKind::shadow_filter && kind != OpKind::miss_filter;
}

std::vector<MicrobenchSample> run_stream_microbenchmarks(
    const MicrobenchOptions& options, const std::function<void(uint32_t, uint32_t)>& progress) {
    const Scene scene = synthetic_scene();
    const Bvh bvh(scene);
    const StreamKernels& kernels = stream_kernels(resolve_isa(options.isa));
    CameraFrame camera(scene.camera, 64, 64);
    const double overhead = tsc_overhead();
    std::mt19937 rng(uint32_t(options.seed));

    // The kinds, in the order they are reported.
    const std::vector<OpKind> kinds = {OpKind::camera,
                                       OpKind::box_test,
                                       OpKind::triangle_test,
                                       OpKind::sphere_test,
                                       OpKind::shadow_filter,
                                       OpKind::miss_filter,
                                       OpKind::emission_filter,
                                       OpKind::depth_filter,
                                       OpKind::material_filter,
                                       OpKind::ambient,
                                       OpKind::lambertian_choice,
                                       OpKind::lambertian_direct,
                                       OpKind::lambertian_indirect,
                                       OpKind::dielectric,
                                       OpKind::glossy};
    // The camera is timed twice: on the synthetic scene's pinhole and on a thin lens (atrium's
    // aperture, focused on the scene's centre; any aperture above zero runs the same lens
    // arithmetic, kernels/camera.h), whose difference a lens scene's camera ops pay
    // (OpCostConfig::thin_lens_per_lane_cycles). The direct-light filter likewise: on the quad
    // light and on a sphere light (the glass sphere, emitting), whose samples take a point on a
    // sphere (sin and cos, kernels/lights.h) where a triangle's take a barycentric one
    // (OpCostConfig::sphere_light_per_pass_cycles). The triangle test likewise: on rays from
    // no hit, where nearly every candidate (a lane its float stage does not reject) passes, and
    // on candidates that fail, point by point behind their origin (as on a secondary ray's own
    // surface) and beyond a closer hit, the two ways a frame's secondary rays fail
    // (OpCostConfig::per_failed_candidate_cycles). The emission filter likewise: on hits on
    // triangles and on hits on the sphere, whose surfaces cost differently (surface_at: a
    // triangle's three vertices and an interpolation, a sphere's normalize), each stream of one
    // kind (OpCostConfig::sphere_hit_per_lane_cycles; the mix of the two, which the filter was
    // timed on before 2026-12-03, priced furnace's all-sphere filter 37-48 % over the host's).
    struct TimedKind {
        OpKind kind;
        bool thin_lens = false, sphere_light = false, failing_candidates = false,
             sphere_hits = false;
    };
    std::vector<TimedKind> timed_kinds;
    for (const OpKind kind : kinds) {
        timed_kinds.push_back({kind});
        if (kind == OpKind::camera) timed_kinds.push_back({kind, true, false});
        if (kind == OpKind::lambertian_direct) timed_kinds.push_back({kind, false, true});
        if (kind == OpKind::triangle_test) timed_kinds.push_back({kind, false, false, true});
        if (kind == OpKind::emission_filter)
            timed_kinds.push_back({kind, false, false, false, true});
    }
    Scene sphere_light_scene = scene;
    {
        const uint32_t sphere = scene.triangle_count();  // the glass sphere
        AreaLight light;
        light.primitives = {sphere};
        light.area = scene.primitive_area(sphere);
        light.area_cdf = {light.area};
        light.emission = scene.lights.front().emission;
        sphere_light_scene.lights = {light};
    }
    ThinLensCamera lens = scene.camera;
    lens.aperture_radius = 0.03f;
    lens.focal_distance = length(lens.look_at - lens.eye);
    const CameraFrame lens_camera(lens, 64, 64);
    std::vector<MicrobenchSample> out;
    uint32_t done = 0;
    Scene ambient_scene = scene;  // the ambient filter reads scene.ambient
    ambient_scene.ambient = Vec3(0.2f);

    std::vector<Buffers> buffers;
    for (uint32_t slots : options.buffer_slots)
        buffers.push_back(make_buffers(scene, bvh, slots, rng));
    // A traversal's box and leaf tests run back to back in a frame, thousands to a pass, so
    // each call finds the filter's code warm. Timed right after the deal and the touch of the
    // buffer, a call found it cold: on an Intel Xeon VM (2026-11-29), an AVX2 box test of 96
    // lanes over 4096 records in the L2 took 11-19 cycles a lane alone and 8-10 right after a
    // box test of 8 to 64 other lanes (6.5 with its records in the L1D), and the fit charged
    // the difference to the lanes beyond the L1D, which a frame's 64-pixel tiles then paid
    // (AVX2, atrium, conference and cornell 64 x 64: the model's traversal 17-44 % over the
    // host's at tile 64, +1 to +23 % at 32). So a traversal op's timed calls follow one call of
    // the same op on k_primer_lanes lanes of a buffer of its own: 16 (8, 16 and 64 warmed the
    // box test alike there), whose 1 KiB of records leaves the measured buffer's cache state as
    // it was. A shading filter runs once per generation between the others (cold in a frame
    // too), so it is timed cold, after a traversal (below).
    constexpr uint32_t k_primer_lanes = 16;
    std::mt19937 primer_rng(7);
    Buffers primer = make_buffers(scene, bvh, 64, primer_rng);
    TraversalJob primer_job = traversal_job(bvh, primer);
    // A frame's shading filters run right after its generation's traversal, whose vector code
    // sets the core's clock, and a cycle is the back end's chain clock (base/core_clock.h). On
    // an Intel Xeon VM with AVX-512 (2026-11-29) the zmm chain clocked 3.68-3.79 GHz, the
    // scalar one 3.99-4.09, and the shading filters timed right after a traversal of 64 rays
    // took 6-13 % more TSC time (median over lengths, by kind) than right after the deal and
    // the touch, which are scalar code: about what running at the scalar clock instead of the
    // zmm one gives (no PMU there to count the cycles), and the model had priced AVX-512's
    // shading about a tenth under. AVX2's took 1-3 % more, scalar's 0.5-3 %; a traversal op,
    // primed by its own call, took the same after a traversal (within 1 %). So a shading
    // filter's timed calls follow a traversal of k_rays_before_shading rays of a buffer of
    // their own.
    constexpr uint32_t k_rays_before_shading = 64;
    std::mt19937 before_shading_rng(11);
    Buffers before_shading = make_buffers(scene, bvh, k_rays_before_shading, before_shading_rng);
    TraversalJob before_shading_job = traversal_job(bvh, before_shading);
    std::iota(before_shading.ids.begin(), before_shading.ids.begin() + k_rays_before_shading, 0u);
    before_shading_job.n = k_rays_before_shading;
    before_shading_job.ids = before_shading.ids.data();
    auto traverse_before_shading = [&] {
        Buffers& b = before_shading;
        for (uint32_t i = 0; i < k_rays_before_shading; ++i)  // each time from no hit, as loaded
            set_up_ray(b.ray[i], b.path[i].kind == RayKind::shadow, i, b.any_hit[i], b.hit[i],
                       b.pre[i], b.trav);
        kernels.traverse[int(TraceDetail::none)](before_shading_job);
    };
    BetweenCalls trace_tile(scene, bvh, options.isa);  // the cold calls' (cold_call_lengths)
    // The triangle test's floor triangle (primitive 0) at its leaf position.
    auto leaf_position = [&](uint32_t prim) {
        return uint32_t(std::find(bvh.prim_ids().begin(), bvh.prim_ids().end(), prim) -
                        bvh.prim_ids().begin());
    };
    const uint32_t floor_leaf = leaf_position(0);
    const LeafPrimitive& floor_triangle = bvh.leaf_primitives()[floor_leaf];
    // The failing-candidate variant's rays: dealt from those that hit the floor triangle, then
    // each turned round (`behind`: its line still crosses the triangle, behind its origin) or
    // given a closer hit (t = 1: its origin is 4 or more above the floor). One way for a whole
    // point, the other for the next: a frame's op most likely fails its candidates mostly one
    // way (a secondary ray's own surface's leaf behind them all; not counted per op), and lanes
    // dealt both ways at random cost more, most likely the test's exit mispredicted (no PMU to
    // count it; AVX2 on a Zen 5 VM, 2026-12-02: 67-90 cycles a lane against 41-42 where the
    // ways alternated lane by lane, and 65-97 for passing candidates).
    auto make_candidates_fail = [](Buffers& b, uint32_t slots, bool behind) {
        for (uint32_t i = 0; i < slots; ++i) {
            if (!behind) {
                b.trav.t(i) = 1.f;
                continue;
            }
            b.ray[i].dir = -1.f * b.ray[i].dir;
            b.pre[i] = RayPrecomp(b.ray[i]);
            b.trav.set(i, b.pre[i], b.ray[i].t_max);
        }
    };
    // The sphere test's sphere (the scene's first, the large one) likewise.
    const uint32_t sphere_leaf = leaf_position(scene.triangle_count());
    // The box test's nodes: the root (every ray passes) and the nodes below it, breadth first
    // (a share of the rays passes, as in a frame, where a stream's lanes pass and fail: the
    // filter's per-lane branches and compress see both); the samples take them in turn.
    std::vector<uint32_t> box_nodes = {0};
    for (size_t i = 0; i < box_nodes.size() && box_nodes.size() < 7; ++i) {
        const BvhNode& node = bvh.nodes()[box_nodes[i]];
        if (node.is_leaf()) continue;
        box_nodes.push_back(BvhNode::left(box_nodes[i]));
        box_nodes.push_back(node.right());
    }
    // Each point's samples over the visits, in core cycles, by the point's place in the sweep
    // (every visit sweeps the points in one order, the box test's nodes in the same turns).
    std::vector<std::vector<double>> visited;
    const uint32_t visits = std::max(1u, options.visits);
    for (uint32_t visit = 0; visit < visits; ++visit) {
        const bool last_visit = visit + 1 == visits;
        uint32_t box_sample = 0;
        size_t point = 0;
        for (const TimedKind& timed : timed_kinds) {
            const OpKind kind = timed.kind;
            const bool thin_lens = timed.thin_lens;
            const Scene& lit = timed.sphere_light ? sphere_light_scene : scene;
            if (!options.kinds.empty() &&
                std::find(options.kinds.begin(), options.kinds.end(), kind) == options.kinds.end())
                continue;
            for (size_t bi = 0; bi < options.buffer_slots.size(); ++bi) {
                const uint32_t slots = options.buffer_slots[bi];
                Buffers& b = buffers[bi];
                TraversalJob job = traversal_job(bvh, b);  // the leaf tests' buffers
                std::vector<uint32_t> order(slots), deal(slots);
                std::iota(order.begin(), order.end(), 0u);
                std::iota(deal.begin(), deal.end(), 0u);
                std::vector<uint32_t> streams;
                std::vector<uint32_t> made;  // per call of a timed sample: the rays it made
                bool all_hits = true;        // the stream's lanes are all hits
                // The material sort's inputs (the depth filter's by-product in the tracer, so
                // taken before the timed region): per stream, its rays of each material; the
                // next one's write position.
                const uint32_t materials = uint32_t(scene.materials.size());
                std::vector<uint32_t> material_counts, material_next(materials);
                const uint32_t* counts_now = nullptr;
                auto count_materials = [&](const uint32_t* ids, uint32_t n, uint32_t* counts) {
                    std::fill(counts, counts + materials, 0u);
                    for (uint32_t i = 0; i < n; ++i) ++counts[b.surf[ids[i]].material];
                };
                // The op of `kind` on the stream ids[0, n) of buffer `b` (partitioned in place, as
                // the tracer's filters leave it): its passing count. box_node: the box test's node.
                auto run_op = [&](Buffers& b, TraversalJob& job, uint32_t* ids, uint32_t n,
                                  uint32_t box_node) {
                    uint32_t passed = 0;
                    uint8_t* mask = b.mask.data();
                    uint32_t* scratch = b.scratch.data();
                    NoTrace trace;
                    const uint32_t mat = 0;
                    auto run_filter = [&](auto&& test) {
                        return filter(kernels, trace, kind, 1, mat, ids, n, mask, scratch, test);
                    };
                    switch (kind) {
                        case OpKind::camera:
                            for (uint32_t i = 0; i < n; ++i) {
                                const uint32_t slot = ids[i];
                                PathState& p = b.path[slot];
                                p = PathState{};
                                p.key = {1, slot, 0};
                                b.next[slot] = (thin_lens ? lens_camera : camera).generate(p.key);
                                mask[i] = 1;
                            }
                            passed = n;
                            break;
                        case OpKind::box_test: {
                            // The tracer's box_filter with the trace off: the kernel, then
                            // the failing ids copied back behind the passing ones.
                            uint32_t negative = 0;
                            const BvhNode& node = bvh.nodes()[box_node];
                            passed = kernels.box_filter(b.trav.view(), node.bounds, node.axis, ids,
                                                        n, ids, scratch, nullptr, negative);
                            std::copy(scratch, scratch + (n - passed), ids + passed);
                            break;
                        }
                        case OpKind::triangle_test:
                            // A floor triangle (about half the rays) as a leaf of its own,
                            // by the tracer's leaf code: the float stage, then the full
                            // test of each candidate, the hits taken if closer.
                            job.ids = ids;
                            job.n = n;
                            passed = kernels.leaf_tests(job, floor_leaf, 1, n);
                            break;
                        case OpKind::sphere_test:
                            // The large glass sphere as a leaf of its own, likewise: the
                            // test of each group, then its hits taken if closer.
                            job.ids = ids;
                            job.n = n;
                            passed = kernels.leaf_tests(job, sphere_leaf, 1, n);
                            break;
                        case OpKind::shadow_filter:
                            passed = run_filter([&](uint32_t id) {
                                if (!b.any_hit[id]) return false;
                                finish_shadow(b.path[id], b.hit[id].valid());
                                return true;
                            });
                            break;
                        case OpKind::miss_filter:
                            passed = run_filter([&](uint32_t id) {
                                if (b.hit[id].valid()) return false;
                                shade_miss(b.path[id], scene);
                                return true;
                            });
                            break;
                        case OpKind::emission_filter:
                            // As the tracer runs it: the hits' surfaces in a loop of their own
                            // (compute_surfaces, with its prefetches), then the filter on them.
                            // A timed stream holds hits only (frame_streams_hold_hits_only); the
                            // buffer's classification, untimed, holds misses too and reads the
                            // surfaces the deal restored (make_buffers computed them).
                            if (all_hits)
                                compute_surfaces(scene, b.ray.data(), b.hit.data(), ids, n,
                                                 b.surf.data());
                            passed = run_filter([&](uint32_t id) {
                                if (!b.hit[id].valid()) return false;  // misses left earlier
                                const Material& m = scene.materials[b.surf[id].material];
                                if (!m.emissive()) return false;
                                shade_emission(b.path[id], m);
                                return true;
                            });
                            break;
                        case OpKind::depth_filter: {
                            uint32_t material_rays[4] = {0, 0, 0, 0};
                            passed = run_filter([&](uint32_t id) {
                                if (!may_scatter(b.path[id], 3)) return false;
                                ++material_rays[b.surf[id].material & 3];
                                return true;
                            });
                            break;
                        }
                        case OpKind::material_filter: {
                            // As the tracer runs the material filters with the trace off: one
                            // counting sort of the stream by material (placed_by_material_sort,
                            // hw_model/op_costs.h), where the stream holds two materials or more;
                            // passing: the first material's rays, as the first filter's.
                            uint32_t start = 0, present = 0;
                            passed = 0;
                            for (uint32_t m = 0; m < materials; ++m) {
                                material_next[m] = start;
                                start += counts_now[m];
                                if (counts_now[m] && present++ == 0) passed = counts_now[m];
                            }
                            if (present > 1) {
                                for (uint32_t i = 0; i < n; ++i)
                                    scratch[material_next[b.surf[ids[i]].material]++] = ids[i];
                                std::copy(scratch, scratch + n, ids);
                            }
                            break;
                        }
                        case OpKind::ambient:
                            passed = run_filter([&](uint32_t id) {
                                add_ambient(b.path[id], scene.materials[b.surf[id].material],
                                            ambient_scene);
                                return true;
                            });
                            break;
                        case OpKind::lambertian_choice:
                            passed = run_filter([&](uint32_t id) {
                                return lambertian_takes_direct(b.path[id], scene);
                            });
                            break;
                        case OpKind::lambertian_direct:
                            passed = run_filter([&](uint32_t id) {
                                if (!b.hit[id].valid()) return false;
                                return lambertian_direct(b.path[id], lit, scene.materials[0],
                                                         b.surf[id], b.next[id]);
                            });
                            break;
                        case OpKind::lambertian_indirect:
                            passed = run_filter([&](uint32_t id) {
                                if (!b.hit[id].valid()) return false;
                                return lambertian_indirect(b.path[id], scene, scene.materials[0],
                                                           b.surf[id], b.next[id]);
                            });
                            break;
                        case OpKind::dielectric:
                            passed = run_filter([&](uint32_t id) {
                                if (!b.hit[id].valid()) return false;
                                return dielectric_scatter(b.path[id], scene.materials[2],
                                                          b.surf[id], b.ray[id], b.next[id]);
                            });
                            break;
                        case OpKind::glossy:
                            passed = run_filter([&](uint32_t id) {
                                if (!b.hit[id].valid()) return false;
                                return glossy_scatter(b.path[id], scene.materials[1], b.surf[id],
                                                      b.ray[id], b.next[id]);
                            });
                            break;
                        // Not microbenchmarked (the host's seed-kernel ops); no default, so
                        // a new kind (a new material's filter) is a compile error here.
                        case OpKind::frustum_bounds:
                        case OpKind::frustum_test:
                        case OpKind::reorder_lod_test:
                        case OpKind::reorder_key:
                        case OpKind::reorder_sort:
                        case OpKind::raygrid_walk:
                        case OpKind::raygrid_enqueue:
                        case OpKind::count:
                            break;
                    }
                    return passed;
                };
                // The rays (saved, by index) that this shading op passes and those it fails: its
                // streams are also timed with every lane passing and with none, since a frame's
                // shading streams are filtered already and most of their lanes pass, while the
                // buffer's mix alone fixes only one sum of a tested lane's cost and a passing
                // one's. The same rays, dealt into the slots with repeats. A mixed stream takes
                // the buffer's share of passing rays exactly, so that the several short streams
                // of one timed repetition have the one pass count the sample records.
                std::vector<uint32_t> passing, failing;
                std::vector<uint8_t> passes(slots, 0);
                const bool hits_only = frame_streams_hold_hits_only(kind);
                const bool leaf_test = stage_of(kind) == OpStage::intersection;
                const bool primed = stage_of(kind) != OpStage::shading;
                if (leaf_test) {
                    // A leaf test's lane passes where its ray hits the primitive (from no hit,
                    // as every deal leaves it), each ray tested alone. Its streams are also
                    // timed with every lane passing and with none, as a shading op's are: the
                    // buffer's one share of rays that hit its primitive told a group's cost
                    // from a passing lane's only by rounding, so that a frame whose leaf tests
                    // pass more often (furnace's sphere) was priced by whichever split the fit
                    // fell on (on an Intel Xeon VM, 2026-11-29, AVX2's sphere test 5.7 and
                    // 23.7 cycles a passing lane in two calibrations of the same code).
                    deal_rays(b, deal, false);  // deal is the identity here
                    std::vector<uint32_t> one(1 + k_stream_padding);
                    for (uint32_t ray = 0; ray < slots; ++ray) {
                        one[0] = ray;
                        (run_op(b, job, one.data(), 1, box_nodes[0]) > 0 ? passing : failing)
                            .push_back(ray);
                    }
                }
                if (stage_of(kind) == OpStage::shading) {
                    deal_rays(b, deal, true);  // deal is the identity here
                    std::vector<uint32_t> all(slots + k_stream_padding);
                    std::iota(all.begin(), all.begin() + slots, 0u);
                    if (kind == OpKind::material_filter) {
                        material_counts.resize(materials);
                        count_materials(all.data(), slots, material_counts.data());
                        counts_now = material_counts.data();
                    }
                    all_hits = false;
                    const uint32_t p = run_op(b, job, all.data(), slots, box_nodes[0]);
                    all_hits = true;
                    passing.assign(all.begin(), all.begin() + p);
                    failing.assign(all.begin() + p, all.begin() + slots);
                    if (hits_only) {
                        auto not_a_hit = [&](uint32_t ray) {
                            return !b.saved_hit[ray].valid() || b.saved_any_hit[ray];
                        };
                        for (auto* rays : {&passing, &failing})
                            rays->erase(std::remove_if(rays->begin(), rays->end(), not_a_hit),
                                        rays->end());
                    }
                    if (kind == OpKind::emission_filter) {  // hits of one primitive kind
                        auto other_kind = [&](uint32_t ray) {
                            return scene.is_sphere(b.saved_hit[ray].prim) != timed.sphere_hits;
                        };
                        for (auto* rays : {&passing, &failing})
                            rays->erase(std::remove_if(rays->begin(), rays->end(), other_kind),
                                        rays->end());
                    }
                }
                for (uint32_t ray : passing) passes[ray] = 1;
                // The rays a stream is dealt from: the whole buffer, or its hits.
                std::vector<uint32_t> pool = passing;
                pool.insert(pool.end(), failing.begin(), failing.end());
                std::sort(pool.begin(), pool.end());
                if (hits_only && pool.empty()) continue;  // no hit of the kind in this buffer
                // The material sort has no outcome per lane to split its streams by.
                const bool classified = !passing.empty() && !failing.empty() &&
                                        kind != OpKind::material_filter;
                std::vector<uint32_t> pass_slots, fail_slots;
                enum class Deal { mixed, all_pass, none_pass };
                std::vector<Deal> deals = {Deal::mixed};
                if (classified) deals = {Deal::mixed, Deal::all_pass, Deal::none_pass};
                if (timed.failing_candidates) deals = {Deal::all_pass};
                for (const Deal dealt : deals)
                    for (uint32_t n : options.lengths) {
                        if (n > slots) continue;
                        // A one-lane leaf test is priced by its lane's outcome (one_lane_cycles
                        // and the extras of OpCostConfig): its points are of one outcome each, a
                        // passing or a failing lane (or a failed candidate), not mixed.
                        const bool one_lane_leaf = leaf_test && n == 1;
                        if (one_lane_leaf && classified && dealt == Deal::mixed) continue;
                        std::vector<double> times;
                        uint32_t passed = 0;
                        const double ticks_per_cycle =
                            tsc_ticks_per_core_cycle(3, isa_width(resolve_isa(options.isa)));
                        const uint32_t box_node = box_nodes[box_sample++ % box_nodes.size()];
                        // Short streams run several times in the timed region (the TSC ticks in
                        // steps of tens of cycles here), each time on other slots (an op changes
                        // its rays: a hit tightens t, a shader moves the path on).
                        const bool exact_mix = classified && dealt == Deal::mixed && !one_lane_leaf;
                        const uint32_t stream_passing =
                            exact_mix
                                ? std::min<uint32_t>(
                                      n, uint32_t(std::lround(double(n) * double(passing.size()) /
                                                              double(pool.size()))))
                                : 0;
                        uint32_t inner = std::max(1u, std::min(256u, slots) / n);
                        if (exact_mix) {
                            // A deal holds each passing and failing ray at least `copies` times.
                            const size_t copies = hits_only ? slots / pool.size() : 1;
                            if (stream_passing > 0)
                                inner = std::min<uint32_t>(
                                    inner, passing.size() * copies / stream_passing);
                            if (n > stream_passing)
                                inner = std::min<uint32_t>(
                                    inner, failing.size() * copies / (n - stream_passing));
                            // A stream longer than a hits-only pool can fill is not timed.
                            if (inner == 0) continue;
                        }
                        const uint32_t stride = n + k_stream_padding;
                        streams.assign(size_t(inner) * stride, 0u);
                        made.assign(inner, 0u);
                        uint32_t set_aside = 0;  // samples after which the core was shared
                        while (needs_more_samples(times, options.convergence)) {
                            // Fresh random streams: n slots of the buffer each, in increasing
                            // order, as the tracer's streams are (the camera's, and every stable
                            // partition of one), with the rays dealt anew; the whole buffer touched
                            // in random order first, so the L1D holds what a pass over this buffer
                            // leaves in it.
                            if (hits_only && !pool.empty()) {
                                // Every ray of the pool as often as the next (repeats where
                                // the pool is smaller than the buffer), so that a deal holds
                                // at least the pool's passing and failing rays.
                                for (uint32_t i = 0; i < slots; ++i) deal[i] = pool[i % pool.size()];
                            }
                            std::shuffle(deal.begin(), deal.end(), rng);
                            if (dealt != Deal::mixed) {
                                const std::vector<uint32_t>& from =
                                    dealt == Deal::all_pass ? passing : failing;
                                for (uint32_t& d : deal) d = from[rng() % from.size()];
                            }
                            deal_rays(b, deal, stage_of(kind) == OpStage::shading);
                            if (timed.failing_candidates)  // by the point's place in the sweep
                                make_candidates_fail(b, slots, point % 2 == 0);
                            std::shuffle(order.begin(), order.end(), rng);
                            if (exact_mix) {
                                pass_slots.clear();
                                fail_slots.clear();
                                for (uint32_t slot : order)
                                    (passes[deal[slot]] ? pass_slots : fail_slots).push_back(slot);
                            }
                            for (uint32_t j = 0; j < inner; ++j) {
                                uint32_t* stream = streams.data() + size_t(j) * stride;
                                if (exact_mix) {
                                    const size_t p = size_t(j) * stream_passing,
                                                 f = size_t(j) * (n - stream_passing);
                                    std::copy(pass_slots.begin() + p,
                                              pass_slots.begin() + p + stream_passing, stream);
                                    std::copy(fail_slots.begin() + f,
                                              fail_slots.begin() + f + (n - stream_passing),
                                              stream + stream_passing);
                                } else {
                                    // inner * n <= slots: the streams are disjoint.
                                    const auto first = order.begin() + size_t(j) * n;
                                    std::copy(first, first + n, stream);
                                }
                                std::sort(stream, stream + n);
                            }
                            touch_slots(b, order);

                            material_counts.resize(size_t(inner) * materials);
                            if (kind == OpKind::material_filter)
                                for (uint32_t j = 0; j < inner; ++j)
                                    count_materials(streams.data() + size_t(j) * stride, n,
                                                    material_counts.data() + size_t(j) * materials);
                            if (primed) {
                                std::iota(primer.ids.begin(), primer.ids.begin() + k_primer_lanes,
                                          0u);
                                run_op(primer, primer_job, primer.ids.data(), k_primer_lanes,
                                       box_node);
                            } else {
                                traverse_before_shading();
                            }
                            const uint64_t start = __rdtsc();
                            for (uint32_t again = 0; again < inner; ++again) {
                                counts_now = material_counts.data() + size_t(again) * materials;
                                passed = run_op(b, job, streams.data() + size_t(again) * stride, n,
                                                box_node);
                                made[again] = passed;
                            }
                            if (op_info(kind).pushes_rays)
                                for (uint32_t again = 0; again < inner; ++again)
                                    set_up_made(b, streams.data() + size_t(again) * stride,
                                                made[again], kind == OpKind::lambertian_direct);
                            const uint64_t end = __rdtsc();
                            times.push_back(std::max(0.0, double(end - start) - overhead) / inner);
                            core_contention().set_aside_if_contended({&times}, set_aside,
                                                                     options.convergence.budget);
                        }
                        // Cold and warm single calls of a shading op (cold_call_lengths):
                        // streams 0 and 1 of the last deal, which hold the same mix.
                        double cold_call = 0.0;
                        bool cold_timed = false;
                        if (last_visit && stage_of(kind) == OpStage::shading && !timed.thin_lens &&
                            !timed.sphere_light && !timed.sphere_hits && dealt == Deal::mixed &&
                            slots == options.cold_call_slots && inner >= 2 &&
                            options.cold_call_pairs > 0 &&
                            std::count(options.cold_call_lengths.begin(),
                                       options.cold_call_lengths.end(), n) > 0) {
                            std::vector<double> cold, warm;
                            std::vector<uint32_t> kept(size_t(2) * stride);
                            std::copy(streams.begin(), streams.begin() + 2 * stride, kept.begin());
                            for (uint32_t j = 0; j < 2; ++j)  // in increasing order again
                                std::sort(kept.begin() + j * stride, kept.begin() + j * stride + n);
                            for (uint32_t pair = 0; pair < options.cold_call_pairs; ++pair) {
                                deal_rays(b, deal, true);
                                std::copy(kept.begin(), kept.end(), streams.begin());
                                trace_tile();
                                touch_slots(b, order);
                                time_cold_then_warm(
                                    pair,
                                    [&](uint32_t j) {
                                        counts_now = material_counts.data() + size_t(j) * materials;
                                        run_op(b, job, streams.data() + size_t(j) * stride, n,
                                               box_node);
                                    },
                                    cold, warm);
                            }
                            cold_call = cold_call_difference(cold, warm) / ticks_per_cycle;
                            cold_timed = true;
                        }
                        if (visited.size() <= point) visited.resize(point + 1);
                        std::vector<double>& cycles = visited[point++];
                        for (const double t : times) cycles.push_back(t / ticks_per_cycle);
                        if (!last_visit) continue;
                        // The triangle test's failed candidates, counted by the tracer's float
                        // stage on the last repetition's streams (it does not depend on t).
                        uint32_t failed_candidates = 0;
                        if (kind == OpKind::triangle_test) {
                            uint64_t candidates = 0, made_sum = 0;
                            for (uint32_t j = 0; j < inner; ++j) {
                                candidates += kernels.triangle_candidates(
                                    b.trav.view(), floor_triangle.p0, floor_triangle.p1,
                                    floor_triangle.p2, streams.data() + size_t(j) * stride, n,
                                    b.positions.data());
                                made_sum += made[j];
                            }
                            failed_candidates = uint32_t(std::lround(
                                double(candidates - std::min(candidates, made_sum)) / inner));
                        }
                        // Converged: the fastest k of all the visits' samples agree.
                        const Convergence c = judge_convergence(cycles, options.convergence);
                        out.push_back({kind, slots, n, passed, c.fastest, c.converged, c.samples,
                                       timed.thin_lens, timed.sphere_light,
                                       timed.failing_candidates, failed_candidates,
                                       timed.sphere_hits, cold_call, cold_timed});
                    }
            }
            if (progress) progress(++done, uint32_t(timed_kinds.size()) * visits);
        }
    }
    return out;
}

// Tallies a traversal's ops by kind and stream length (the tracer sends them by length when the
// trace is counts only).
class OpLengthTally : public TraceSink {
  public:
    void op(const StreamOp& o) override {
        ops_of_length(o.kind, o.stage, o.generation, o.length, 1, o.pass_count,
                      o.failed_candidates);
        if (o.starts_traversal && o.origin_shared && o.length > 1)
            m_origin_shared_lanes += o.length - 1;  // each compared with the first
    }
    void ops_of_length(OpKind kind, OpStage, uint16_t, uint32_t length, uint32_t count,
                       uint32_t passed, uint32_t failed_candidates) override {
        OpsOfLength& t = m_tally[{kind, length}];
        t.count += count;
        t.passed += passed;
        t.failed_candidates += failed_candidates;
    }
    bool counts_only() const override { return true; }
    // Into a sample: one-lane ops, the few-ray loop's box tests (a wide back end's), the rest.
    void fill(OneRaySample& s, uint32_t width) const {
        s.origin_shared_lanes += m_origin_shared_lanes;
        for (const auto& [key, t] : m_tally) {
            const auto [kind, length] = key;
            if (length == 1) {
                s.ops[size_t(kind)] += t.count;
                s.one_lane_passed[size_t(kind)] += t.passed;
                s.one_lane_failed_candidates[size_t(kind)] += t.failed_candidates;
            } else if (runs_in_few_ray_loop(kind, length, width))
                s.few_ops[size_t(kind)] += t.count;
            else
                s.stream_ops.push_back({kind, length, t.count, t.passed, t.failed_candidates});
        }
    }

  private:
    std::map<std::pair<OpKind, uint32_t>, OpsOfLength> m_tally;  // its kind and lanes unset
    uint64_t m_origin_shared_lanes = 0;
};

namespace {

// The stage clock's split of a traversal (`traverse`, each repetition after `prepare`): the
// shares of its time in the one-ray loop and the few-ray loop (their leaves left out), and in
// the leaves by the loop whose leaf code ran them (TraversalJob::leaf_tsc, ShortLoopClock; the
// stream loop's are the rest of the leaves), each the median of its own share over 5 clocked
// repetitions (the clock's reads are in them), so that the parts add up (the leaves' whole is
// the sum of the three loops' medians, not the median of their sum).
struct ClockedShares {
    std::array<double, 2> short_loops{};
    std::array<double, 3> leaves{};
    double all_leaves() const { return leaves[0] + leaves[1] + leaves[2]; }
    // The stream loop's share less its leaves: the rest.
    double stream_loop() const {
        return std::max(0.0, 1.0 - short_loops[0] - short_loops[1] - all_leaves());
    }
};
template <class Prepare, class Traverse>
ClockedShares clocked_loop_shares(TraversalJob& job, Prepare&& prepare, Traverse&& traverse) {
    std::vector<double> shares[5];
    for (uint32_t rep = 0; rep < 5; ++rep) {
        prepare();
        uint64_t leaf_ticks = 0;
        ShortLoopClock clock;
        job.leaf_tsc = &leaf_ticks;
        job.short_loops = &clock;
        const uint64_t start = __rdtsc();
        traverse();
        const double spent = double(std::max<uint64_t>(1, __rdtsc() - start));
        job.leaf_tsc = nullptr;
        job.short_loops = nullptr;
        const uint64_t short_leaves = clock.leaf_ticks[0] + clock.leaf_ticks[1];
        for (int l = 0; l < 2; ++l) {
            shares[l].push_back(double(clock.ticks[l]) / spent);
            shares[2 + l].push_back(double(clock.leaf_ticks[l]) / spent);
        }
        shares[4].push_back(double(leaf_ticks - std::min(leaf_ticks, short_leaves)) / spent);
    }
    ClockedShares out;
    for (int l = 0; l < 2; ++l) out.short_loops[size_t(l)] = median(shares[l]);
    for (int l = 0; l < 3; ++l) out.leaves[size_t(l)] = median(shares[2 + l]);
    return out;
}

// The node `depth` levels below the root on a ray's way down (the left child if the ray enters
// its box, else the right), or the last it reached.
uint32_t entry_below(const Bvh& bvh, const RayPrecomp& ray, float t_max, uint32_t depth) {
    const BvhNodes& nodes = bvh.nodes();
    uint32_t at = 0;
    for (uint32_t d = 0; d < depth && !nodes[at].is_leaf(); ++d) {
        const uint32_t left = BvhNode::left(at), right = nodes[at].right();
        if (intersect_box(ray, nodes[left].bounds, t_max) < INFINITY)
            at = left;
        else if (intersect_box(ray, nodes[right].bounds, t_max) < INFINITY)
            at = right;
        else
            break;
    }
    return at;
}

}  // namespace

Scene one_ray_microbench_scene() {
    return synthetic_scene(true);
}

std::vector<OneRaySample> run_one_ray_microbenchmarks(Isa isa, const ConvergenceRule& convergence,
                                                      uint64_t seed,
                                                      const PredictorReplay& predictor_replay) {
    const Scene scene = one_ray_microbench_scene();
    const Bvh bvh(scene);
    const Isa resolved = resolve_isa(isa);
    const StreamKernels& kernels = stream_kernels(resolved);
    std::mt19937 rng{uint32_t(seed)};
    const double overhead = tsc_overhead();
    // Rays enough that the other rays' traversals between a batch's repetitions (below) are
    // many more than a branch predictor can learn.
    constexpr uint32_t k_slots = 4096;
    Buffers b = make_buffers(scene, bvh, k_slots, rng);
    TraversalJob job = traversal_job(bvh, b);
    std::vector<uint32_t> order(k_slots);
    std::iota(order.begin(), order.end(), 0u);
    // Every stream its own ids with the kernels' padding: the traversal partitions them in place.
    std::vector<uint32_t> stream_ids, other_ids, stream_entry;
    std::vector<OneRaySample> out;
    struct Shape {
        uint32_t rays, streams;  // rays per stream, streams one after another
        bool bundle;             // each stream a bundle (below), or rays drawn at random
        uint32_t entry_depth = 0;
    };
    std::vector<Shape> shapes;
    const bool few_loop = isa_width(resolved) >= k_few_ray_min_width;
    // One-ray streams by the 8 to 32, as a frame runs them (hundreds in a row): a batch of one
    // to four, timed again and again, ran 13-33 % cheaper a box test than a batch of 32 (AMD
    // Zen 5 VM, 2026-11-27), a regime no frame has, and with them the fit could not tell the
    // one-ray entry cost: 0 to 98 cycles over six fits, the one-lane fit's worst error 65-103 %;
    // without them, 21-48 (AVX2, AVX-512) and 88-101 (scalar) over six, worst error 21-44 %.
    for (uint32_t streams : {8u, 16u, 32u}) shapes.push_back({1, streams, false});
    // Few-ray streams where the few-ray loop runs them: elsewhere the stream loop does, whose
    // costs the filter microbenchmarks measure.
    if (few_loop)
        for (uint32_t rays = 2; rays <= k_few_ray_lanes; ++rays)
            for (uint32_t streams : {4u, 8u, 16u, 32u}) shapes.push_back({rays, streams, false});
    // Short streams entering deep, whose subtrees are small: what a loop's start costs apart
    // from its box tests (from the root, every stream's subtree holds about as many).
    for (uint32_t depth : {3u, 6u})
        for (uint32_t rays = 1; rays <= (few_loop ? k_few_ray_lanes : 1u); ++rays)
            for (uint32_t streams : {8u, 32u}) shapes.push_back({rays, streams, false, depth});
    // Streams the stream loop starts (every back end): its box tests in a traversal, where each
    // op's stream is the one before's output, not the filter microbenchmarks' independent calls;
    // bundles that stay together, as a tile's camera rays do, and rays that part at once, as
    // bounces do.
    for (bool bundle : {true, false})
        for (uint32_t rays : {8u, 16u, 32u, 64u, 128u})
            for (uint32_t streams : {1u, 4u}) shapes.push_back({rays, streams, bundle});
    for (const Shape& shape : shapes)
        for (uint32_t batch = 0; batch < 8; ++batch) {
            const uint32_t rays = shape.rays, streams = shape.streams;
            std::shuffle(order.begin(), order.end(), rng);
            const uint32_t stride = rays + k_stream_padding;
            stream_ids.assign(size_t(streams) * stride, 0u);
            stream_entry.assign(streams, 0u);
            // A bundle: one origin, targets within a cell of the floor, so that it stays one
            // stream for several levels (its rays restored after the batch).
            if (shape.bundle)
                for (uint32_t s = 0; s < streams; ++s) {
                    std::uniform_real_distribution<float> u(-1.f, 1.f);
                    const Vec3 org(3 * u(rng), 5.f + u(rng), 6.f + u(rng));
                    const Vec3 centre(4.f * u(rng), 0.2f, 4.f * u(rng));
                    for (uint32_t i = s * rays; i < (s + 1) * rays; ++i) {
                        Ray& r = b.ray[order[i]];
                        r.org = org;
                        r.dir = normalize(centre + Vec3(0.5f * u(rng), 0.f, 0.5f * u(rng)) - org);
                        b.pre[order[i]] = RayPrecomp(r);
                    }
                }
            // The stream of the rays order[first, first + rays) into `ids`: in increasing order,
            // as the tracer's are, each from no hit and its full t, as after load_rays.
            auto load_stream = [&](uint32_t first, uint32_t* ids) {
                std::copy(order.begin() + first, order.begin() + first + rays, ids);
                std::sort(ids, ids + rays);
                for (uint32_t i = 0; i < rays; ++i) {
                    b.trav.set(ids[i], b.pre[ids[i]], b.ray[ids[i]].t_max);
                    b.hit[ids[i]] = Hit{};
                }
            };
            // A traversal as the tracer starts one (its job's stream, the shared-origin check);
            // the entry node found beforehand, as a frame's is by the search it traces as ops.
            auto traverse = [&](uint32_t* ids, TraceDetail detail, uint32_t entry) {
                job.n = rays;
                job.ids = ids;
                job.entry = entry;
                job.shared_origin = shared_origin(job.rays, ids, rays);  // as the tracer
                kernels.traverse[int(detail)](job);
            };
            auto reset = [&] {
                for (uint32_t s = 0; s < streams; ++s) {
                    uint32_t* ids = stream_ids.data() + size_t(s) * stride;
                    load_stream(s * rays, ids);
                    stream_entry[s] =
                        entry_below(bvh, b.pre[ids[0]], b.ray[ids[0]].t_max, shape.entry_depth);
                }
            };
            auto run = [&](TraceDetail detail) {
                for (uint32_t s = 0; s < streams; ++s)
                    traverse(stream_ids.data() + size_t(s) * stride, detail, stream_entry[s]);
            };
            // Before each repetition, every other ray's traversal, in streams of as many rays, in
            // a new order (a frame's traversals do not repeat), then the batch's own, untimed:
            // the timed run is primed, as the model's predictor replays it. Displaced, the model
            // mispredicted 0.26-0.57 times a one-ray box test where the core's timing barely
            // moved (33.3 / 52.9 cycles a box test entering at the root / 6 levels down against
            // 30.8 / 51.3 primed, scalar, Zen 4 VM, 2026-12-04: 3-11 cycles a modelled
            // misprediction, against 51 on the branch microbenchmark), and the fit that nets the
            // model's mispredictions out priced the one-lane box test at 0 (scalar) and the
            // stream loop's box per-op at 0 (AVX2, AVX-512). Primed, both mispredict little, and
            // the costs fitted hold the work; a frame's mispredictions are the model's, priced
            // at the branch microbenchmark's cost.
            const uint32_t batch_rays = rays * streams;
            auto displace_then_prime = [&](TraceDetail detail) {
                std::shuffle(order.begin() + batch_rays, order.end(), rng);
                other_ids.assign(stride, 0u);
                for (uint32_t first = batch_rays; first + rays <= k_slots; first += rays) {
                    load_stream(first, other_ids.data());
                    traverse(other_ids.data(), detail, 0);
                }
                reset();
                run(detail);
            };
            OneRaySample sample;
            sample.rays = rays;
            sample.streams = streams;
            sample.slots = batch_rays;
            sample.entry_depth = shape.entry_depth;
            OpLengthTally tally;
            ShortLoopClock loops;
            job.sink = &tally;
            job.short_loops = &loops;
            reset();
            run(TraceDetail::counts);
            tally.fill(sample, isa_width(resolved));
            sample.entries = {loops.entries[0], loops.entries[1]};
            job.sink = nullptr;
            job.short_loops = nullptr;
            if (predictor_replay) {
                auto recorder = [&](bool others) {
                    return [&, others](TraceSink& sink) {
                        TilePass pass;
                        pass.tile = uint32_t(out.size());
                        pass.slot_count = k_slots;
                        sink.begin_pass(pass);
                        job.sink = &sink;
                        if (others) {
                            displace_then_prime(TraceDetail::lanes);
                        } else {
                            reset();
                            run(TraceDetail::lanes);
                        }
                        job.sink = nullptr;
                        sink.end_pass(pass);
                    };
                };
                const ModelledMispredictions modelled =
                    predictor_replay(recorder(true), recorder(false));
                sample.modelled_mispredictions = modelled.total;
                sample.modelled_box_loop_mispredictions = modelled.box_by_loop;
                sample.few_ray_one_lane_box_ops = modelled.few_ray_one_lane_box_ops;
            }
            std::vector<double> times;
            const double ticks_per_cycle = tsc_ticks_per_core_cycle(3, isa_width(resolved));
            uint32_t set_aside = 0;
            while (needs_more_samples(times, convergence)) {
                displace_then_prime(TraceDetail::none);
                reset();
                const uint64_t start = __rdtsc();
                run(TraceDetail::none);
                times.push_back(std::max(0.0, double(__rdtsc() - start) - overhead));
                core_contention().set_aside_if_contended({&times}, set_aside, convergence.budget);
            }
            const Convergence c = judge_convergence(times, convergence);
            sample.cycles = c.fastest / ticks_per_cycle;
            sample.converged = c.converged;
            sample.repetitions = c.samples;
            const ClockedShares shares = clocked_loop_shares(
                job,
                [&] {
                    displace_then_prime(TraceDetail::none);
                    reset();
                },
                [&] { run(TraceDetail::none); });
            sample.short_loop_share = shares.short_loops;
            sample.leaf_share = shares.all_leaves();
            out.push_back(sample);
            if (shape.bundle)
                for (uint32_t i = 0; i < batch_rays; ++i) {
                    b.ray[order[i]] = b.saved_ray[order[i]];
                    b.pre[order[i]] = b.saved_pre[order[i]];
                }
        }
    return out;
}

std::vector<KernelRate> run_gather_compress_microbenchmarks(Isa isa, uint32_t repeats) {
    const Scene scene = synthetic_scene();
    const Bvh bvh(scene);
    const StreamKernels& kernels = stream_kernels(resolve_isa(isa));
    std::mt19937 rng(3);
    const double overhead = tsc_overhead();
    std::vector<KernelRate> out;
    for (uint32_t slots : {256u, 4096u, 65536u}) {
        Buffers b = make_buffers(scene, bvh, slots, rng);
        std::vector<uint32_t> order(slots);
        std::iota(order.begin(), order.end(), 0u);
        for (bool scattered : {false, true}) {
            for (uint32_t n : {16u, 256u, slots}) {
                if (n > slots) continue;
                std::vector<double> gather_t, compress_t;
                for (uint32_t rep = 0; rep < repeats; ++rep) {
                    if (scattered) std::shuffle(order.begin(), order.end(), rng);
                    std::copy(order.begin(), order.begin() + n, b.ids.begin());
                    // The box kernel against a box every ray passes: a record-half read of 7
                    // fields and a compress per group, no failing ids.
                    Bounds3 all;
                    all.lo = Vec3(-1e30f);
                    all.hi = Vec3(1e30f);
                    uint32_t negative = 0;
                    uint64_t s = __rdtsc();
                    kernels.box_filter(b.trav.view(), all, 0, b.ids.data(), n, b.scratch.data(),
                                       b.scratch2.data(), nullptr, negative);
                    uint64_t e = __rdtsc();
                    gather_t.push_back((double(e - s) - overhead) / n);
                    for (uint32_t i = 0; i < n; ++i) b.mask[i] = uint8_t(rng() & 1);
                    s = __rdtsc();
                    kernels.partition(b.ids.data(), n, b.mask.data(), b.scratch.data());
                    e = __rdtsc();
                    compress_t.push_back((double(e - s) - overhead) / n);
                }
                const double ticks_per_cycle =
                    tsc_ticks_per_core_cycle(3, isa_width(resolve_isa(isa)));
                out.push_back({"field read (box kernel, 7 fields)", slots, n, scattered,
                               median(gather_t) / ticks_per_cycle});
                out.push_back({"compress partition", slots, n, scattered,
                               median(compress_t) / ticks_per_cycle});
            }
        }
    }
    return out;
}

namespace {

// A mesh of `triangles` triangles, each with its own three vertices in triangle order, spread
// over a unit box (what surface_at computes does not depend on where they are).
Scene surface_read_mesh(uint32_t triangles, std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.f, 1.f);
    Scene s;
    s.name = "surface-reads";
    s.materials.resize(1);
    s.positions.resize(size_t(triangles) * 3);
    s.triangles.resize(triangles);
    for (uint32_t i = 0; i < triangles; ++i) {
        const Vec3 base(u(rng), u(rng), u(rng));
        s.positions[3 * size_t(i)] = base;
        s.positions[3 * size_t(i) + 1] = base + Vec3(0.01f, 0.f, 0.f);
        s.positions[3 * size_t(i) + 2] = base + Vec3(0.f, 0.01f, 0.f);
        s.triangles[i].v0 = 3 * i;
        s.triangles[i].v1 = 3 * i + 1;
        s.triangles[i].v2 = 3 * i + 2;
    }
    return s;
}

}  // namespace

std::vector<uint32_t> surface_read_hits(const SurfaceReadSample& sample, uint32_t repetition) {
    std::mt19937 rng(uint32_t(sample.seed * 7919 + repetition));
    std::uniform_int_distribution<uint32_t> pick(0, sample.triangles - 1);
    std::vector<uint32_t> prims(sample.lanes);
    for (uint32_t& p : prims) p = pick(rng);
    return prims;
}

SharedOriginSample run_shared_origin_microbenchmark(Isa isa, const ConvergenceRule& convergence) {
    namespace f = traversal_field;
    constexpr uint32_t k_short = 1024, k_long = 4096;
    const double overhead = tsc_overhead();
    const double ticks_per_cycle = tsc_ticks_per_core_cycle(3, isa_width(resolve_isa(isa)));
    // Traversal records (64 bytes a slot) whose origins all agree, as a pinhole camera's rays'.
    std::vector<float> records(size_t(k_long) * f::record, 0.5f);
    std::vector<uint32_t> ids(k_long + k_stream_padding);
    std::iota(ids.begin(), ids.end(), 0u);
    std::vector<double> times[2];
    uint32_t set_aside = 0;
    const float* found = nullptr;
    while (needs_more_samples(times[0], convergence) || needs_more_samples(times[1], convergence)) {
        for (int which = 0; which < 2; ++which) {
            const uint32_t n = which ? k_long : k_short;
            const uint64_t start = __rdtsc();
            found = shared_origin(records.data(), ids.data(), n);
            times[which].push_back(std::max(0.0, double(__rdtsc() - start) - overhead));
        }
        core_contention().set_aside_if_contended({&times[0], &times[1]}, set_aside,
                                                 convergence.budget);
    }
    if (!found) throw std::logic_error("shared-origin microbenchmark: origins differ");
    const Convergence a = judge_convergence(times[0], convergence);
    const Convergence b = judge_convergence(times[1], convergence);
    SharedOriginSample s;
    s.per_lane_cycles =
        std::max(0.0, (b.fastest - a.fastest) / double(k_long - k_short)) / ticks_per_cycle;
    s.converged = a.converged && b.converged;
    s.repetitions = uint32_t(times[1].size());
    return s;
}

std::vector<SurfaceReadSample> run_surface_read_microbenchmarks(Isa isa,
                                                                const ConvergenceRule& convergence,
                                                                uint64_t seed) {
    constexpr uint32_t k_lanes = 4096, k_resident = 64;
    std::mt19937 rng{uint32_t(seed)};
    const double overhead = tsc_overhead();
    const double ticks_per_cycle = tsc_ticks_per_core_cycle(3, isa_width(resolve_isa(isa)));
    std::vector<Ray> rays(k_lanes);
    std::vector<Hit> hits(k_lanes);
    std::vector<SurfaceHit> surf(k_lanes);
    std::vector<uint32_t> ids(k_lanes);
    std::iota(ids.begin(), ids.end(), 0u);
    std::uniform_real_distribution<float> u(0.f, 0.5f);
    for (uint32_t i = 0; i < k_lanes; ++i) {
        rays[i].dir = Vec3(0.f, 0.f, 1.f);
        hits[i].t = 1.f;
        hits[i].u = u(rng);
        hits[i].v = u(rng);
    }
    const Scene resident = surface_read_mesh(k_resident, rng);
    std::vector<SurfaceReadSample> out;
    uint64_t stream_seed = seed;
    for (uint32_t triangles : {1u << 13, 1u << 17, 1u << 20}) {
        const Scene mesh = surface_read_mesh(triangles, rng);
        SurfaceReadSample sample;
        sample.triangles = triangles;
        sample.lanes = k_lanes;
        sample.seed = ++stream_seed;
        // Interleaved: the mesh's stream, then the resident one, each time anew.
        std::vector<double> times, resident_times;
        float sink = 0.f;
        uint32_t set_aside = 0;
        for (uint32_t rep = 0; needs_more_samples(times, convergence) ||
                               needs_more_samples(resident_times, convergence);
             ++rep) {
            const std::vector<uint32_t> prims = surface_read_hits(sample, rep);
            for (uint32_t i = 0; i < k_lanes; ++i) hits[i].prim = prims[i];
            uint64_t start = __rdtsc();
            compute_surfaces(mesh, rays.data(), hits.data(), ids.data(), k_lanes, surf.data());
            times.push_back(std::max(0.0, double(__rdtsc() - start) - overhead));
            sink += surf[k_lanes / 2].position.x;
            for (uint32_t i = 0; i < k_lanes; ++i) hits[i].prim = prims[i] % k_resident;
            start = __rdtsc();
            compute_surfaces(resident, rays.data(), hits.data(), ids.data(), k_lanes, surf.data());
            resident_times.push_back(std::max(0.0, double(__rdtsc() - start) - overhead));
            sink += surf[k_lanes / 2].position.x;
            core_contention().set_aside_if_contended({&times, &resident_times}, set_aside,
                                                     convergence.budget);
        }
        if (sink == 12345.f) out.clear();  // keeps the surfaces computed
        const Convergence c = judge_convergence(times, convergence);
        const Convergence r = judge_convergence(resident_times, convergence);
        sample.cycles = c.fastest / ticks_per_cycle;
        sample.resident_cycles = r.fastest / ticks_per_cycle;
        sample.converged = c.converged && r.converged;
        sample.repetitions = uint32_t(times.size());
        out.push_back(sample);
    }
    return out;
}

namespace {

// The scene lines a traversal reads: each box test's node, each passed leaf's primitives.
class SceneLineSink : public TraceSink {
  public:
    // `also`, where given, receives every op too.
    SceneLineSink(const Bvh& bvh, TraceSink* also) : m_bvh(bvh), m_also(also) {}
    void op(const StreamOp& op) override {
        if (m_also) m_also->op(op);
        if (op.kind != OpKind::box_test) return;
        ++box_tests;
        const BvhNode& node = m_bvh.nodes()[op.object];
        add(&node, sizeof(BvhNode));
        if (node.is_leaf() && op.pass_count > 0)
            add(&m_bvh.leaf_primitives()[node.first], size_t(node.count) * sizeof(LeafPrimitive));
    }
    std::vector<const uint64_t*> lines() const {
        std::vector<const uint64_t*> out;
        for (const uintptr_t l : m_lines) out.push_back(reinterpret_cast<const uint64_t*>(l << 6));
        return out;
    }
    uint64_t box_tests = 0;

  private:
    void add(const void* p, size_t bytes) {
        const uintptr_t first = reinterpret_cast<uintptr_t>(p) >> 6;
        const uintptr_t last = (reinterpret_cast<uintptr_t>(p) + bytes - 1) >> 6;
        for (uintptr_t l = first; l <= last; ++l) m_lines.insert(l);
    }
    const Bvh& m_bvh;
    TraceSink* m_also;
    std::set<uintptr_t> m_lines;
};

}  // namespace

std::vector<PredictorSample> run_predictor_microbenchmarks(
    const Scene& scene, const Bvh& bvh, Isa isa, const ConvergenceRule& convergence, uint64_t seed,
    const PredictorBatchSink& batch_sink, bool time_evicted) {
    constexpr uint32_t k_res = 64, k_tile = 16, k_tiles = (k_res / k_tile) * (k_res / k_tile);
    constexpr uint32_t k_pixels = k_res * k_res;
    const Isa resolved = resolve_isa(isa);
    const StreamKernels& kernels = stream_kernels(resolved);
    std::mt19937 rng{uint32_t(seed)};
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    // Slots [0, k_pixels): the camera rays in pixel order; [k_pixels, 2 k_pixels): their bounces.
    Buffers b = allocate_buffers(2 * k_pixels);
    const CameraFrame camera(scene.camera, k_res, k_res);
    for (uint32_t p = 0; p < k_pixels; ++p) {
        const Ray r = camera.generate(PathKey(seed, p, 0));
        const Hit h = bvh.intersect(r);
        Vec3 d;
        do d = Vec3(u(rng), u(rng), u(rng));
        while (dot(d, d) > 1.f || dot(d, d) < 1e-4f);
        d = normalize(d);
        if (dot(d, r.dir) > 0.f) d = -d;
        Ray bounce;
        bounce.org = h.valid() ? r.org + r.dir * (h.t * 0.999f) : r.org;
        bounce.dir = d;
        b.ray[p] = r;
        b.ray[k_pixels + p] = bounce;
    }
    for (uint32_t i = 0; i < 2 * k_pixels; ++i) b.pre[i] = RayPrecomp(b.ray[i]);
    TraversalJob job = traversal_job(bvh, b);
    const double overhead = tsc_overhead();
    const double ticks_per_cycle = tsc_ticks_per_core_cycle(3, isa_width(resolved));
    std::vector<PredictorSample> out;
    for (const bool bounce : {false, true}) {
        // Each tile's batch: its slots in increasing order, as the tracer's streams are.
        std::vector<std::vector<uint32_t>> batches(k_tiles);
        for (uint32_t t = 0; t < k_tiles; ++t) {
            const uint32_t x0 = (t % (k_res / k_tile)) * k_tile,
                           y0 = (t / (k_res / k_tile)) * k_tile;
            for (uint32_t y = y0; y < y0 + k_tile; ++y)
                for (uint32_t x = x0; x < x0 + k_tile; ++x)
                    batches[t].push_back((bounce ? k_pixels : 0) + y * k_res + x);
        }
        auto traverse = [&](uint32_t t, TraceDetail detail) {
            const std::vector<uint32_t>& ids = batches[t];
            for (const uint32_t id : ids) {
                b.trav.set(id, b.pre[id], b.ray[id].t_max);
                b.hit[id] = Hit{};
            }
            std::copy(ids.begin(), ids.end(), b.ids.begin());
            job.ids = b.ids.data();
            job.n = uint32_t(ids.size());
            job.entry = 0;
            job.shared_origin = shared_origin(job.rays, job.ids, job.n);
            kernels.traverse[int(detail)](job);
        };
        PredictorSample sample;
        sample.bounce = bounce;
        sample.batches = k_tiles;
        std::vector<std::vector<const uint64_t*>> lines(k_tiles);
        for (uint32_t t = 0; t < k_tiles; ++t) {
            TraceSink* model = batch_sink ? batch_sink(bounce, t) : nullptr;
            TilePass pass;
            pass.tile = t;
            pass.slot_count = 2 * k_pixels;
            if (model) model->begin_pass(pass);
            SceneLineSink sink(bvh, model);
            job.sink = &sink;
            traverse(t, TraceDetail::lanes);
            job.sink = nullptr;
            if (model) model->end_pass(pass);
            lines[t] = sink.lines();
            sample.box_tests += sink.box_tests;
            sample.lines += lines[t].size();
        }
        uint64_t touched = 0;
        // What runs before each timed traversal of a batch.
        enum class Before { itself, itself_and_others_lines, others_traversals, itself_evicted };
        for (uint32_t t = 0; t < k_tiles; ++t) {
            bool converged = true;
            // What runs before each timed traversal of the batch, as `before` says.
            auto prepare = [&](Before before) {
                if (before == Before::others_traversals) {
                    for (uint32_t o = 0; o < k_tiles; ++o)
                        if (o != t) traverse(o, TraceDetail::none);
                } else {
                    traverse(t, TraceDetail::none);
                    if (before == Before::itself_and_others_lines)
                        for (uint32_t o = 0; o < k_tiles; ++o)
                            if (o != t)
                                for (const uint64_t* line : lines[o]) touched += *line;
                    if (before == Before::itself_evicted) {
                        evict_caches();  // the scene's lines, as a cold render's
                        // The batch's own data back in the caches, as primed: only the
                        // scene's lines stay in DRAM (traverse writes its rays' fields).
                        const size_t n = batches[t].size() + k_stream_padding;
                        for (const uint32_t id : batches[t]) {
                            touched += touch_lines(&b.pre[id], sizeof(RayPrecomp));
                            touched += b.any_hit[id];
                        }
                        for (const std::vector<uint32_t>* v : {&b.ids, &b.scratch, &b.scratch2})
                            touched += touch_lines(v->data(), n * sizeof(uint32_t));
                        touched += touch_lines(
                            b.positions.data(),
                            std::min(b.positions.size(), k_leaf_batch * n) * sizeof(uint32_t));
                        touched += touch_lines(b.mask.data(), n);
                    }
                }
            };
            // The batch's fastest cycles in a state, and their split by the loop that ran them,
            // box tests and leaves apart (clocked_loop_shares, each repetition prepared as the
            // timed ones are).
            auto timed = [&](Before before, BatchStateCycles& state) {
                // Untimed first: the state before (the batch run many times, primed or cached)
                // lasts beyond one preparation; on the branch microbenchmark the first displaced
                // repetition was over 3 % faster than the rest's median in 23 % of the batches
                // and, their fastest, set the misprediction's cost (Intel Xeon VM, 2026-12-06).
                for (uint32_t w = 0; w < k_predictor_warm_repetitions; ++w) {
                    prepare(before);
                    traverse(t, TraceDetail::none);
                }
                std::vector<double> times;
                uint32_t set_aside = 0;
                while (needs_more_samples(times, convergence)) {
                    prepare(before);
                    const uint64_t start = __rdtsc();
                    traverse(t, TraceDetail::none);
                    times.push_back(std::max(0.0, double(__rdtsc() - start) - overhead));
                    core_contention().set_aside_if_contended({&times}, set_aside,
                                                             convergence.budget);
                }
                const Convergence c = judge_convergence(times, convergence);
                converged = converged && c.converged;
                const ClockedShares shares = clocked_loop_shares(
                    job, [&] { prepare(before); }, [&] { traverse(t, TraceDetail::none); });
                const double cycles = c.fastest / ticks_per_cycle;
                state.cycles += cycles;
                state.loops[0] += cycles * shares.short_loops[0];
                state.loops[1] += cycles * shares.short_loops[1];
                state.loops[2] += cycles * shares.stream_loop();
                for (size_t l = 0; l < 3; ++l) state.leaves[l] += cycles * shares.leaves[l];
            };
            timed(Before::itself, sample.primed);
            timed(Before::itself_and_others_lines, sample.cached);
            timed(Before::others_traversals, sample.displaced);
            if (time_evicted) timed(Before::itself_evicted, sample.evicted);
            sample.converged_batches += converged;
        }
        if (touched == 1) out.clear();  // keeps the reads of the others' lines
        out.push_back(sample);
    }
    return out;
}

std::vector<PredictorSample> run_predictor_microbenchmarks(Isa isa,
                                                           const ConvergenceRule& convergence,
                                                           uint64_t seed) {
    const Scene scene = synthetic_scene(true);
    return run_predictor_microbenchmarks(scene, Bvh(scene), isa, convergence, seed);
}

Scene branch_microbench_scene() {
    return random_triangle_cloud(20000, 7);
}

double microbench_timed_slot_bytes(uint32_t slots) {
    return allocate_buffers(slots).timed_bytes() / double(slots);
}

}  // namespace sfx
