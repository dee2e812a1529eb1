// The stream tracer's lane-parallel slab test decides exactly as intersect_box, lane by lane,
// including the hard cases: origins on slab planes with zero directions (0 * inf), infinite
// inverse directions, signed zeros, flat and empty boxes, t_max of -1, 0 and infinity.

#include <catch2/catch.hpp>
#include <vector>

#include "kernels/rng.h"
#include "kernels/stream/stream_box.h"

using namespace sfx;

namespace {

float pick(uint32_t i, uint32_t dim, const std::vector<float>& specials) {
    const uint32_t bits = random_bits(11, i, 0, 0, dim);
    if (bits % 3 == 0) return specials[(bits >> 8) % specials.size()];
    return (float((bits >> 8) & 0xffff) / 65536.f - 0.5f) * 8.f;
}

}  // namespace

TEST_CASE("Lane slab test equals intersect_box on every lane, hard cases included", "[stream]") {
    const std::vector<float> coords{0.f, -0.f, 1.f, -1.f, 2.f, 0.5f, 1e-30f, -1e30f};
    const std::vector<float> dirs{0.f, -0.f, 1.f, -1.f, 1e-40f, -1e-40f, 0.3f, 1e20f};
    const std::vector<float> t_maxes{INFINITY, 1.f, -1.f, 0.f, 0.5f, 3.f, 1e-7f, 100.f};
    constexpr int W = 4;
    uint64_t lanes = 0, hits = 0, mismatches = 0;
    for (uint32_t i = 0; i < 40000; ++i) {
        Bounds3 box;
        for (int a = 0; a < 3; ++a) {
            const float p = pick(i, 10 + a, coords), q = pick(i, 20 + a, coords);
            box.lo[a] = std::min(p, q);
            box.hi[a] = i % 11 == 0 ? box.lo[a] : std::max(p, q);  // flat boxes too
        }
        if (i % 97 == 0) box = Bounds3{};  // empty: lo = inf, hi = -inf
        std::vector<RayPrecomp> rays;
        std::vector<float> t;
        for (int l = 0; l < W; ++l) {
            const uint32_t k = i * W + uint32_t(l);
            Ray ray;
            for (int a = 0; a < 3; ++a) {
                ray.org[a] = pick(k, 30 + a, coords);
                ray.dir[a] = pick(k, 40 + a, dirs);
            }
            if (k % 2 == 0 && !box.empty()) ray.dir = box.center() - ray.org;  // aim at it
            if (ray.dir == Vec3(0.f)) ray.dir.x = 1.f;
            rays.emplace_back(ray);
            t.push_back(t_maxes[random_bits(11, k, 0, 0, 50) % t_maxes.size()]);
        }
        const RayPrecomp* lane[W] = {&rays[0], &rays[1], &rays[2], &rays[3]};
        const uint32_t bits = box_test_gather4(lane, t.data(), box);
        for (int l = 0; l < W; ++l) {
            const bool expected = intersect_box(rays[l], box, t[l]) != INFINITY;
            ++lanes;
            hits += expected;
            mismatches += expected != bool((bits >> l) & 1u);
        }
    }
    CHECK(hits > lanes / 10);
    CHECK(hits < lanes - lanes / 10);
    CHECK(mismatches == 0);
}
