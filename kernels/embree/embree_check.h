#pragma once
// Cross-check of sfx's BVH against Embree 3: the same rays go through Bvh::intersect and
// rtcIntersect1, and every pair of hits is put into one class. Ties (equal t, different
// primitive) and edge hits (a hit within ~1e-5 of a triangle edge or a sphere silhouette) are
// explained: two correct tracers may differ there. Everything else is unexplained, and the
// check passes only if unexplained rays are at most 2e-5 of the rays traced.
//
// Embree 3.13 aborts the process on NaN/Inf rays and on coordinates beyond ~1.8e18, so every
// ray passes EmbreeScene::accepts() first; rejected rays are counted as filtered, never traced.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "kernels/bvh.h"
#include "kernels/ray.h"
#include "workloads/scene.h"

struct RTCDeviceTy;
struct RTCSceneTy;

namespace sfx {

// EmbreeScene Public Types
// One Embree scene mirroring an sfx Scene: geometry 0 holds the triangles, geometry 1 the
// spheres (as RTC_GEOMETRY_TYPE_SPHERE_POINT, so Embree's own sphere test is checked against
// sfx's rather than sfx's against itself). Built with RTC_SCENE_FLAG_ROBUST at high quality.
class EmbreeScene {
  public:
    // Largest coordinate magnitude handed to Embree; beyond ~1.8e18 Embree aborts.
    static constexpr float k_coordinate_limit = 1e18f;

    explicit EmbreeScene(const Scene& scene);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    // True if the ray is valid for sfx (ray_is_valid) and every number Embree derives from it
    // stays in range. Rays that fail this must never reach rtcIntersect1.
    static bool accepts(const Ray& ray);

    // Closest hit as an sfx Hit with the global primitive id (triangles, then spheres).
    // A ray that accepts() refuses returns a miss without calling Embree.
    Hit intersect(const Ray& ray) const;

    // Primitives left out of the Embree scene because their coordinates are out of range.
    uint32_t excluded_primitives() const { return m_excluded; }
    double build_seconds() const { return m_build_seconds; }

  private:
    RTCDeviceTy* m_device = nullptr;
    RTCSceneTy* m_scene = nullptr;
    uint32_t m_triangle_geometry = ~0u, m_sphere_geometry = ~0u;
    std::vector<uint32_t> m_triangle_ids;  // Embree primID -> sfx primitive id
    std::vector<uint32_t> m_sphere_ids;
    uint32_t m_excluded = 0;
    double m_build_seconds = 0.0;
    std::string m_error;  // first message from Embree's error callback
};

// Classification of one ray's pair of hits (sfx, Embree).
enum class HitClass : uint8_t {
    both_miss,        // explained
    agree,            // same primitive, t, u, v within tolerance; explained
    tie,              // different primitives at equal t (within tolerance); explained
    edge,             // a hit on an edge/vertex/sphere silhouette, or at the ray origin (the
                      // origin lies on a surface), where either answer is right; explained
    same_prim_apart,  // same primitive, but t, u or v beyond tolerance
    hit_miss,         // one hit, the other missed, away from any edge
    disagree,         // different primitives at different t, away from any edge
    count
};
constexpr size_t k_hit_class_count = size_t(HitClass::count);
const char* to_string(HitClass c);
inline bool is_explained(HitClass c) {
    return c <= HitClass::edge;
}

// Two hits agree if t, u, v are within `ulps` ulps (of t itself, and of the largest coordinate
// in play: positions round there whatever t is) or `relative` of each other. Both are scaled
// by 1/|cos| of the angle between ray and surface, the condition number of the intersection.
struct HitTolerance {
    float ulps = 16.f;
    float relative = 1e-5f;  // u, v: absolute, they live in [0, 1]
    float edge = 1e-5f;      // barycentric distance to an edge, relative distance to a silhouette
};

HitClass classify_hits(const Scene& scene, const Ray& ray, const Hit& sfx_hit,
                       const Hit& embree_hit, const HitTolerance& tolerance = {});

// Ray populations of the check.
enum class CheckRayKind : uint8_t { primary, diffuse, count };
const char* to_string(CheckRayKind k);

struct ClassCounts {
    std::array<uint64_t, k_hit_class_count> by_class{};
    uint64_t filtered = 0;  // refused by EmbreeScene::accepts: never traced by either side

    uint64_t traced() const;
    uint64_t explained() const;
    uint64_t unexplained() const { return traced() - explained(); }
    ClassCounts& operator+=(const ClassCounts& o);
};

// One unexplained ray, kept for the report.
struct HitMismatch {
    CheckRayKind kind = CheckRayKind::primary;
    uint64_t index = 0;  // ray index within its kind
    HitClass cls = HitClass::disagree;
    Ray ray;
    Hit sfx_hit, embree_hit;
};
// One line: kind, index, class, the ray and both hits, with enough digits to replay it.
std::string describe(const HitMismatch& m);

struct EmbreeCheckOptions {
    uint64_t rays = 1000000;  // total: the first half primary, the rest diffuse
    uint32_t width = 256, height = 256;
    uint64_t seed = 0;
    uint32_t threads = 0;  // 0: all cores; never changes a count
    HitTolerance tolerance;
    double max_unexplained_rate = 2e-5;
    uint32_t max_examples = 8;
    // Test hook: edits a copy of the scene that only Embree sees (to prove a wrong answer is
    // detected). Empty in normal use.
    std::function<void(Scene&)> embree_scene_edit;
};

struct EmbreeAgreement {
    std::array<ClassCounts, size_t(CheckRayKind::count)> by_kind;
    std::vector<HitMismatch> examples;  // the first unexplained rays, primary then diffuse
    uint64_t diffuse_sources = 0;       // primary hits the diffuse rays were spawned from
    uint32_t excluded_primitives = 0;
    double max_unexplained_rate = 2e-5;
    double embree_build_seconds = 0.0;
    double trace_seconds = 0.0;

    ClassCounts total() const;
    double unexplained_rate() const;  // over traced rays
    bool pass() const;                // something was traced and the rate is within bounds
};

// Classifies `rays` (all of one kind, numbered from `first_index`) into `counts`; returns
// per-ray sfx hits. Rays refused by EmbreeScene::accepts are counted as filtered.
std::vector<Hit> compare_rays(const Scene& scene, const Bvh& bvh, const EmbreeScene& embree,
                              const std::vector<Ray>& rays, CheckRayKind kind,
                              const EmbreeCheckOptions& options, ClassCounts& counts,
                              std::vector<HitMismatch>& examples);

EmbreeAgreement check_against_embree(const Scene& scene, const Bvh& bvh,
                                     const EmbreeCheckOptions& options = {});

}  // namespace sfx
