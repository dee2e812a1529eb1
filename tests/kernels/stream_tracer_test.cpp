// The stream tracer against the reference tracer, bit for bit; its hit records; the trace.

#include "kernels/stream/stream_tracer.h"

#include <catch2/catch.hpp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "kernels/bvh.h"
#include "kernels/camera.h"
#include "kernels/reference/reference_tracer.h"
#include "tests/kernels/test_scenes.h"

using namespace sfx;

namespace {

using test::box_scene;
using test::Variant;

RenderSettings small(const Scene& s, uint32_t w, uint32_t h, uint32_t spp) {
    RenderSettings r;
    r.width = w;
    r.height = h;
    r.spp = spp;
    r.max_depth = s.max_depth;
    return r;
}

bool same_bits(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Vec3)) == 0;
}

size_t differing_pixels(const Image& a, const Image& b) {
    size_t n = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        n += std::memcmp(&a.pixels[i], &b.pixels[i], sizeof(Vec3)) != 0;
    return n;
}

bool same_hit(const Hit& a, const Hit& b) {
    return a.prim == b.prim && float_bits(a.t) == float_bits(b.t) &&
           float_bits(a.u) == float_bits(b.u) && float_bits(a.v) == float_bits(b.v);
}

// Checks every k-th traced ray against the reference traversal of the same ray.
struct HitChecker : RayObserver {
    const Bvh& bvh;
    uint32_t every;
    uint64_t seen = 0, checked = 0, mismatches = 0;
    HitChecker(const Bvh& b, uint32_t k) : bvh(b), every(k) {}
    void ray(const PathState& p, const Ray& ray, const Hit& hit, bool occluded) override {
        if (seen++ % every) return;
        ++checked;
        if (p.kind == RayKind::shadow)
            mismatches += bvh.occluded(ray) != occluded;
        else
            mismatches += !same_hit(bvh.intersect(ray), hit);
    }
};

void check_identical(const Scene& s, RenderSettings settings) {
    const Bvh bvh(s);
    settings.threads = 1;
    const RenderResult ref = render_reference(s, bvh, settings);
    REQUIRE(ref.image.mean().x > 0.f);
    // Every back end the machine has, the scalar one always.
    for (const Isa isa : supported_isas())
        for (uint32_t tile : {1u, 8u, 32u, 64u})
            for (uint32_t threads : {1u, 2u}) {
                settings.tile = tile;
                settings.threads = threads;
                settings.isa = isa;
                const RenderResult st = render_stream(s, bvh, settings);
                INFO("scene " << s.name << " back end " << isa_name(isa) << " tile " << tile
                              << " threads " << threads << ": "
                              << differing_pixels(ref.image, st.image) << " pixels differ");
                CHECK(same_bits(ref.image, st.image));
                CHECK(st.stats.camera_rays == ref.stats.camera_rays);
                CHECK(st.stats.extension_rays == ref.stats.extension_rays);
                CHECK(st.stats.shadow_rays == ref.stats.shadow_rays);
                CHECK(st.stats.nonfinite_paths == ref.stats.nonfinite_paths);
            }
}

}  // namespace

TEST_CASE(
    "Stream image equals the reference image bit for bit (every back end, tiles 1-64, "
    "threads 1-2)",
    "[stream]") {
    SECTION("area lights, three materials, thin lens") {
        check_identical(box_scene(Variant::lights), small(box_scene(Variant::lights), 32, 28, 3));
    }
    SECTION("ambient term") {
        const Scene s = box_scene(Variant::ambient);
        check_identical(s, small(s, 20, 20, 2));
    }
    SECTION("environment only, no lights") {
        const Scene s = box_scene(Variant::environment_only);
        check_identical(s, small(s, 20, 24, 2));
    }
    SECTION("emissive sphere light, deep paths") {
        Scene s = box_scene(Variant::emissive_sphere);
        RenderSettings r = small(s, 16, 16, 2);
        r.max_depth = 8;
        check_identical(s, r);
    }
}

TEST_CASE("The stream image changes with the seed (the comparison can fail)", "[stream]") {
    const Scene s = box_scene(Variant::lights);
    const Bvh bvh(s);
    RenderSettings r = small(s, 16, 16, 1);
    const RenderResult a = render_stream(s, bvh, r);
    r.seed = 7;
    CHECK_FALSE(same_bits(a.image, render_stream(s, bvh, r).image));
}

TEST_CASE("A workload's other frame is the same workload with other random numbers", "[stream]") {
    const Scene s = box_scene(Variant::lights);
    const Bvh bvh(s);
    RenderSettings r = small(s, 16, 16, 1);
    r.tile = 8;
    r.stage_clock = true;
    const RenderSettings other = other_frame(r, 2);
    CHECK(other.seed == r.seed + 2);
    CHECK((other.width == r.width && other.height == r.height && other.spp == r.spp &&
           other.max_depth == r.max_depth && other.tile == r.tile && other.isa == r.isa &&
           other.threads == r.threads && other.stage_clock && !other.part_clock));
    const RenderResult a = render_stream(s, bvh, r);
    CHECK(same_bits(a.image, render_stream(s, bvh, other_frame(r, 0)).image));
    CHECK_FALSE(same_bits(a.image, render_stream(s, bvh, other).image));
}

TEST_CASE("A render never sees what the ray buffers held in the render before", "[stream]") {
    // The buffers are kept from render to render (RayBufferPool): a render on one thread takes
    // the set the render before it left, here another scene's deeper paths in a bigger tile.
    const Scene s = box_scene(Variant::lights);
    const Bvh bvh(s);
    RenderSettings r = small(s, 16, 16, 1);
    r.threads = 1;
    for (const Isa isa : supported_isas()) {
        r.isa = isa;
        const RenderResult first = render_stream(s, bvh, r);
        const Scene other = box_scene(Variant::emissive_sphere);
        RenderSettings deeper = small(other, 40, 40, 2);
        deeper.max_depth = 8;
        deeper.tile = 64;
        deeper.threads = 1;
        deeper.isa = isa;
        render_stream(other, Bvh(other), deeper);
        CHECK(same_bits(first.image, render_stream(s, bvh, r).image));
    }
}

TEST_CASE("Stream per-ray hit records equal the reference traversal's", "[stream]") {
    for (Variant v : {Variant::lights, Variant::environment_only}) {
        const Scene s = box_scene(v);
        const Bvh bvh(s);
        RenderSettings r = small(s, 32, 32, 2);
        StreamTracer tracer(s, bvh, r);
        HitChecker checker(bvh, 3);
        RenderStats stats;
        std::vector<Vec3> sums(32 * 32);
        for (uint32_t smp = 0; smp < 2; ++smp)
            tracer.trace_pass({0, 0, 32, 32}, 0, smp, sums.data(), stats, nullptr, &checker);
        CHECK(checker.checked > 500);
        CHECK(checker.mismatches == 0);
    }
    // And on a stream of arbitrary rays (including invalid ones).
    const Scene s = box_scene(Variant::lights);
    const Bvh bvh(s);
    std::vector<Ray> rays;
    for (uint32_t i = 0; i < 5000; ++i) {
        Ray ray;
        ray.org = {random_float(1, i, 0, 0, RngDim::pixel_x) * 3.f - 1.5f,
                   random_float(1, i, 0, 0, RngDim::pixel_y) * 3.f - 1.5f,
                   random_float(1, i, 0, 0, RngDim::lens_u) * 3.f - 1.5f};
        ray.dir = to_world(sample_cosine_hemisphere(random_float(1, i, 0, 0, RngDim::lens_v),
                                                    random_float(1, i, 0, 0, RngDim::light_u)),
                           normalize(Vec3(0.3f, -1.f, float(i % 5) - 2.f)));
        if (i % 1000 == 999) ray.dir = Vec3(0.f);
        rays.push_back(ray);
    }
    std::vector<Hit> hits;
    stream_intersect(bvh, rays, hits);
    uint64_t valid = 0, mismatches = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        valid += hits[i].valid();
        mismatches += !same_hit(hits[i], bvh.intersect(rays[i]));
    }
    CHECK(valid > 1000);
    CHECK(mismatches == 0);
}
