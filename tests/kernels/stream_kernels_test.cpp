// Every stream-kernel back end the machine has (scalar always) decides exactly as the one-ray code,
// lane by lane, and partitions exactly as a stable partition: the slab test on the hard cases
// (origins on slab planes with zero directions (0 * inf), infinite inverse directions, signed
// zeros, flat and empty boxes, t_max of -1, 0 and infinity; each lane's own origin or one the
// stream shares), the triangle filter's float stage, the sphere filter (origins on the surface,
// tangents), the traversal's leaf code over every leaf of a scene, and the compress. Streams of odd
// lengths exercise partial groups (at 16 lanes, the 8-lane tail), shuffled and increasing ids the
// records' transposed reads.

#include "kernels/stream/stream_kernels.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <numeric>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/intersect.h"
#include "kernels/rng.h"
#include "kernels/simd/lanes.h"
#include "workloads/scene_loader.h"

using namespace sfx;

namespace {

float pick(uint32_t i, uint32_t dim, const std::vector<float>& specials) {
    const uint32_t bits = random_bits(11, i, 0, 0, dim);
    if (bits % 3 == 0) return specials[(bits >> 8) % specials.size()];
    return (float((bits >> 8) & 0xffff) / 65536.f - 0.5f) * 8.f;
}

// Ids in a shuffled order with a padded tail, as the tracer's buffers have. The tail holds a
// sentinel: in-place kernels must not write past the stream (other streams live there).
constexpr uint32_t k_sentinel = 0xdeadbeef;
bool tail_intact(const std::vector<uint32_t>& ids, uint32_t n) {
    return std::all_of(ids.begin() + n, ids.end(), [](uint32_t v) { return v == k_sentinel; });
}

std::vector<uint32_t> shuffled_ids(uint32_t n, uint32_t seed) {
    std::vector<uint32_t> ids(n + k_stream_padding, k_sentinel);
    std::iota(ids.begin(), ids.begin() + n, 0u);
    for (uint32_t i = n; i > 1; --i) std::swap(ids[i - 1], ids[random_bits(seed, i, 0, 0, 1) % i]);
    return ids;
}

// n distinct ids out of the first n, 2n, 3n or 4n slots (the test makes 4n rays), as the
// tracer's streams hold them: shuffled, increasing with gaps (the runs stable partitions
// leave), or increasing with a few neighbours swapped (a group's first id is not its least).
std::vector<uint32_t> stream_ids(uint32_t n, uint32_t seed) {
    std::vector<uint32_t> ids(n + k_stream_padding, k_sentinel);
    std::vector<uint32_t> slots((1 + seed / 3 % 4) * n);
    std::iota(slots.begin(), slots.end(), 0u);
    for (uint32_t i = uint32_t(slots.size()); i > 1; --i)
        std::swap(slots[i - 1], slots[random_bits(seed, i, 0, 0, 2) % i]);
    std::copy(slots.begin(), slots.begin() + n, ids.begin());
    if (seed % 3 != 0) std::sort(ids.begin(), ids.begin() + n);
    if (seed % 3 == 2)
        for (uint32_t i = 1; i < n; i += 5) std::swap(ids[i - 1], ids[i]);
    return ids;
}

// The traversal's SoA ray records of the test's rays, in their order.
TraversalRays traversal_rays(const std::vector<RayPrecomp>& pre, const std::vector<float>& t_max) {
    TraversalRays rays;
    rays.resize(uint32_t(pre.size()));
    for (uint32_t l = 0; l < pre.size(); ++l) rays.set(l, pre[l], t_max[l]);
    return rays;
}

}  // namespace

TEST_CASE("Box filter of every back end equals intersect_box per lane, hard cases included",
          "[stream][simd]") {
    const std::vector<float> coords{0.f, -0.f, 1.f, -1.f, 2.f, 0.5f, 1e-30f, -1e30f};
    const std::vector<float> dirs{0.f, -0.f, 1.f, -1.f, 1e-40f, -1e-40f, 0.3f, 1e20f};
    const std::vector<float> t_maxes{INFINITY, 1.f, -1.f, 0.f, 0.5f, 3.f, 1e-7f, 100.f};
    for (const Isa isa : supported_isas()) {
        const StreamKernels& kernels = stream_kernels(isa);
        INFO("back end " << isa_name(isa));
        CHECK(kernels.isa == isa);
        CHECK(kernels.width == isa_width(isa));
        uint64_t lanes = 0, hits = 0, mismatches = 0, order_errors = 0, negative_errors = 0;
        uint32_t shared_streams = 0;
        for (uint32_t i = 0; i < 2000; ++i) {
            Bounds3 box;
            for (int a = 0; a < 3; ++a) {
                const float p = pick(i, 10 + a, coords), q = pick(i, 20 + a, coords);
                box.lo[a] = std::min(p, q);
                box.hi[a] = i % 11 == 0 ? box.lo[a] : std::max(p, q);  // flat boxes too
            }
            if (i % 97 == 0) box = Bounds3{};  // empty: lo = inf, hi = -inf
            const uint32_t n = 1 + i % 41;
            std::vector<RayPrecomp> pre;
            std::vector<float> t_max;
            Ray unit;
            unit.dir = {0.f, 0.f, 1.f};
            for (uint32_t l = 0; l < 4 * n; ++l) {
                const uint32_t k = i * 256 + l;
                Ray ray;
                for (int a = 0; a < 3; ++a) {
                    // Every fourth stream's rays share one origin (the box filter's
                    // shared-origin form), on slab planes as often as the others.
                    ray.org[a] = pick(i % 4 == 3 ? i * 256 : k, 30 + a, coords);
                    ray.dir[a] = pick(k, 40 + a, dirs);
                }
                if (k % 2 == 0 && !box.empty()) ray.dir = box.center() - ray.org;  // aim at it
                if (ray.dir == Vec3(0.f)) ray.dir.x = 1.f;
                pre.push_back(RayPrecomp(ray));
                t_max.push_back(t_maxes[random_bits(11, k, 0, 0, 50) % t_maxes.size()]);
            }
            const TraversalRays rays = traversal_rays(pre, t_max);
            const int axis = int(i % 5 % 3);
            const std::vector<uint32_t> ids = stream_ids(n, i);
            std::vector<uint32_t> pass(n + k_stream_padding), fail(n + k_stream_padding);
            std::vector<uint8_t> mask(n + k_stream_padding, 7);
            TraversalView view = rays.view();
            view.shared_origin = shared_origin(view.data, ids.data(), n);
            shared_streams += view.shared_origin != nullptr;
            if (i % 4 == 3) CHECK(view.shared_origin != nullptr);
            uint32_t negative = 0;
            const uint32_t passed = kernels.box_filter(view, box, axis, ids.data(), n, pass.data(),
                                                       fail.data(), mask.data(), negative);
            std::vector<uint32_t> want_pass, want_fail;
            uint32_t want_negative = 0;
            for (uint32_t l = 0; l < n; ++l) {
                const RayPrecomp& r = pre[ids[l]];
                const bool expected = intersect_box(r, box, t_max[ids[l]]) != INFINITY;
                ++lanes;
                hits += expected;
                mismatches += mask[l] != uint8_t(expected);
                (expected ? want_pass : want_fail).push_back(ids[l]);
                want_negative += expected && r.dir[axis] < 0.f;
            }
            order_errors += passed != want_pass.size() ||
                            !std::equal(want_pass.begin(), want_pass.end(), pass.begin()) ||
                            !std::equal(want_fail.begin(), want_fail.end(), fail.begin());
            negative_errors += negative != want_negative;
            // In place, without a mask: the passing prefix is the same.
            std::vector<uint32_t> in_place = ids;
            uint32_t negative2 = 0;
            const uint32_t passed2 =
                kernels.box_filter(view, box, axis, in_place.data(), n, in_place.data(),
                                   fail.data(), nullptr, negative2);
            order_errors += !tail_intact(in_place, n);
            order_errors += passed2 != passed ||
                            !std::equal(want_pass.begin(), want_pass.end(), in_place.begin()) ||
                            !std::equal(want_fail.begin(), want_fail.end(), fail.begin());
        }
        CHECK(hits > lanes / 10);
        CHECK(hits < lanes - lanes / 10);
        CHECK(mismatches == 0);
        CHECK(order_errors == 0);
        CHECK(negative_errors == 0);
        // The shared-origin streams, and those of one ray; no stream of differing origins.
        CHECK(shared_streams >= 500);
        CHECK(shared_streams < 700);
    }
}

TEST_CASE("Triangle filter of every back end keeps every hit and equals the scalar one",
          "[stream][simd]") {
    const std::vector<float> coords{0.f, -0.f, 1.f, -1.f, 2.f, 0.5f};
    const StreamKernels& scalar = stream_kernels(Isa::scalar);
    uint64_t total_hits = 0, total_candidates = 0, lanes = 0;
    for (const Isa isa : supported_isas()) {
        const StreamKernels& kernels = stream_kernels(isa);
        INFO("back end " << isa_name(isa));
        uint64_t lost_hits = 0, differ = 0, leaf_differ = 0, leaf_lanes = 0;
        for (uint32_t i = 0; i < 1500; ++i) {
            Vec3 p[3];
            for (int v = 0; v < 3; ++v)
                for (int a = 0; a < 3; ++a) p[v][a] = pick(i, 10 + 3 * v + a, coords);
            const uint32_t n = 1 + i % 37;
            std::vector<RayPrecomp> pre;
            for (uint32_t l = 0; l < 4 * n; ++l) {
                const uint32_t k = i * 256 + l;
                Ray ray;
                for (int a = 0; a < 3; ++a) ray.org[a] = pick(k, 30 + a, coords) * 3.f;
                // Aim at a point near the triangle (edges and vertices included).
                const float u = float(random_bits(13, k, 0, 0, 1) % 5) / 4.f;
                const float v = float(random_bits(13, k, 0, 0, 2) % 5) / 4.f * (1.f - u);
                ray.dir = p[0] * (1.f - u - v) + p[1] * u + p[2] * v - ray.org;
                if (k % 3 == 0) ray.dir = ray.dir + Vec3(0.f, 0.7f, 0.f);
                if (ray.dir == Vec3(0.f)) ray.dir.x = 1.f;
                pre.push_back(RayPrecomp(ray));
            }
            const TraversalRays rays =
                traversal_rays(pre, std::vector<float>(pre.size(), INFINITY));
            const std::vector<uint32_t> ids = stream_ids(n, i);
            std::vector<uint32_t> got(n + k_stream_padding), want(n + k_stream_padding);
            const uint32_t c = kernels.triangle_candidates(rays.view(), p[0], p[1], p[2],
                                                           ids.data(), n, got.data());
            const uint32_t c_scalar = scalar.triangle_candidates(rays.view(), p[0], p[1], p[2],
                                                                 ids.data(), n, want.data());
            differ += c != c_scalar || !std::equal(got.begin(), got.begin() + c, want.begin());
            // A leaf's run of 1-4 triangles (this one and shifted copies) in one pass: per
            // triangle, the same candidates as the scalar filter of that triangle alone.
            const uint32_t batch = 1 + i % k_leaf_batch, stride = n + k_stream_padding;
            LeafPrimitive leaf[k_leaf_batch];
            for (uint32_t j = 0; j < batch; ++j) {
                const Vec3 shift(0.25f * float(j), 0.f, 0.f);
                leaf[j] = {p[0] + shift, p[1] + shift, p[2] + shift, j};
            }
            std::vector<uint32_t> positions(size_t(k_leaf_batch) * stride);
            uint32_t found[k_leaf_batch];
            kernels.leaf_candidates(rays.view(), leaf, batch, ids.data(), n, positions.data(),
                                    stride, found);
            for (uint32_t j = 0; j < batch; ++j) {
                const uint32_t cj = scalar.triangle_candidates(rays.view(), leaf[j].p0, leaf[j].p1,
                                                               leaf[j].p2, ids.data(), n,
                                                               want.data());
                const auto first = positions.begin() + j * stride;
                leaf_differ += found[j] != cj || !std::equal(first, first + cj, want.begin());
                leaf_lanes += n;
            }
            for (uint32_t l = 0; l < n; ++l) {
                float t, u, v;
                const bool hit =
                    intersect_triangle(pre[ids[l]], p[0], p[1], p[2], INFINITY, t, u, v);
                const bool kept = std::find(got.begin(), got.begin() + c, l) != got.begin() + c;
                lost_hits += hit && !kept;
                total_hits += hit;
            }
            total_candidates += c;
            lanes += n;
        }
        CHECK(lost_hits == 0);
        CHECK(differ == 0);
        CHECK(leaf_differ == 0);
        CHECK(leaf_lanes > 2 * 1500);
    }
    CHECK(total_hits > 0);
    CHECK(total_candidates < lanes);  // the filter rejects something
}

TEST_CASE("Sphere filter of every back end equals intersect_sphere per lane, hard cases included",
          "[stream][simd]") {
    // Origins on the surface (spawned rays leaving it inwards and outwards), inside, outside;
    // rays through the centre, tangent, grazing, away; zero direction components; t_max of
    // -1, 0, below and beyond the roots, infinity; spheres of radius 0, tiny and huge.
    const std::vector<float> coords{0.f, -0.f, 1.f, -1.f, 2.f, 0.5f};
    const std::vector<float> radii{1.f, 0.5f, 0.f, 1e-3f, 1e4f, 3.f};
    const std::vector<float> t_maxes{INFINITY, 1.f, -1.f, 0.f, 0.5f, 3.f, 1e-7f, 100.f};
    for (const Isa isa : supported_isas()) {
        const StreamKernels& kernels = stream_kernels(isa);
        INFO("back end " << isa_name(isa));
        uint64_t lanes = 0, hits = 0, mismatches = 0, t_mismatches = 0;
        uint64_t surface_hits = 0, surface_misses = 0;  // lanes with an origin at the surface
        for (uint32_t i = 0; i < 1500; ++i) {
            Sphere sphere;
            for (int a = 0; a < 3; ++a) sphere.center[a] = pick(i, 10 + a, coords);
            sphere.radius = radii[random_bits(17, i, 0, 0, 1) % radii.size()];
            const uint32_t n = 1 + i % 41;
            std::vector<RayPrecomp> pre;
            std::vector<float> t_max;
            std::vector<uint8_t> at_surface;
            for (uint32_t l = 0; l < 4 * n; ++l) {
                const uint32_t k = i * 256 + l;
                Ray ray;
                at_surface.push_back(k % 6 < 2);
                for (int a = 0; a < 3; ++a) {
                    ray.org[a] = pick(k, 30 + a, coords) * 2.f;
                    ray.dir[a] = pick(k, 40 + a, coords);
                }
                // A point on the surface along a random direction, maybe nudged off it.
                Vec3 out = Vec3(pick(k, 50, coords), pick(k, 51, coords), pick(k, 52, coords));
                if (out == Vec3(0.f)) out.z = 1.f;
                const Vec3 surface = sphere.center + normalize(out) * sphere.radius;
                switch (k % 6) {
                    case 0:  // on the surface, leaving outwards or inwards
                        ray.org = surface;
                        ray.dir = (k / 6 % 2 ? out : -out) + ray.dir * 0.25f;
                        break;
                    case 1:  // just off the surface (a spawned ray)
                        ray.org =
                            offset_ray_origin(surface, normalize(out) * (k / 6 % 2 ? 1.f : -1.f));
                        break;
                    case 2:  // through the centre
                        ray.dir = sphere.center - ray.org;
                        break;
                    case 3: {  // tangent: at right angles to the radius through `surface`
                        const Vec3 side = cross(out, Vec3(0.3f, 1.f, 0.1f));
                        ray.org = surface - side * 2.f;
                        ray.dir = side;
                        break;
                    }
                    default:
                        break;
                }
                if (ray.dir == Vec3(0.f)) ray.dir.x = 1.f;
                pre.push_back(RayPrecomp(ray));
                t_max.push_back(t_maxes[random_bits(17, k, 0, 0, 50) % t_maxes.size()]);
            }
            const TraversalRays rays = traversal_rays(pre, t_max);
            const std::vector<uint32_t> ids = stream_ids(n, i);
            std::vector<uint8_t> mask(n + k_stream_padding, 7);
            std::vector<float> t(n + k_stream_padding, -7.f);
            const uint32_t passed = kernels.sphere_filter(rays.view(), pre.data(), sphere,
                                                          ids.data(), n, mask.data(), t.data());
            uint32_t want_passed = 0;
            for (uint32_t l = 0; l < n; ++l) {
                float want_t = 0.f;
                const bool want = intersect_sphere(pre[ids[l]], sphere, t_max[ids[l]], want_t);
                ++lanes;
                hits += want;
                want_passed += want;
                if (at_surface[ids[l]]) (want ? surface_hits : surface_misses) += 1;
                mismatches += mask[l] != uint8_t(want);
                t_mismatches += want && float_bits(t[l]) != float_bits(want_t);
            }
            mismatches += passed != want_passed;
        }
        CHECK(hits > lanes / 10);
        CHECK(hits < lanes - lanes / 10);
        CHECK(surface_hits > lanes / 20);  // leaving inwards: the far side
        CHECK(surface_misses > lanes / 20);  // leaving outwards
        CHECK(mismatches == 0);
        CHECK(t_mismatches == 0);
    }
}

TEST_CASE("Leaf tests of every back end, over every leaf, find the one-ray code's closest hit",
          "[stream][simd]") {
    // The traversal's leaf code (StreamKernels::leaf_tests, which the microbenchmarks time) on
    // every leaf of cornell (triangles in batches and spheres) for one stream of camera rays and
    // rays in every direction from inside the box: whatever order the leaves come in, each ray ends
    // with Bvh::intersect's hit.
    const Scene scene = load_scene("cornell");
    const Bvh bvh(scene);
    constexpr uint32_t n = 203;  // odd: partial groups at every width
    std::vector<Ray> rays(n);
    for (uint32_t i = 0; i < n; ++i) {
        Ray& r = rays[i];
        r.org = i % 2 ? scene.camera.eye : scene.camera.look_at;
        r.dir = normalize(Vec3(pick(i, 63, {0.f}), pick(i, 64, {0.f}), pick(i, 65, {0.f})) +
                          (i % 2 ? scene.camera.look_at - scene.camera.eye : Vec3(0.f)));
    }
    uint32_t hits = 0;
    for (const Isa isa : supported_isas()) {
        INFO("back end " << isa_name(isa));
        const StreamKernels& kernels = stream_kernels(isa);
        std::vector<RayPrecomp> pre;
        std::vector<float> t_max;
        for (const Ray& r : rays) pre.push_back(RayPrecomp(r)), t_max.push_back(r.t_max);
        TraversalRays trav = traversal_rays(pre, t_max);
        std::vector<Hit> hit(n);
        std::vector<uint8_t> any_hit(n, 0), mask(n + k_stream_padding);
        std::vector<uint32_t> ids = stream_ids(n, 1);  // increasing with gaps
        std::vector<uint32_t> positions(size_t(k_leaf_batch) * (n + k_stream_padding));
        TraversalJob job = traversal_job(bvh);
        job.rays = trav.data();
        job.pre = pre.data();
        job.hit = hit.data();
        job.any_hit = any_hit.data();
        job.ids = ids.data();
        job.n = n;
        job.positions = positions.data();
        job.mask = mask.data();
        uint64_t passed = 0;
        // Back to front: the closest hit must win over the ones found before it.
        for (size_t i = bvh.nodes().size(); i-- > 0;) {
            const BvhNode& node = bvh.nodes()[i];
            if (node.is_leaf()) passed += kernels.leaf_tests(job, node.first, node.count, n);
        }
        uint32_t mismatches = 0;
        hits = 0;
        for (uint32_t l = 0; l < n; ++l) {
            const uint32_t id = ids[l];
            const Hit want = bvh.intersect(rays[id]);
            hits += want.valid();
            mismatches += hit[id].prim != want.prim || float_bits(hit[id].t) != float_bits(want.t);
        }
        CHECK(mismatches == 0);
        CHECK(passed >= hits);  // each hit taken at least once
        CHECK(tail_intact(ids, n));
    }
    CHECK(hits > n / 2);
}

TEST_CASE("Compress partition of every back end is the stable partition", "[stream][simd]") {
    for (const Isa isa : supported_isas()) {
        const StreamKernels& kernels = stream_kernels(isa);
        INFO("back end " << isa_name(isa));
        for (uint32_t n = 1; n < 70; ++n) {
            std::vector<uint32_t> ids = shuffled_ids(n, n), scratch(n + k_stream_padding);
            std::vector<uint8_t> mask(n + k_stream_padding, 1);  // past n: "passing" junk
            for (uint32_t i = 0; i < n; ++i) mask[i] = random_bits(17, n, i, 0, 0) % 3 == 0;
            std::vector<uint32_t> want(ids.begin(), ids.begin() + n);
            std::vector<uint8_t> want_mask(mask.begin(), mask.begin() + n);
            std::vector<uint32_t> order(n);
            std::iota(order.begin(), order.end(), 0u);
            std::stable_partition(order.begin(), order.end(),
                                  [&](uint32_t i) { return want_mask[i] != 0; });
            for (uint32_t i = 0; i < n; ++i) order[i] = want[order[i]];
            const uint32_t passed = kernels.partition(ids.data(), n, mask.data(), scratch.data());
            CHECK(passed == uint32_t(std::count(want_mask.begin(), want_mask.end(), 1)));
            CHECK(std::equal(order.begin(), order.end(), ids.begin()));
            CHECK(tail_intact(ids, n));
        }
    }
}

TEST_CASE("Lane type: masks as values, gathers and compress at width 1 and 4", "[simd]") {
    const vfloat<4> a = {1.f, -2.f, 3.f, -0.f};
    const vbool<4> negative = sign_bit<4>(a);
    CHECK(bits<4>(negative) == 0b1010u);
    CHECK(popcount<4>(negative) == 2u);
    CHECK(any<4>(negative));
    CHECK_FALSE(none<4>(negative));
    CHECK(none<4>(a != a));
    const vfloat<4> picked = select(negative, broadcast<4>(9.f), a);
    CHECK((picked[0] == 1.f && picked[1] == 9.f && picked[2] == 3.f && picked[3] == 9.f));
    CHECK(bits<4>(from_bits<4>(0b0110u)) == 0b0110u);
    const float table[5] = {10.f, 11.f, 12.f, 13.f, 14.f};
    const vfloat<4> g = gather<4>(table, vint<4>{4, 0, 2, 2});
    CHECK((g[0] == 14.f && g[1] == 10.f && g[2] == 12.f && g[3] == 12.f));
    alignas(32) float records[32];
    for (int i = 0; i < 32; ++i) records[i] = float(i);
    const int32_t starts[4] = {24, 0, 8, 8};
    vfloat<4> fields[8];
    load_transposed<4>(records, starts, fields);
    for (int f = 0; f < 8; ++f)
        CHECK((fields[f][0] == float(24 + f) && fields[f][1] == float(f) &&
               fields[f][2] == float(8 + f) && fields[f][3] == float(8 + f)));
    vfloat<4> quarter[4];  // the first four fields only (a shared-origin stream's box read)
    const int32_t quarter_starts[4] = {4, 28, 16, 0};
    load_transposed<4, 4>(records, quarter_starts, quarter);
    for (int f = 0; f < 4; ++f)
        CHECK((quarter[f][0] == float(4 + f) && quarter[f][1] == float(28 + f) &&
               quarter[f][2] == float(16 + f) && quarter[f][3] == float(f)));
    uint32_t out[4] = {};
    CHECK(compress_store<4>(0b1101u, vint<4>{5, 6, 7, 8}, out) == 3u);
    CHECK((out[0] == 5u && out[1] == 7u && out[2] == 8u));
    uint32_t exact[5] = {0, 0, 0, 0, 99};
    CHECK(compress_store_exact<4>(0b1010u, vint<4>{5, 6, 7, 8}, exact) == 2u);
    CHECK((exact[0] == 6u && exact[1] == 8u && exact[2] == 0u && exact[3] == 0u));
    // Width 1 is plain float and bool.
    static_assert(std::is_same_v<vfloat<1>, float> && std::is_same_v<vbool<1>, bool>);
    CHECK(sign_bit<1>(-0.f));
    CHECK(select(true, 1.f, 2.f) == 1.f);
    CHECK(popcount<1>(true) == 1u);
    uint32_t one = 0;
    CHECK(compress_store<1>(1u, 42, &one) == 1u);
    CHECK(one == 42u);
    CHECK(compress_store_exact<1>(0u, 7, &one) == 0u);
    CHECK(one == 42u);
}
