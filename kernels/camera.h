#pragma once
// Thin-lens camera. A zero aperture takes the pinhole path exactly (no lens arithmetic), so
// a pinhole and a zero-aperture lens give the same bits.

#include <cmath>

#include "kernels/ray.h"
#include "kernels/rng.h"
#include "kernels/sampling.h"
#include "workloads/scene.h"

namespace sfx {

class CameraFrame {
public:
    CameraFrame(const ThinLensCamera& c, uint32_t width, uint32_t height)
        : m_eye(c.eye), m_width(width), m_height(height), m_aperture(c.aperture_radius),
          m_focal_distance(c.focal_distance) {
        m_forward = normalize(c.look_at - c.eye);
        m_right = normalize(cross(m_forward, c.up));
        m_up = cross(m_right, m_forward);
        const float tan_half = std::tan(0.5f * c.vertical_fov_degrees * k_pi / 180.f);
        m_half_height = tan_half;
        m_half_width = tan_half * float(width) / float(height);
    }

    // Direction through film position (fx, fy) in pixels, before the lens.
    Vec3 pinhole_direction(float fx, float fy) const {
        const float sx = (2.f * fx / float(m_width) - 1.f) * m_half_width;
        const float sy = (1.f - 2.f * fy / float(m_height)) * m_half_height;
        return normalize(m_forward + m_right * sx + m_up * sy);
    }

    // A ray through film point (fx, fy) and lens sample (lu, lv) in [0,1)^2.
    Ray ray_through(float fx, float fy, float lu, float lv) const {
        Ray r;
        r.org = m_eye;
        r.dir = pinhole_direction(fx, fy);
        if (m_aperture > 0.f) {
            const float cos_axis = dot(r.dir, m_forward);
            const Vec3 focus = m_eye + r.dir * (m_focal_distance / cos_axis);
            const Vec3 disk = sample_concentric_disk(lu, lv);
            r.org = m_eye + (m_right * disk.x + m_up * disk.y) * m_aperture;
            r.dir = normalize(focus - r.org);
        }
        return r;
    }

    // The camera ray of one path: jittered inside its pixel, lens sampled from its key.
    Ray generate(const PathKey& key) const {
        const uint32_t px = key.pixel % m_width, py = key.pixel / m_width;
        const float fx = float(px) + key.uniform(0, RngDim::pixel_x);
        const float fy = float(py) + key.uniform(0, RngDim::pixel_y);
        return ray_through(fx, fy, key.uniform(0, RngDim::lens_u), key.uniform(0, RngDim::lens_v));
    }

    const Vec3& forward() const { return m_forward; }
    float focal_distance() const { return m_focal_distance; }
    const Vec3& eye() const { return m_eye; }

private:
    Vec3 m_eye, m_forward, m_right, m_up;
    uint32_t m_width, m_height;
    float m_half_width = 1.f, m_half_height = 1.f;
    float m_aperture, m_focal_distance;
};

}  // namespace sfx
