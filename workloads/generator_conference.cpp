// The `conference` generator: a conference room with 72 ceiling light panels.

#include <algorithm>
#include <cmath>

#include "workloads/generator_kit.h"

namespace sfx {

namespace {

// One office chair facing +z (backrest at -z), built around the origin and moved by `xf`.
void office_chair(SceneBuilder& b, const Transform& xf, uint32_t detail, uint32_t fabric,
                  uint32_t frame) {
    const uint32_t first_vertex = uint32_t(b.scene().positions.size());
    const uint32_t seg = detail;
    // Five-star base with casters.
    for (int k = 0; k < 5; ++k) {
        const Transform leg = Transform::rotate_y(72.f * float(k) + 18.f);
        shapes::box(b, Vec3(0.f, 0.06f, -0.025f), Vec3(0.32f, 0.1f, 0.025f), frame, &leg);
        const Vec3 tip = leg.apply(Vec3(0.3f, 0.f, 0.f));
        shapes::lathe(b, tip, 0.06f, seg / 2, seg / 4, frame,
                      [](float, float t) { return 0.008f + 0.022f * std::sin(3.14159f * t); });
    }
    shapes::lathe(b, Vec3(0.f, 0.08f, 0.f), 0.36f, seg, 4, frame,
                  [](float, float t) { return t < 0.5f ? 0.035f : 0.025f; });
    // Seat: a shell and a cushion bulging up.
    shapes::box(b, Vec3(-0.26f, 0.42f, -0.26f), Vec3(0.26f, 0.45f, 0.24f), frame);
    shapes::surface(b, seg, seg, fabric, [](float u, float v) {
        const float x = -0.25f + 0.5f * u, z = 0.23f - 0.48f * v;
        const float su = 2.f * u - 1.f, sv = 2.f * v - 1.f;
        const float bulge = (1.f - su * su * su * su) * (1.f - sv * sv * sv * sv);
        return Vec3(x, 0.45f + 0.06f * bulge, z);
    });
    // Backrest: a curved, reclined pad (front and back skins).
    for (int side = 0; side < 2; ++side) {
        shapes::surface(b, seg, seg, side ? frame : fabric, [side](float u, float v) {
            const float x = -0.24f + 0.48f * (side ? 1.f - u : u);
            const float y = 0.56f + 0.5f * v;
            const float sx = x / 0.24f;
            const float thick =
                side ? 0.f : 0.04f * (1.f - sx * sx * sx * sx) * std::sin(3.14159f * v);
            const float z = -0.27f - 0.12f * v + 0.08f * sx * sx - thick + (side ? -0.02f : 0.f);
            return Vec3(x, y, z);
        });
    }
    // Armrests on posts.
    for (int s = -1; s <= 1; s += 2) {
        const float x = 0.29f * float(s);
        shapes::box(b, Vec3(x - 0.03f, 0.66f, -0.2f), Vec3(x + 0.03f, 0.69f, 0.12f), frame);
        shapes::lathe(b, Vec3(x, 0.45f, -0.05f), 0.21f, seg / 2, 2, frame,
                      [](float, float) { return 0.015f; });
    }
    // The chair was built around the origin; move it into place.
    auto& positions = b.scene().positions;
    for (size_t i = first_vertex; i < positions.size(); ++i) positions[i] = xf.apply(positions[i]);
}

// Conference room: a long table with chairs around it and along the walls, wood wainscot, a
// whiteboard, and a ceiling of 12 x 6 light panels (72 area lights).
void build_conference(const GeneratorInput& in, SceneBuilder& b) {
    const Ctx c{in, b};
    const float hx = 10.f, hz = 5.f, h = 3.2f;
    const uint32_t wall = c.m("wall"), carpet = c.m("carpet"), wood = c.m("wood");
    const uint32_t metal = c.m("metal"), ceiling = c.m("ceiling"), board = c.m("whiteboard");
    const uint32_t detail = c.n("chair_detail");
    const uint32_t fabrics[2] = {c.m("fabric"), c.m("fabric_alt")};
    // Shell: carpet floor (tiles), walls, ceiling.
    shapes::grid(b, Vec3(-hx, 0.f, -hz), Vec3(0.f, 0.f, 2.f * hz), Vec3(2.f * hx, 0.f, 0.f), 20, 10,
                 carpet);
    shapes::quad(b, Vec3(-hx, h, -hz), Vec3(2.f * hx, 0.f, 0.f), Vec3(0.f, 0.f, 2.f * hz), ceiling);
    shapes::quad(b, Vec3(-hx, 0.f, -hz), Vec3(0.f, h, 0.f), Vec3(2.f * hx, 0.f, 0.f), wall);
    shapes::quad(b, Vec3(-hx, 0.f, hz), Vec3(2.f * hx, 0.f, 0.f), Vec3(0.f, h, 0.f), wall);
    shapes::quad(b, Vec3(-hx, 0.f, -hz), Vec3(0.f, 0.f, 2.f * hz), Vec3(0.f, h, 0.f), wall);
    shapes::quad(b, Vec3(hx, 0.f, -hz), Vec3(0.f, h, 0.f), Vec3(0.f, 0.f, 2.f * hz), wall);
    // Wood wainscot panels with a rail along the long walls, and a whiteboard at the far end.
    for (int s = -1; s <= 1; s += 2) {
        for (int k = 0; k < 16; ++k) {
            const float x0 = -hx + 0.1f + 1.25f * float(k);
            const float z = float(s) * (hz - 0.02f);
            shapes::box(b, Vec3(x0, 0.1f, std::min(z, z - s * 0.03f)),
                        Vec3(x0 + 1.1f, 0.95f, std::max(z, z - s * 0.03f)), wood);
        }
        shapes::box(b, Vec3(-hx, 0.97f, s > 0 ? hz - 0.06f : -hz),
                    Vec3(hx, 1.02f, s > 0 ? hz : -hz + 0.06f), wood);
    }
    shapes::box(b, Vec3(hx - 0.05f, 0.9f, -2.f), Vec3(hx - 0.02f, 2.2f, 2.f), board);
    shapes::box(b, Vec3(hx - 0.08f, 0.86f, -2.05f), Vec3(hx - 0.02f, 0.9f, 2.05f), metal);
    // The table: a racetrack top on pedestals, with a notepad and a cup at every place.
    const float table_half = 5.f, table_w = 1.2f, top_y = 0.75f;
    shapes::box(b, Vec3(-table_half, top_y - 0.05f, -table_w), Vec3(table_half, top_y, table_w),
                wood);
    for (int s = -1; s <= 1; s += 2)
        shapes::lathe(b, Vec3(float(s) * table_half, top_y - 0.05f, 0.f), 0.05f, 96, 1, wood,
                      [](float, float) { return 1.2f; });
    for (int k = -2; k <= 2; ++k)
        shapes::box(b, Vec3(2.f * float(k) - 0.2f, 0.f, -0.5f),
                    Vec3(2.f * float(k) + 0.2f, top_y - 0.05f, 0.5f), metal);
    const uint32_t per_side = c.n("chairs_per_side");
    const uint32_t cup_seg = c.n("cup_segments");
    auto place_setting = [&](float x, float z, float facing) {
        const Transform xf = Transform::rotate_y(facing, Vec3(x, top_y, z));
        shapes::box(b, Vec3(-0.1f, 0.f, -0.15f), Vec3(0.1f, 0.01f, 0.15f), c.m("paper"), &xf);
        const Vec3 cup = xf.apply(Vec3(0.22f, 0.f, -0.05f));
        shapes::lathe(b, cup, 0.12f, cup_seg, cup_seg / 2, metal,
                      [](float, float t) { return 0.032f + 0.01f * t; });
    };
    uint32_t chair_index = 0;
    auto chair = [&](float x, float z, float facing) {
        const bool alt = hash_float(in.seed, chair_index++, 9) < 0.35f;
        office_chair(b, Transform::rotate_y(facing, Vec3(x, 0.f, z)), detail, fabrics[alt], metal);
    };
    for (uint32_t i = 0; i < per_side; ++i) {
        const float x =
            -table_half + 0.5f + (2.f * table_half - 1.f) * (float(i) + 0.5f) / float(per_side);
        const float jitter = 6.f * (hash_float(in.seed, i, 1) - 0.5f);
        chair(x, -table_w - 0.55f, jitter);  // faces +z, toward the table
        chair(x, table_w + 0.55f, 180.f + jitter);
        place_setting(x, -table_w + 0.35f, 180.f);
        place_setting(x, table_w - 0.35f, 0.f);
    }
    chair(-table_half - 1.6f, 0.f, 90.f);
    chair(table_half + 1.6f, 0.f, -90.f);
    // A second row along the long walls for observers.
    const uint32_t wall_chairs = c.n("wall_chairs_per_side");
    for (uint32_t i = 0; i < wall_chairs; ++i) {
        const float x = -hx + 1.f + (2.f * hx - 2.f) * (float(i) + 0.5f) / float(wall_chairs);
        chair(x, -hz + 0.6f, 0.f);
        chair(x, hz - 0.6f, 180.f);
    }
    // Ceiling: 12 x 6 light panels, each its own area light, in metal trims.
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 6; ++j) {
            const float x = -hx + 20.f / 12.f * (float(i) + 0.5f) - 0.3f;
            const float z = -hz + 10.f / 6.f * (float(j) + 0.5f) - 0.6f;
            b.begin_object();
            shapes::quad(b, Vec3(x, h - 0.03f, z), Vec3(0.6f, 0.f, 0.f), Vec3(0.f, 0.f, 1.2f),
                         c.m("panel"));
            b.begin_object();
            shapes::box(b, Vec3(x - 0.04f, h - 0.04f, z - 0.04f), Vec3(x + 0.64f, h - 0.03f, z),
                        metal);
            shapes::box(b, Vec3(x - 0.04f, h - 0.04f, z + 1.2f),
                        Vec3(x + 0.64f, h - 0.03f, z + 1.24f), metal);
        }
}

}  // namespace

GeneratorInfo conference_generator() {
    return {"conference",
            "conference room: long table, office chairs, wainscot, 12 x 6 ceiling light panels",
            {P("chairs_per_side", 10, 0, 64, true, "chairs along each side of the table"),
             P("wall_chairs_per_side", 12, 0, 64, true, "chairs along each long wall"),
             P("chair_detail", 27, 4, 256, true, "grid cells across a chair's seat and back"),
             P("cup_segments", 24, 3, 256, true, "segments around a cup")},
            {"wall", "carpet", "wood", "metal", "ceiling", "whiteboard", "fabric", "fabric_alt",
             "paper", "panel"},
            build_conference};
}

}  // namespace sfx
