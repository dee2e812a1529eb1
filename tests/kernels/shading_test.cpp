// Hard cases 14, 15, 17, 18: Fresnel and refraction, sampling against its density (chi-square),
// the thin lens, and area-light densities.

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "kernels/camera.h"
#include "kernels/lights.h"
#include "kernels/materials.h"
#include "kernels/rng.h"
#include "kernels/sampling.h"

using namespace sfx;

TEST_CASE("Fresnel: 0.04 at normal incidence, 1 at grazing and under TIR, 0 for eta 1",
          "[shading]") {
    CHECK(fresnel_dielectric(1.f, 1.5f) == Approx(0.04f).epsilon(1e-5));
    CHECK(fresnel_dielectric(0.f, 1.5f) == Approx(1.f).epsilon(1e-6));
    // Inside glass (eta = 1/1.5) beyond the critical angle asin(1/1.5) ~ 41.8 degrees.
    CHECK(fresnel_dielectric(std::cos(60.f * k_pi / 180.f), 1.f / 1.5f) == 1.f);
    for (float c : {0.05f, 0.3f, 0.7f, 1.f}) CHECK(fresnel_dielectric(c, 1.f) == 0.f);
    // Monotone towards grazing.
    CHECK(fresnel_dielectric(0.2f, 1.5f) > fresnel_dielectric(0.8f, 1.5f));
}

TEST_CASE("Refraction is reversible and obeys Snell's law", "[shading]") {
    const Vec3 n{0.f, 0.f, 1.f};
    for (float deg : {0.f, 10.f, 35.f, 60.f, 85.f}) {
        const float a = deg * k_pi / 180.f;
        const Vec3 wo{std::sin(a), 0.f, std::cos(a)};
        Vec3 wt;
        REQUIRE(refract(wo, n, 1.5f, wt));
        CHECK(length(wt) == Approx(1.f).epsilon(1e-5));
        CHECK(std::sqrt(wt.x * wt.x + wt.y * wt.y) * 1.5f == Approx(std::sin(a)).margin(1e-5));
        Vec3 back;
        REQUIRE(refract(wt, -n, 1.f / 1.5f, back));  // wt points away on the glass side
        CHECK(back.x == Approx(wo.x).margin(1e-5));
        CHECK(back.y == Approx(wo.y).margin(1e-5));
        CHECK(back.z == Approx(wo.z).margin(1e-5));
    }
    Vec3 unused;
    CHECK_FALSE(refract(Vec3{std::sin(1.2f), 0.f, std::cos(1.2f)}, n, 1.f / 1.5f, unused));
}

namespace {

// Chi-square test of a direction sampler against its density over (cos theta, phi) bins of the
// upper hemisphere, plus one bin for samples below it. Bins with small expectation are pooled.
template <class Sample, class Pdf>
void chi_square_directions(Sample&& sample, Pdf&& pdf, int samples) {
    constexpr int k_theta = 10, k_phi = 20, k_sub = 12;
    std::vector<double> observed(k_theta * k_phi + 1, 0.0), expected(k_theta * k_phi + 1, 0.0);
    for (int i = 0; i < samples; ++i) {
        const Vec3 w = sample(uint32_t(i));
        if (!(w.z > 0.f)) { observed.back() += 1; continue; }
        float phi = std::atan2(w.y, w.x);
        if (phi < 0.f) phi += 2.f * k_pi;
        const int bt = std::min(k_theta - 1, int(w.z * k_theta));
        const int bp = std::min(k_phi - 1, int(phi / (2.f * k_pi) * k_phi));
        observed[bt * k_phi + bp] += 1;
    }
    double total = 0.0;
    for (int bt = 0; bt < k_theta; ++bt)
        for (int bp = 0; bp < k_phi; ++bp) {
            double integral = 0.0;
            const double dc = 1.0 / (k_theta * k_sub), dp = 2.0 * M_PI / (k_phi * k_sub);
            for (int i = 0; i < k_sub; ++i)
                for (int j = 0; j < k_sub; ++j) {
                    const double c = (bt * k_sub + i + 0.5) * dc;
                    const double p = (bp * k_sub + j + 0.5) * dp;
                    const double s = std::sqrt(1.0 - c * c);
                    integral += pdf(Vec3{float(s * std::cos(p)), float(s * std::sin(p)), float(c)}) *
                                dc * dp;
                }
            expected[bt * k_phi + bp] = integral * samples;
            total += integral;
        }
    expected.back() = std::max(0.0, 1.0 - total) * samples;
    double chi2 = 0.0, pooled_obs = 0.0, pooled_exp = 0.0;
    int dof = -1;
    for (size_t b = 0; b < observed.size(); ++b) {
        if (expected[b] < 5.0) {
            pooled_obs += observed[b];
            pooled_exp += expected[b];
            continue;
        }
        chi2 += (observed[b] - expected[b]) * (observed[b] - expected[b]) / expected[b];
        ++dof;
    }
    if (pooled_exp >= 5.0) {
        chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
        ++dof;
    } else {
        CHECK(pooled_obs <= 5.0 + 5.0 * pooled_exp);  // nothing where the density says nothing
    }
    // Wilson-Hilferty approximation of the chi-square quantile at significance 1e-4.
    const double k = dof, z = 3.719;
    const double critical = k * std::pow(1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k)), 3.0);
    INFO("chi2 = " << chi2 << " dof = " << dof << " critical = " << critical);
    CHECK(chi2 < critical);
}

}  // namespace

TEST_CASE("Lambertian cosine sampling passes a chi-square test", "[shading]") {
    chi_square_directions(
        [](uint32_t i) {
            return sample_cosine_hemisphere(random_float(1, i, 0, 0, RngDim::direction_u),
                                            random_float(1, i, 0, 0, RngDim::direction_v));
        },
        [](const Vec3& w) { return double(cosine_hemisphere_pdf(w.z)); }, 200000);
}

TEST_CASE("Glossy sampling passes a chi-square test, also at grazing incidence", "[shading]") {
    const Vec3 n{0.f, 0.f, 1.f};
    for (float cos_o : {0.9f, 0.5f, 0.05f}) {
        for (float exponent : {8.f, 40.f}) {
            const Vec3 wo = normalize(Vec3{std::sqrt(1.f - cos_o * cos_o), 0.3f, cos_o});
            INFO("cos_o " << cos_o << " exponent " << exponent);
            chi_square_directions(
                [&](uint32_t i) {
                    return glossy_sample(exponent, n, wo, random_float(2, i, 0, 0, RngDim::lobe_choice),
                                         random_float(2, i, 0, 0, RngDim::direction_u),
                                         random_float(2, i, 0, 0, RngDim::direction_v));
                },
                [&](const Vec3& wi) { return double(glossy_pdf(exponent, n, wo, wi)); }, 200000);
        }
    }
}

TEST_CASE("Thin lens: zero aperture equals the pinhole, lens rays meet on the focal plane",
          "[shading]") {
    ThinLensCamera cam;
    cam.eye = {1.f, 2.f, 3.f};
    cam.look_at = {0.f, 0.5f, -4.f};
    cam.vertical_fov_degrees = 50.f;
    cam.aperture_radius = 0.f;
    cam.focal_distance = 6.f;
    const CameraFrame pinhole(cam, 64, 48);
    for (uint32_t i = 0; i < 100; ++i) {
        const float fx = 64.f * random_float(3, i, 0, 0, RngDim::pixel_x);
        const float fy = 48.f * random_float(3, i, 0, 0, RngDim::pixel_y);
        const Ray r = pinhole.ray_through(fx, fy, 0.3f, 0.7f);
        CHECK(r.org == cam.eye);
        CHECK(r.dir == pinhole.pinhole_direction(fx, fy));
    }
    cam.aperture_radius = 0.25f;
    const CameraFrame lens(cam, 64, 48);
    for (uint32_t i = 0; i < 20; ++i) {
        const float fx = 64.f * random_float(4, i, 0, 0, RngDim::pixel_x);
        const float fy = 48.f * random_float(4, i, 0, 0, RngDim::pixel_y);
        const Ray centre = pinhole.ray_through(fx, fy, 0.5f, 0.5f);
        const Vec3 focus = centre.org + centre.dir * (cam.focal_distance / dot(centre.dir, lens.forward()));
        for (uint32_t j = 0; j < 16; ++j) {
            const Ray r = lens.ray_through(fx, fy, random_float(5, i, j, 0, RngDim::lens_u),
                                           random_float(5, i, j, 0, RngDim::lens_v));
            CHECK(length(r.org - cam.eye) <= cam.aperture_radius * 1.0001f);
            // Where this ray crosses the focal plane.
            const float t = (cam.focal_distance - dot(r.org - cam.eye, lens.forward())) /
                            dot(r.dir, lens.forward());
            const Vec3 p = r.org + r.dir * t;
            CHECK(length(p - focus) < 1e-4f * cam.focal_distance);
        }
    }
}

TEST_CASE("Area light sampling: the sampling pdf equals the evaluated pdf", "[shading]") {
    Scene scene;
    scene.materials.push_back({});
    Material lamp;
    lamp.diffuse = Vec3(0.f);
    lamp.emission = Vec3(4.f);
    scene.materials.push_back(lamp);
    // Light 0: a quad of two triangles (area 2 x 1 = 2); light 1: a sphere of radius 0.5.
    scene.positions = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};
    scene.triangles = {{0, 1, 2, 1}, {0, 2, 3, 1}};
    scene.spheres = {{{5.f, 0.f, 0.f}, 0.5f, 1}};
    scene.finalize({0, 0, 1});
    REQUIRE(scene.lights.size() == 2);
    CHECK(scene.lights[0].area == Approx(2.f));
    CHECK(scene.lights[1].area == Approx(k_pi));
    const int n = 100000;
    double inverse_pdf_sum = 0.0;
    std::vector<int> per_prim(3, 0);
    for (uint32_t i = 0; i < uint32_t(n); ++i) {
        const LightSample s = sample_light(scene, random_float(6, i, 0, 0, RngDim::light_choice),
                                           random_float(6, i, 0, 0, RngDim::light_w),
                                           random_float(6, i, 0, 0, RngDim::light_u),
                                           random_float(6, i, 0, 0, RngDim::light_v));
        REQUIRE(s.pdf_area == light_pdf_area(scene, s.light));
        ++per_prim[s.prim];
        inverse_pdf_sum += 1.0 / s.pdf_area;
        if (s.prim == 2) {
            CHECK(length(s.position - scene.spheres[0].center) == Approx(0.5f).epsilon(1e-5));
        } else {
            CHECK(s.position.z == 0.f);
            CHECK(s.position.x >= 0.f);
            CHECK(s.position.x <= 2.f);
        }
    }
    // E[1/pdf] is the total emitting area; each primitive gets its share of its light.
    CHECK(inverse_pdf_sum / n == Approx(2.0 + M_PI).epsilon(0.01));
    CHECK(per_prim[0] / double(n) == Approx(0.25).margin(0.01));
    CHECK(per_prim[1] / double(n) == Approx(0.25).margin(0.01));
    CHECK(per_prim[2] / double(n) == Approx(0.5).margin(0.01));
}

TEST_CASE("Random numbers: a path's key draws the hash of (seed, pixel, sample, bounce, dim)",
          "[shading]") {
    // The definition, hashed in three rounds as rng.h states it; PathKey keeps the first two.
    auto spec = [](uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce, uint32_t dim) {
        uint64_t h = mix64(seed ^ 0x9e3779b97f4a7c15ull);
        h = mix64(h ^ ((uint64_t(pixel) << 32) | sample));
        h = mix64(h ^ ((uint64_t(bounce) << 32) | dim));
        return float(uint32_t(h >> 32) >> 8) * (1.0f / 16777216.0f);
    };
    for (const uint64_t seed : {0ull, 1ull, 0xfedcba9876543210ull})
        for (const uint32_t pixel : {0u, 7u, 65535u})
            for (const uint32_t sample : {0u, 3u})
                for (uint32_t bounce = 0; bounce < 3; ++bounce)
                    for (uint32_t d = 0; d < uint32_t(RngDim::count); ++d) {
                        const float u = PathKey(seed, pixel, sample).uniform(bounce, RngDim(d));
                        CHECK(u == spec(seed, pixel, sample, bounce, d));
                        CHECK(u == random_float(seed, pixel, sample, bounce, RngDim(d)));
                    }
    CHECK(PathKey().uniform(2, RngDim::light_u) == spec(0, 0, 0, 2, uint32_t(RngDim::light_u)));
}
