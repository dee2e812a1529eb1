// The `atrium` generator: a two-storey arcaded courtyard (Sponza-like).

#include <algorithm>
#include <cmath>

#include "workloads/generator_kit.h"

namespace sfx {

namespace {

// Atrium: a two-storey arcaded courtyard (Sponza-like) under a sky panel, with a fountain,
// glass and metal spheres, balustrades and hanging cloths.
void build_atrium(const GeneratorInput& in, SceneBuilder& b) {
    const Ctx c{in, b};
    const uint32_t bays = c.n("bays");
    const float bay = 3.f;
    const float half_l = 0.5f * bay * float(bays);
    const float court = 6.f, gallery = 9.f;  // courtyard half width, gallery back wall
    const float h1 = 5.f, h2 = 9.7f, h_top = 11.5f;
    const uint32_t col_seg = c.n("column_segments"), col_rings = c.n("column_rings");
    const uint32_t arch_seg = c.n("arch_segments");
    const uint32_t stone = c.m("stone"), floor_a = c.m("floor"), floor_b = c.m("floor_dark");

    // Courtyard and gallery floors: checkered marble tiles.
    for (int iz = 0; iz < int(2.f * gallery); ++iz)
        for (int ix = 0; ix < int(bay) * int(bays); ++ix)
            shapes::quad(b, Vec3(-half_l + float(ix), 0.f, -gallery + float(iz)),
                         Vec3(0.f, 0.f, 1.f), Vec3(1.f, 0.f, 0.f),
                         ((ix + iz) & 1) ? floor_a : floor_b);
    // Walls: gallery backs, end walls, and the attic parapet above the arcades.
    for (int s = -1; s <= 1; s += 2) {
        const float z = float(s) * gallery;
        shapes::box(b, Vec3(-half_l, 0.f, std::min(z, z + s * 0.4f)),
                    Vec3(half_l, h_top, std::max(z, z + s * 0.4f)), stone);
        shapes::box(b, Vec3(-half_l, h2, std::min(s * court - 0.3f, s * court + 0.3f)),
                    Vec3(half_l, h_top, std::max(s * court - 0.3f, s * court + 0.3f)), stone);
        const float x = float(s) * half_l;
        shapes::box(b, Vec3(std::min(x, x + s * 0.4f), 0.f, -gallery),
                    Vec3(std::max(x, x + s * 0.4f), h_top, gallery), stone);
    }
    // Per side and storey: columns, arches, floor slab over the gallery, cornice.
    auto column = [&](const Vec3& base, float height) {
        shapes::lathe(b, base, height, col_seg, col_rings, stone, [](float, float t) {
            if (t < 0.06f) return 0.34f;
            if (t < 0.1f) return 0.34f - 0.1f * smoothstep(0.06f, 0.1f, t);
            if (t > 0.9f) return 0.24f + 0.12f * smoothstep(0.9f, 0.97f, t);
            return 0.24f - 0.02f * t;  // entasis
        });
    };
    const uint32_t curtain_res = c.n("curtain_resolution");
    const uint32_t cloths[3] = {c.m("cloth_red"), c.m("cloth_blue"), c.m("cloth_green")};
    for (int s = -1; s <= 1; s += 2) {
        const float z = float(s) * court;
        const float floors[2] = {0.f, h1 + 0.2f};
        const float springs[2] = {3.f, h1 + 0.2f + 2.6f};
        const float tops[2] = {h1, h2};
        for (int storey = 0; storey < 2; ++storey) {
            for (uint32_t i = 0; i <= bays; ++i)
                column(Vec3(-half_l + bay * float(i), floors[storey], z),
                       springs[storey] - floors[storey]);
            for (uint32_t i = 0; i < bays; ++i) {
                const float cx = -half_l + bay * (float(i) + 0.5f);
                const Transform xf =
                    Transform::make(Vec3(1.f), Vec3(0.f), Vec3(cx, springs[storey], z));
                shapes::arch(b, 0.5f * bay - 0.3f, 0.5f * bay, tops[storey] - springs[storey], 0.6f,
                             arch_seg, stone, xf);
            }
            // Slab over the gallery and a cornice along the arcade.
            const float zb = s > 0 ? z - 0.3f : z + 0.3f;
            shapes::box(b, Vec3(-half_l, tops[storey], std::min(zb, float(s) * gallery)),
                        Vec3(half_l, tops[storey] + 0.2f, std::max(zb, float(s) * gallery)), stone);
            shapes::box(b, Vec3(-half_l, tops[storey], z - 0.45f),
                        Vec3(half_l, tops[storey] + 0.3f, z + 0.45f), stone);
        }
        // Upper balustrade: rail, plinth and turned balusters in every bay.
        const float fy = h1 + 0.2f;
        const uint32_t per_bay = c.n("balusters_per_bay");
        const uint32_t bal_seg = c.n("baluster_segments"), bal_rings = c.n("baluster_rings");
        for (uint32_t i = 0; i < bays; ++i) {
            const float x0 = -half_l + bay * float(i) + 0.3f, x1 = x0 + bay - 0.6f;
            shapes::box(b, Vec3(x0, fy, z - 0.15f), Vec3(x1, fy + 0.12f, z + 0.15f), stone);
            shapes::box(b, Vec3(x0, fy + 0.9f, z - 0.17f), Vec3(x1, fy + 1.f, z + 0.17f), stone);
            for (uint32_t k = 0; k < per_bay; ++k) {
                const float x = x0 + (x1 - x0) * (float(k) + 0.5f) / float(per_bay);
                shapes::lathe(b, Vec3(x, fy + 0.12f, z), 0.78f, bal_seg, bal_rings, stone,
                              [](float, float t) {
                                  return 0.045f + 0.04f * std::sin(3.14159f * std::pow(t, 0.7f)) -
                                         0.015f * std::sin(6.2832f * t);
                              });
            }
            // Cloths hang from the upper arches in alternate bays, with folds.
            if ((i + (s > 0 ? 1u : 0u)) % 2 == 0) {
                const float cz = z - float(s) * 0.45f;
                const uint32_t cloth = cloths[(i / 2 + (s > 0)) % 3];
                shapes::surface(b, curtain_res, curtain_res * 2, cloth, [&](float u, float v) {
                    const float x = x0 + 0.15f + (x1 - x0 - 0.3f) * u;
                    const float y = springs[1] + 1.2f - 3.6f * v;
                    const float fold = 0.08f * std::sin(u * 6.f * 3.14159f) * (0.3f + v);
                    return Vec3(x, y, cz - float(s) * (fold + 0.25f * v * v));
                });
            }
        }
    }
    // End walls: blind arcades on pilasters continue the rhythm of the long sides.
    const float end_bays[6] = {-gallery, -court, -2.f, 2.f, court, gallery};
    for (int s = -1; s <= 1; s += 2) {
        const float x = float(s) * (half_l - 0.15f);
        for (int storey = 0; storey < 2; ++storey) {
            const float floor_y = storey ? h1 + 0.2f : 0.f, spring = storey ? h1 + 2.8f : 3.f;
            const float top = storey ? h2 : h1;
            for (int k = 0; k < 5; ++k) {
                const float z0 = end_bays[k], z1 = end_bays[k + 1];
                const float half_w = 0.5f * (z1 - z0);
                const Transform xf = Transform::rotate_y(90.f, Vec3(x, spring, 0.5f * (z0 + z1)));
                shapes::arch(b, half_w - 0.3f, half_w, top - spring, 0.3f, arch_seg, stone, xf);
            }
            for (int k = 0; k < 6; ++k)
                shapes::box(b, Vec3(x - 0.2f, floor_y, end_bays[k] - 0.3f),
                            Vec3(x + 0.2f, spring, end_bays[k] + 0.3f), stone);
        }
    }
    // Courtyard: a fountain with a glass sphere, pedestals with glass and metal spheres,
    // and planters with shrubs.
    const uint32_t glass = c.m("glass"), metal = c.m("metal"), plant = c.m("plant");
    shapes::lathe(b, Vec3(0.f, 0.f, 0.f), 0.6f, 64, 12, stone, [](float, float t) {
        return 2.f - 0.3f * t;  // basin wall
    });
    shapes::lathe(b, Vec3(0.f, 0.f, 0.f), 1.3f, 32, 16, stone, [](float, float t) {
        return 0.25f + 0.35f * smoothstep(0.75f, 1.f, t);  // the central stem and bowl
    });
    b.add_sphere(Vec3(0.f, 1.9f, 0.f), 0.6f, glass);
    const uint32_t pedestals = c.n("pedestals");
    for (uint32_t k = 0; k < pedestals; ++k) {
        const float x =
            -half_l + 2.5f + (2.f * half_l - 5.f) * float(k) / float(std::max(1u, pedestals - 1));
        for (int s = -1; s <= 1; s += 2) {
            const float z = float(s) * (court - 1.5f);
            shapes::box(b, Vec3(x - 0.3f, 0.f, z - 0.3f), Vec3(x + 0.3f, 1.f, z + 0.3f), stone);
            b.add_sphere(Vec3(x, 1.35f, z), 0.35f, (k + (s > 0)) % 2 ? glass : metal);
        }
    }
    const uint32_t rock_levels = c.n("shrub_detail");
    for (int corner = 0; corner < 4; ++corner) {
        const float x = (corner & 1 ? 1.f : -1.f) * (half_l - 2.f);
        const float z = (corner & 2 ? 1.f : -1.f) * (court - 1.6f);
        shapes::box(b, Vec3(x - 0.7f, 0.f, z - 0.7f), Vec3(x + 0.7f, 0.6f, z + 0.7f), stone);
        for (int k = 0; k < 3; ++k)
            shapes::rock(b, Vec3(x + 0.3f * float(k - 1), 1.1f + 0.2f * float(k % 2), z),
                         Vec3(0.55f, 0.6f, 0.55f), rock_levels, in.seed * 131 + corner * 7 + k,
                         0.5f, plant);
    }
    // Lights: the sky over the courtyard and a lantern above the fountain.
    b.begin_object();
    shapes::quad(b, Vec3(-half_l, h_top, -court), Vec3(2.f * half_l, 0.f, 0.f),
                 Vec3(0.f, 0.f, 2.f * court), c.m("sky"));
    b.begin_object();
    b.add_sphere(Vec3(0.f, 6.5f, 0.f), 0.3f, c.m("lantern"));
    b.begin_object();
}

}  // namespace

GeneratorInfo atrium_generator() {
    return {"atrium",
            "two-storey arcaded courtyard under a sky panel, fountain, glass and metal spheres",
            {P("bays", 8, 2, 64, true, "arches per side and storey (3 m each)"),
             P("column_segments", 28, 3, 512, true, "segments around a column"),
             P("column_rings", 15, 1, 512, true, "rings up a column"),
             P("arch_segments", 24, 2, 512, true, "segments along an arch"),
             P("balusters_per_bay", 7, 0, 64, true, "balusters in each upper bay"),
             P("baluster_segments", 12, 3, 256, true, "segments around a baluster"),
             P("baluster_rings", 10, 1, 256, true, "rings up a baluster"),
             P("curtain_resolution", 14, 1, 256, true, "grid cells across a hanging cloth"),
             P("pedestals", 4, 0, 64, true, "pedestals with spheres along each side"),
             P("shrub_detail", 2, 0, 6, true, "icosphere subdivisions of a shrub")},
            {"stone", "floor", "floor_dark", "glass", "metal", "plant", "cloth_red", "cloth_blue",
             "cloth_green", "sky", "lantern"},
            build_atrium};
}

}  // namespace sfx
