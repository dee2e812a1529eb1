#include "kernels/embree/embree_check.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <cstring>
#include <iomanip>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "kernels/camera.h"
#include "kernels/intersect.h"
#include "kernels/render.h"
#include "kernels/sampling.h"
#include "base/host_clock.h"

namespace sfx {

namespace {

bool in_range(float x) {
    return std::fabs(x) <= EmbreeScene::k_coordinate_limit;
}
bool in_range(const Vec3& p) {
    return in_range(p.x) && in_range(p.y) && in_range(p.z);
}

void record_error(void* user, RTCError code, const char* message) {
    auto* text = static_cast<std::string*>(user);
    if (text->empty())
        *text = "embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

}  // namespace

// EmbreeScene Method Definitions

EmbreeScene::EmbreeScene(const Scene& scene) {
    const auto start = HostClock::now();
    // One build thread: Embree's tree, and so which of two equal-t primitives it reports, must
    // not depend on the machine or on --threads. Queries run on the caller's threads anyway.
    m_device = rtcNewDevice("threads=1");
    if (!m_device) throw std::runtime_error("embree: rtcNewDevice failed");
    rtcSetDeviceErrorFunction(m_device, record_error, &m_error);
    m_scene = rtcNewScene(m_device);
    // Robust: no accuracy-reducing shortcuts in traversal (the default leaks ~10% of rays on
    // meshes far from the origin). High quality: spatial splits, the best tree Embree builds.
    rtcSetSceneFlags(m_scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(m_scene, RTC_BUILD_QUALITY_HIGH);

    const uint32_t vertex_count = uint32_t(scene.positions.size());
    std::vector<uint32_t> triangle_ids;
    for (uint32_t i = 0; i < scene.triangle_count(); ++i) {
        const Triangle& t = scene.triangles[i];
        const bool ok = t.v0 < vertex_count && t.v1 < vertex_count && t.v2 < vertex_count &&
                        in_range(scene.positions[t.v0]) && in_range(scene.positions[t.v1]) &&
                        in_range(scene.positions[t.v2]);
        if (ok)
            triangle_ids.push_back(i);
        else
            ++m_excluded;
    }
    if (!triangle_ids.empty()) {
        RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertex_count));
        for (uint32_t i = 0; i < vertex_count; ++i) {
            // Out-of-range vertices belong only to excluded triangles; zero them so no
            // out-of-range number ever enters Embree.
            const Vec3 p = in_range(scene.positions[i]) ? scene.positions[i] : Vec3(0.f);
            v[3 * i] = p.x;
            v[3 * i + 1] = p.y;
            v[3 * i + 2] = p.z;
        }
        auto* idx = static_cast<uint32_t*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(uint32_t), triangle_ids.size()));
        for (size_t k = 0; k < triangle_ids.size(); ++k) {
            const Triangle& t = scene.triangles[triangle_ids[k]];
            idx[3 * k] = t.v0;
            idx[3 * k + 1] = t.v1;
            idx[3 * k + 2] = t.v2;
        }
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
        rtcCommitGeometry(g);
        m_triangle_geometry = rtcAttachGeometry(m_scene, g);
        rtcReleaseGeometry(g);
    }
    m_triangle_ids = std::move(triangle_ids);

    std::vector<uint32_t> sphere_ids;
    for (uint32_t i = 0; i < uint32_t(scene.spheres.size()); ++i) {
        const Sphere& s = scene.spheres[i];
        const bool ok = in_range(s.center) && std::isfinite(s.radius) && s.radius > 0.f &&
                        in_range(s.radius) && in_range(s.center + Vec3(s.radius)) &&
                        in_range(s.center - Vec3(s.radius));
        if (ok)
            sphere_ids.push_back(scene.triangle_count() + i);
        else
            ++m_excluded;
    }
    if (!sphere_ids.empty()) {
        RTCGeometry g = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), sphere_ids.size()));
        for (size_t k = 0; k < sphere_ids.size(); ++k) {
            const Sphere& s = scene.sphere(sphere_ids[k]);
            v[4 * k] = s.center.x;
            v[4 * k + 1] = s.center.y;
            v[4 * k + 2] = s.center.z;
            v[4 * k + 3] = s.radius;
        }
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
        rtcCommitGeometry(g);
        m_sphere_geometry = rtcAttachGeometry(m_scene, g);
        rtcReleaseGeometry(g);
    }
    m_sphere_ids = std::move(sphere_ids);

    rtcCommitScene(m_scene);
    if (!m_error.empty()) {
        const std::string what = m_error;
        rtcReleaseScene(m_scene);
        rtcReleaseDevice(m_device);
        throw std::runtime_error(what);
    }
    m_build_seconds = seconds_since(start);
}

EmbreeScene::~EmbreeScene() {
    rtcReleaseScene(m_scene);
    rtcReleaseDevice(m_device);
}

bool EmbreeScene::accepts(const Ray& ray) {
    if (!ray_is_valid(ray) || !in_range(ray.org) || !in_range(ray.dir)) return false;
    // t_max may be +inf (Embree's own "no limit"); a finite one must be in range too.
    return ray.t_max == INFINITY || in_range(ray.t_max);
}

Hit EmbreeScene::intersect(const Ray& ray) const {
    Hit hit;
    if (!accepts(ray)) return hit;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = ray.org.x;
    rh.ray.org_y = ray.org.y;
    rh.ray.org_z = ray.org.z;
    rh.ray.tnear = 0.f;  // sfx rays cover (0, t_max]; origins are already offset
    rh.ray.dir_x = ray.dir.x;
    rh.ray.dir_y = ray.dir.y;
    rh.ray.dir_z = ray.dir.z;
    rh.ray.time = 0.f;
    rh.ray.tfar = ray.t_max;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    for (unsigned& id : rh.hit.instID) id = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m_scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
    hit.t = rh.ray.tfar;
    if (rh.hit.geomID == m_triangle_geometry) {
        hit.prim = m_triangle_ids.at(rh.hit.primID);
        hit.u = rh.hit.u;
        hit.v = rh.hit.v;
    } else {
        hit.prim = m_sphere_ids.at(rh.hit.primID);  // u, v stay 0 as in sfx
    }
    return hit;
}

// Classification

const char* to_string(HitClass c) {
    switch (c) {
        case HitClass::both_miss:
            return "both_miss";
        case HitClass::agree:
            return "agree";
        case HitClass::tie:
            return "tie";
        case HitClass::edge:
            return "edge";
        case HitClass::same_prim_apart:
            return "same_prim_apart";
        case HitClass::hit_miss:
            return "hit_miss";
        case HitClass::disagree:
            return "disagree";
        case HitClass::count:
            break;
    }
    return "?";
}

const char* to_string(CheckRayKind k) {
    return k == CheckRayKind::primary ? "primary" : k == CheckRayKind::diffuse ? "diffuse" : "?";
}

namespace {

// Distance in representable floats; +0 and -0 are the same point.
int64_t ulp_distance(float a, float b) {
    auto ordered = [](float f) {
        const int64_t i = int32_t(float_bits(f));
        return i < 0 ? int64_t(INT32_MIN) - i : i;
    };
    const int64_t d = ordered(a) - ordered(b);
    return d < 0 ? -d : d;
}

// How far two correct float answers for one ray may lie apart.
struct Slack {
    double condition = 1.0;  // 1/|cos| of the hit angle (hit_condition), the worse of the two
    double t_abs = 0.0;      // absolute t slack: rounding of the coordinates involved
    double bary_abs = 0.0;   // absolute barycentric slack: the same, over the triangle's size
};

bool close_distance(float a, float b, const HitTolerance& tol, const Slack& slack) {
    if (a == b) return true;
    if (!std::isfinite(a) || !std::isfinite(b)) return false;
    const double d = std::fabs(double(a) - double(b));
    return d <= tol.relative * slack.condition * std::max(std::fabs(a), std::fabs(b)) ||
           d <= slack.t_abs || ulp_distance(a, b) <= int64_t(tol.ulps);
}

// Barycentrics live in [0, 1]: "relative" is relative to that range.
bool close_barycentric(float a, float b, const HitTolerance& tol, const Slack& slack) {
    const double d = std::fabs(double(a) - double(b));
    return a == b || d <= tol.relative * slack.condition || d <= slack.bary_abs ||
           ulp_distance(a, b) <= int64_t(tol.ulps);
}

double max_abs(const Vec3& p) {
    return std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z)));
}

// The ray passes within rounding distance of the sphere's silhouette, where hit and miss are
// both right. The slack grows with the distance to the center: that is the size of the
// rounding error of any float closest-approach computation.
bool grazes_sphere(const Sphere& s, const Ray& ray, const HitTolerance& tol) {
    const double fx = double(s.center.x) - ray.org.x, fy = double(s.center.y) - ray.org.y,
                 fz = double(s.center.z) - ray.org.z;
    const double dx = ray.dir.x, dy = ray.dir.y, dz = ray.dir.z;
    const double proj = (fx * dx + fy * dy + fz * dz) / (dx * dx + dy * dy + dz * dz);
    const double px = fx - dx * proj, py = fy - dy * proj, pz = fz - dz * proj;
    const double miss_distance = std::sqrt(px * px + py * py + pz * pz);
    const double to_center = std::sqrt(fx * fx + fy * fy + fz * fz);
    const double slack = double(tol.edge) * s.radius + 8.0 * double(FLT_EPSILON) * to_center;
    return std::fabs(miss_distance - double(s.radius)) <= slack;
}

// Condition number of a ray/surface intersection: 1/|cos| of the angle between the ray and the
// surface normal. At grazing incidence a rounding of the ray moves t, u and v by that factor
// more, in any correct float implementation (sfx's and Embree's both stray from a double
// reference by ~1e-4 in u at cos = 0.003), so the tolerances grow with it.
double hit_condition(const Scene& scene, const Ray& ray, const Hit& hit) {
    if (!hit.valid()) return 1.0;
    Vec3 n;
    if (scene.is_sphere(hit.prim)) {
        n = ray.org + ray.dir * hit.t - scene.sphere(hit.prim).center;
    } else {
        const Triangle& t = scene.triangles[hit.prim];
        const Vec3& p0 = scene.positions[t.v0];
        n = cross(scene.positions[t.v1] - p0, scene.positions[t.v2] - p0);
    }
    const double nn = double(dot(n, n)), dd = double(dot(ray.dir, ray.dir));
    const double c = std::fabs(double(dot(n, ray.dir))) / std::sqrt(nn * dd);
    if (!(c > 0.0)) return 1e30;  // parallel or degenerate: any answer is as good
    return std::max(1.0, 1.0 / c);
}

// Every float tracer rounds positions to ulps of the largest coordinate in play (the origin's
// or the primitive's), whatever t is: a diffuse ray leaving a corner hits the next wall at
// t ~ 1e-4 with t differing by 4e-5 relative, ~0.05 ulp of the coordinates. So t, u, v and
// the edge test also get an absolute slack of `ulps` such ulps, scaled by the hit's condition;
// for barycentrics it is divided by the triangle's smallest altitude.
struct HitError {
    double condition = 1.0;
    double position = 0.0;       // absolute position slack at this hit
    double altitude = INFINITY;  // triangle's smallest altitude; infinite for spheres and misses
};

HitError hit_error(const Scene& scene, const Ray& ray, const Hit& hit, const HitTolerance& tol) {
    HitError e;
    double coordinate = max_abs(ray.org);
    if (hit.valid()) {
        e.condition = hit_condition(scene, ray, hit);
        const Bounds3 bounds = scene.primitive_bounds(hit.prim);
        coordinate = std::max(coordinate, std::max(max_abs(bounds.lo), max_abs(bounds.hi)));
        if (!scene.is_sphere(hit.prim)) {
            const Triangle& t = scene.triangles[hit.prim];
            const Vec3& p0 = scene.positions[t.v0];
            const Vec3& p1 = scene.positions[t.v1];
            const Vec3& p2 = scene.positions[t.v2];
            const double twice_area = double(length(cross(p1 - p0, p2 - p0)));
            const double longest =
                std::max(double(length(p1 - p0)),
                         std::max(double(length(p2 - p1)), double(length(p0 - p2))));
            e.altitude = longest > 0.0 ? twice_area / longest : 0.0;
        }
    }
    e.position = double(tol.ulps) * coordinate * double(FLT_EPSILON) * e.condition;
    return e;
}

Slack make_slack(const Ray& ray, const HitError& a, const HitError& b) {
    Slack s;
    s.condition = std::max(a.condition, b.condition);
    const double position = std::max(a.position, b.position);
    s.t_abs = position / double(length(ray.dir));
    const double altitude = std::min(a.altitude, b.altitude);
    s.bary_abs = altitude > 0.0 ? position / altitude : INFINITY;
    return s;
}

bool near_edge(const Scene& scene, const Ray& ray, const Hit& hit, const HitError& e,
               const HitTolerance& tol) {
    if (!hit.valid()) return false;
    if (scene.is_sphere(hit.prim)) return grazes_sphere(scene.sphere(hit.prim), ray, tol);
    const float w = 1.f - hit.u - hit.v;
    const double slack = std::max(double(tol.edge) * e.condition,
                                  e.altitude > 0.0 ? e.position / e.altitude : INFINITY);
    return double(std::min(hit.u, std::min(hit.v, w))) <= slack;
}

}  // namespace

HitClass classify_hits(const Scene& scene, const Ray& ray, const Hit& a, const Hit& b,
                       const HitTolerance& tol) {
    if (!a.valid() && !b.valid()) return HitClass::both_miss;
    const HitError error_a = hit_error(scene, ray, a, tol), error_b = hit_error(scene, ray, b, tol);
    const Slack slack = make_slack(ray, error_a, error_b);
    if (a.valid() && b.valid() && a.prim == b.prim) {
        const bool close = close_distance(a.t, b.t, tol, slack) &&
                           close_barycentric(a.u, b.u, tol, slack) &&
                           close_barycentric(a.v, b.v, tol, slack);
        return close ? HitClass::agree : HitClass::same_prim_apart;
    }
    if (a.valid() && b.valid() && close_distance(a.t, b.t, tol, slack)) return HitClass::tie;
    // A hit within rounding distance of the origin: the origin lies on a surface (a ray
    // leaving a corner, offset off one wall but still on the other), where hitting at t ~ 0
    // and passing are both right.
    auto at_origin = [&](const Hit& h) { return h.valid() && double(h.t) <= slack.t_abs; };
    if (near_edge(scene, ray, a, error_a, tol) || near_edge(scene, ray, b, error_b, tol) ||
        at_origin(a) || at_origin(b))
        return HitClass::edge;
    return a.valid() && b.valid() ? HitClass::disagree : HitClass::hit_miss;
}

std::string describe(const HitMismatch& m) {
    std::ostringstream o;
    o << std::setprecision(9) << to_string(m.kind) << " #" << m.index << " " << to_string(m.cls)
      << ": org (" << m.ray.org.x << ", " << m.ray.org.y << ", " << m.ray.org.z << ") dir ("
      << m.ray.dir.x << ", " << m.ray.dir.y << ", " << m.ray.dir.z << ")";
    for (const Hit* h : {&m.sfx_hit, &m.embree_hit}) {
        o << (h == &m.sfx_hit ? "; sfx " : "; embree ");
        if (h->valid())
            o << "prim " << h->prim << " t " << h->t << " u " << h->u << " v " << h->v;
        else
            o << "miss";
    }
    return o.str();
}

// Counts

uint64_t ClassCounts::traced() const {
    uint64_t n = 0;
    for (uint64_t c : by_class) n += c;
    return n;
}

uint64_t ClassCounts::explained() const {
    uint64_t n = 0;
    for (size_t c = 0; c < k_hit_class_count; ++c)
        if (is_explained(HitClass(c))) n += by_class[c];
    return n;
}

ClassCounts& ClassCounts::operator+=(const ClassCounts& o) {
    for (size_t c = 0; c < k_hit_class_count; ++c) by_class[c] += o.by_class[c];
    filtered += o.filtered;
    return *this;
}

ClassCounts EmbreeAgreement::total() const {
    ClassCounts t;
    for (const ClassCounts& k : by_kind) t += k;
    return t;
}

double EmbreeAgreement::unexplained_rate() const {
    const ClassCounts t = total();
    return t.traced() ? double(t.unexplained()) / double(t.traced()) : 0.0;
}

bool EmbreeAgreement::pass() const {
    return total().traced() > 0 && unexplained_rate() <= max_unexplained_rate;
}

// The check

std::vector<Hit> compare_rays(const Scene& scene, const Bvh& bvh, const EmbreeScene& embree,
                              const std::vector<Ray>& rays, CheckRayKind kind,
                              const EmbreeCheckOptions& options, ClassCounts& counts,
                              std::vector<HitMismatch>& examples) {
    // Fixed chunks, merged in chunk order: the counts and the examples kept never depend on
    // the thread count.
    constexpr uint64_t k_chunk = 2048;
    const uint64_t n = rays.size();
    const uint32_t chunks = uint32_t((n + k_chunk - 1) / k_chunk);
    std::vector<Hit> sfx_hits(n);
    std::vector<ClassCounts> chunk_counts(chunks);
    std::vector<std::vector<HitMismatch>> chunk_examples(chunks);
    parallel_for(chunks, options.threads, [&](uint32_t c) {
        ClassCounts& cc = chunk_counts[c];
        const uint64_t end = std::min(n, (c + 1) * k_chunk);
        for (uint64_t i = c * k_chunk; i < end; ++i) {
            const Ray& ray = rays[i];
            if (!EmbreeScene::accepts(ray)) {
                ++cc.filtered;
                continue;  // sfx_hits[i] stays a miss: nothing is spawned from it
            }
            const Hit mine = bvh.intersect(ray);
            const Hit theirs = embree.intersect(ray);
            sfx_hits[i] = mine;
            const HitClass cls = classify_hits(scene, ray, mine, theirs, options.tolerance);
            ++cc.by_class[size_t(cls)];
            if (!is_explained(cls) && chunk_examples[c].size() < options.max_examples)
                chunk_examples[c].push_back({kind, i, cls, ray, mine, theirs});
        }
    });
    for (uint32_t c = 0; c < chunks; ++c) {
        counts += chunk_counts[c];
        for (const HitMismatch& m : chunk_examples[c])
            if (examples.size() < options.max_examples) examples.push_back(m);
    }
    return sfx_hits;
}

EmbreeAgreement check_against_embree(const Scene& scene, const Bvh& bvh,
                                     const EmbreeCheckOptions& options) {
    if (options.width == 0 || options.height == 0)
        throw std::invalid_argument("embree check: resolution must be positive");
    EmbreeAgreement result;
    result.max_unexplained_rate = options.max_unexplained_rate;

    std::unique_ptr<EmbreeScene> embree;
    if (options.embree_scene_edit) {
        Scene edited = scene;
        options.embree_scene_edit(edited);
        embree = std::make_unique<EmbreeScene>(edited);
    } else {
        embree = std::make_unique<EmbreeScene>(scene);
    }
    result.excluded_primitives = embree->excluded_primitives();
    result.embree_build_seconds = embree->build_seconds();

    const auto start = HostClock::now();
    const uint64_t n_diffuse = options.rays / 2;
    const uint64_t n_primary = options.rays - n_diffuse;
    const uint64_t pixels = uint64_t(options.width) * options.height;
    const CameraFrame camera(scene.camera, options.width, options.height);
    auto key_of = [&](uint64_t i) {
        return PathKey{options.seed, uint32_t(i % pixels), uint32_t(i / pixels)};
    };

    // Primary rays: pixel-major, so the first width*height rays cover the image once.
    std::vector<Ray> primary(n_primary);
    for (uint64_t i = 0; i < n_primary; ++i) primary[i] = camera.generate(key_of(i));
    const std::vector<Hit> primary_hits =
        compare_rays(scene, bvh, *embree, primary, CheckRayKind::primary, options,
                     result.by_kind[size_t(CheckRayKind::primary)], result.examples);

    // Diffuse rays leave sfx's primary hit points, cosine-distributed about the normal facing
    // the camera ray, as a Lambertian bounce would. Sources are reused round-robin (with fresh
    // random numbers, bounce 1, 2, ...) so there are exactly n_diffuse of them.
    std::vector<uint64_t> sources;
    for (uint64_t i = 0; i < n_primary; ++i)
        if (primary_hits[i].valid()) sources.push_back(i);
    result.diffuse_sources = sources.size();
    if (!sources.empty() && n_diffuse > 0) {
        std::vector<Ray> diffuse(n_diffuse);
        for (uint64_t j = 0; j < n_diffuse; ++j) {
            const uint64_t src = sources[j % sources.size()];
            const uint32_t bounce = uint32_t(1 + j / sources.size());
            const PathKey key = key_of(src);
            const SurfaceHit s = surface_at(scene, primary[src], primary_hits[src]);
            const Vec3 local = sample_cosine_hemisphere(key.uniform(bounce, RngDim::direction_u),
                                                        key.uniform(bounce, RngDim::direction_v));
            diffuse[j].org = offset_ray_origin(s.position, s.normal);
            diffuse[j].dir = to_world(local, s.normal);
        }
        compare_rays(scene, bvh, *embree, diffuse, CheckRayKind::diffuse, options,
                     result.by_kind[size_t(CheckRayKind::diffuse)], result.examples);
    }
    result.trace_seconds = seconds_since(start);
    return result;
}

}  // namespace sfx
