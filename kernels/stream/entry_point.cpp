#include "kernels/stream/entry_point.h"

#include <algorithm>
#include <cmath>

namespace sfx {

namespace {
double dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
}  // namespace

void FrustumProxy::fit(const double w_sum[3], uint32_t count, const RayPrecomp* const* rays) {
    const double len = std::sqrt(dot(w_sum, w_sum));
    if (!(len > 0.0)) return;  // directions cancel out: no planes
    const double w[3] = {w_sum[0] / len, w_sum[1] / len, w_sum[2] / len};
    // u: perpendicular to w (from the axis w is least aligned with), v = w x u.
    const int least = std::fabs(w[0]) < std::fabs(w[1])
                          ? (std::fabs(w[0]) < std::fabs(w[2]) ? 0 : 2)
                          : (std::fabs(w[1]) < std::fabs(w[2]) ? 1 : 2);
    double e[3] = {0.0, 0.0, 0.0};
    e[least] = 1.0;
    double u[3] = {e[1] * w[2] - e[2] * w[1], e[2] * w[0] - e[0] * w[2], e[0] * w[1] - e[1] * w[0]};
    const double ulen = std::sqrt(dot(u, u));
    for (double& c : u) c /= ulen;
    const double v[3] = {w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2],
                         w[0] * u[1] - w[1] * u[0]};
    // Slopes (d.u / d.w, d.v / d.w) and origin coordinates, their ranges over the rays.
    double s_lo[2] = {INFINITY, INFINITY}, s_hi[2] = {-INFINITY, -INFINITY};
    double o_lo[3] = {INFINITY, INFINITY, INFINITY}, o_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    const double* frame[3] = {u, v, w};
    for (uint32_t i = 0; i < count; ++i) {
        const double d[3] = {rays[i]->dir.x, rays[i]->dir.y, rays[i]->dir.z};
        const double o[3] = {rays[i]->org.x, rays[i]->org.y, rays[i]->org.z};
        const double dw = dot(d, w);
        if (!(dw > 0.0)) return;  // a ray at or beyond 90 degrees from the mean: no planes
        for (int k = 0; k < 2; ++k) {
            const double slope = dot(d, frame[k]) / dw;
            s_lo[k] = std::min(s_lo[k], slope);
            s_hi[k] = std::max(s_hi[k], slope);
        }
        for (int k = 0; k < 3; ++k) {
            const double c = dot(o, frame[k]);
            o_lo[k] = std::min(o_lo[k], c);
            o_hi[k] = std::max(o_hi[k], c);
        }
    }
    // Widened by far more than the double rounding of the slopes, so n . d < 0 for every ray.
    for (int k = 0; k < 2; ++k) {
        s_lo[k] -= 1e-7 * (1.0 + std::fabs(s_lo[k]));
        s_hi[k] += 1e-7 * (1.0 + std::fabs(s_hi[k]));
    }
    // Side plane k, upper: n = a - s_hi w with a = u or v, so n . d = d.w (slope - s_hi) < 0 and
    // n . (o + t d) <= n . o <= max(o.a) - s_hi o.w over the origins' ranges. Lower: n = -a + s_lo
    // w.
    auto add = [&](const double* a, double sign, double s, int k) {
        Plane& p = planes[plane_count++];
        for (int c = 0; c < 3; ++c) p.n[c] = sign * a[c] - sign * s * w[c];
        const double a_max = sign > 0 ? o_hi[k] : -o_lo[k];
        p.d = a_max + std::max(-sign * s * o_lo[2], -sign * s * o_hi[2]);
    };
    for (int k = 0; k < 2; ++k) {
        add(frame[k], 1.0, s_hi[k], k);
        add(frame[k], -1.0, s_lo[k], k);
    }
    Plane& back = planes[plane_count++];  // n = -w: n . d = -d.w < 0
    for (int c = 0; c < 3; ++c) back.n[c] = -w[c];
    back.d = -o_lo[2];
}

bool FrustumProxy::overlaps(const Bounds3& box) const {
    if (empty) return false;
    // The slab filter computes in float and lets in rays that pass a few ulps outside a box;
    // the planes are exact (double) but compared with a margin 1e-4 of the coordinates
    // involved, far above that rounding, so such a ray's box still overlaps.
    for (uint32_t i = 0; i < plane_count; ++i) {
        const Plane& p = planes[i];
        double lowest = 0.0, scale = std::fabs(p.d);
        for (int a = 0; a < 3; ++a) {
            lowest += p.n[a] >= 0.0 ? p.n[a] * double(box.lo[a]) : p.n[a] * double(box.hi[a]);
            scale +=
                std::fabs(p.n[a]) * (std::fabs(double(box.lo[a])) + std::fabs(double(box.hi[a])));
        }
        if (lowest > p.d + 1e-4 * scale + 1e-30) return false;  // the box lies beyond the plane
    }
    return true;
}

}  // namespace sfx
