// The `temple` generator: an Egyptian hypostyle hall (after Kalabsha).

#include <algorithm>
#include <cmath>

#include "workloads/generator_kit.h"

namespace sfx {

namespace {

// Bas-relief of an Egyptian temple wall, as a height (m, towards the room) at (u, v) metres
// along and up the wall: stone courses, registers of walking figures, columns of glyphs.
float temple_relief(uint64_t seed, float u, float v) {
    float h = 0.004f * value_noise(seed, u * 9.f, v * 9.f);
    // Stone courses and joints.
    const float course = 0.55f;
    const int row = int(std::floor(v / course));
    const float fv = v / course - float(row);
    const float bu = (u + float(row & 1) * 0.55f) / 1.1f;
    const float fu = bu - std::floor(bu);
    if (fv < 0.025f || fu < 0.012f) h -= 0.008f;
    if (v < 0.6f || v > 8.0f) return h;
    const float reg_h = 1.85f;
    const int reg = int((v - 0.6f) / reg_h);
    const float y = v - 0.6f - float(reg) * reg_h;
    if (y < 0.07f) return h + 0.02f;  // raised ground line of the register
    const float spacing = 1.5f;
    const int cell = int(std::floor(u / spacing));
    const float x0 = u - (float(cell) + 0.5f) * spacing;
    const uint64_t id = uint64_t(int64_t(cell) * 8 + reg);
    const float facing = hash_float(seed, id, 1) < 0.5f ? -1.f : 1.f;
    const float x = x0 * facing;
    const float s = 0.9f + 0.15f * hash_float(seed, id, 2);
    // Figure: union of rounded parts, each a bulge sqrt(1 - d^2) inside its outline.
    float f = 0.f;
    auto ellipse = [&](float cx, float cy, float rx, float ry) {
        const float dx = (x - cx * s) / (rx * s), dy = (y - cy * s) / (ry * s);
        const float d2 = dx * dx + dy * dy;
        if (d2 < 1.f) f = std::max(f, std::sqrt(1.f - d2));
    };
    auto bar = [&](float ax, float ay, float bx, float by, float w) {
        const float px = x - ax * s, py = y - ay * s, qx = (bx - ax) * s, qy = (by - ay) * s;
        const float t = std::min(1.f, std::max(0.f, (px * qx + py * qy) / (qx * qx + qy * qy)));
        const float dx = px - qx * t, dy = py - qy * t;
        const float d2 = (dx * dx + dy * dy) / (w * w * s * s);
        if (d2 < 1.f) f = std::max(f, std::sqrt(1.f - d2));
    };
    if (std::fabs(x0) < 0.5f) {
        const bool offering = hash_float(seed, id, 3) < 0.5f;
        bar(-0.1f, 0.1f, -0.02f, 0.75f, 0.05f);  // back leg
        bar(0.14f, 0.1f, 0.03f, 0.75f, 0.05f);   // front leg (striding)
        ellipse(0.f, 0.92f, 0.17f, 0.25f);       // kilt
        ellipse(0.f, 1.25f, 0.15f, 0.22f);       // torso
        ellipse(0.03f, 1.56f, 0.09f, 0.11f);     // head
        bar(0.f, 1.64f, 0.f, 1.8f, 0.055f);      // crown
        if (offering) {
            bar(0.08f, 1.38f, 0.33f, 1.45f, 0.035f);  // raised arms holding a bowl
            ellipse(0.38f, 1.5f, 0.08f, 0.04f);
        } else {
            bar(0.08f, 1.38f, 0.28f, 1.1f, 0.035f);  // arm holding a staff
            bar(0.3f, 0.1f, 0.3f, 1.75f, 0.02f);
        }
    } else {
        // Column of glyphs between figures: recessed signs on a grid.
        const float gx = (std::fabs(x0) - 0.52f) / 0.2f;
        if (gx > 0.f && gx < 1.f && y > 0.2f && y < 1.75f) {
            const int gi = int((y - 0.2f) / 0.1f);
            const float gy = (y - 0.2f) / 0.1f - float(gi);
            const uint64_t g = id * 64 + uint64_t(gi) * 2 + (x0 > 0.f);
            const float kind = hash_float(seed, g, 7);
            bool in = false;
            if (kind < 0.35f)
                in = (gx - 0.5f) * (gx - 0.5f) + (gy - 0.5f) * (gy - 0.5f) < 0.12f;
            else if (kind < 0.7f)
                in = gy > 0.35f && gy < 0.65f && gx > 0.15f && gx < 0.85f;
            else if (kind < 0.85f)
                in = std::fabs(gx - 0.5f) < 0.15f && gy > 0.1f && gy < 0.9f;
            if (in) h -= 0.012f;
        }
    }
    return h + 0.05f * f;
}

// Temple: an Egyptian hypostyle hall (after Kalabsha): rows of papyrus-bundle columns under
// architraves, walls covered in bas-reliefs, two seated colossi before the lit sanctuary door,
// rubble everywhere. Light comes from a roof slot over the aisle and from the sanctuary.
void build_temple(const GeneratorInput& in, SceneBuilder& b) {
    const Ctx c{in, b};
    const float hx = 9.f, z_front = 10.f, z_back = -20.f, wall_h = 8.f, roof = 9.6f;
    const uint32_t stone = c.m("stone"), relief = c.m("relief"), floor_m = c.m("floor");
    const uint64_t seed = in.seed;
    // Floor: paving slabs of slightly uneven height.
    for (int iz = 0; iz < int(z_front - z_back); ++iz)
        for (int ix = 0; ix < int(2.f * hx); ++ix) {
            const float x = -hx + float(ix), z = z_back + float(iz);
            const float top = -0.012f * hash_float(seed, uint64_t(ix), uint64_t(iz) + 1000);
            shapes::box(b, Vec3(x + 0.004f, -0.2f, z + 0.004f), Vec3(x + 0.996f, top, z + 0.996f),
                        floor_m);
        }
    // Relief walls (left, right, and the back wall around the sanctuary door).
    const uint32_t density = c.n("relief_density");  // grid cells per metre
    const float len = z_front - z_back;
    auto side_height = [seed, len](float reverse) {
        return [seed, len, reverse](float s, float t) {
            return temple_relief(seed, (reverse > 0.f ? 1.f - s : s) * len, t * 8.f);
        };
    };
    shapes::grid(b, Vec3(-hx, 0.f, z_front), Vec3(0.f, 0.f, -len), Vec3(0.f, wall_h, 0.f),
                 uint32_t(len * float(density)), uint32_t(wall_h * float(density)), relief,
                 side_height(1.f));
    shapes::grid(b, Vec3(hx, 0.f, z_back), Vec3(0.f, 0.f, len), Vec3(0.f, wall_h, 0.f),
                 uint32_t(len * float(density)), uint32_t(wall_h * float(density)), relief,
                 side_height(0.f));
    const float door = 1.0f, door_h = 4.f;
    const float back_w = hx - door;
    for (int s = -1; s <= 1; s += 2) {
        const float x0 = s < 0 ? -hx : door;
        shapes::grid(b, Vec3(x0, 0.f, z_back), Vec3(back_w, 0.f, 0.f), Vec3(0.f, wall_h, 0.f),
                     uint32_t(back_w * float(density)), uint32_t(wall_h * float(density)), relief,
                     [seed, x0, back_w](float u, float v) {
                         return temple_relief(seed + 1, 40.f + x0 + u * back_w, v * 8.f);
                     });
    }
    shapes::grid(
        b, Vec3(-door, door_h, z_back), Vec3(2.f * door, 0.f, 0.f), Vec3(0.f, wall_h - door_h, 0.f),
        uint32_t(2.f * door * float(density)), uint32_t((wall_h - door_h) * float(density)), relief,
        [seed](float u, float v) {
            return 0.004f * value_noise(seed + 2, u * 20.f, v * 30.f) +
                   (std::fabs(v - 0.5f) < 0.3f && std::fabs(u - 0.5f) < 0.4f ? 0.03f : 0.f);
        });
    // Upper walls, the front wall, the door passage.
    shapes::box(b, Vec3(-hx - 0.5f, wall_h, z_back - 0.5f), Vec3(-hx, roof, z_front), stone);
    shapes::box(b, Vec3(hx, wall_h, z_back - 0.5f), Vec3(hx + 0.5f, roof, z_front), stone);
    shapes::box(b, Vec3(-hx, wall_h, z_back - 0.5f), Vec3(hx, roof, z_back), stone);
    shapes::box(b, Vec3(-hx - 0.5f, 0.f, z_front), Vec3(hx + 0.5f, roof, z_front + 0.5f), stone);
    shapes::box(b, Vec3(-door - 0.3f, 0.f, z_back - 2.5f), Vec3(-door, door_h, z_back), stone);
    shapes::box(b, Vec3(door, 0.f, z_back - 2.5f), Vec3(door + 0.3f, door_h, z_back), stone);
    shapes::box(b, Vec3(-door, door_h, z_back - 2.5f), Vec3(door, door_h + 0.3f, z_back), stone);
    // Columns: papyrus bundles with open capitals, abaci and architraves.
    const uint32_t seg = c.n("column_segments"), rings = c.n("column_rings");
    const float col_h = 8.f;
    const float row_x[4] = {-6.2f, -3.2f, 3.2f, 6.2f};
    const uint32_t per_row = c.n("columns_per_row");
    const float z0 = -15.f, dz = 18.f / float(std::max(1u, per_row - 1));
    for (int r = 0; r < 4; ++r) {
        for (uint32_t k = 0; k < per_row; ++k) {
            const float z = z0 + dz * float(k);
            const uint64_t cs = seed * 977 + uint64_t(r) * 31 + k;
            shapes::lathe(
                b, Vec3(row_x[r], 0.f, z), col_h, seg, rings, stone, [cs](float theta, float t) {
                    const float lobes = 0.9f + 0.1f * std::fabs(std::cos(4.f * theta));
                    const float wear = 0.015f * value_noise(cs, theta * 6.f, t * 40.f);
                    if (t < 0.03f) return 0.8f - wear;
                    if (t < 0.05f) return 0.8f - 0.25f * smoothstep(0.03f, 0.05f, t) - wear;
                    float r = (0.55f - 0.05f * t) * lobes;
                    if (t > 0.64f && t < 0.71f)  // five tied bands
                        r += 0.03f * std::fabs(std::sin((t - 0.64f) / 0.07f * 5.f * 3.14159f));
                    if (t >= 0.71f) {
                        const float open = std::pow(smoothstep(0.71f, 0.96f, t), 0.8f);
                        r = (0.52f + 0.42f * open) *
                            (0.94f + 0.06f * std::fabs(std::cos(12.f * theta)));
                    }
                    // Incised bands of decoration on the shaft.
                    const float band = std::fmod(t * 14.f, 1.f);
                    if (t > 0.1f && t < 0.6f && band < 0.08f) r -= 0.01f;
                    return r - wear;
                });
            shapes::box(b, Vec3(row_x[r] - 0.6f, col_h, z - 0.6f),
                        Vec3(row_x[r] + 0.6f, col_h + 0.4f, z + 0.6f), stone);
        }
        shapes::box(b, Vec3(row_x[r] - 0.5f, col_h + 0.4f, z0 - 1.f),
                    Vec3(row_x[r] + 0.5f, col_h + 1.2f, z0 + dz * float(per_row - 1) + 1.f), stone);
    }
    // Roof slabs, leaving a slot over the central aisle.
    const float slot = 2.2f;
    shapes::box(b, Vec3(-hx, col_h + 1.2f, z_back), Vec3(-slot, roof, z_front), stone);
    shapes::box(b, Vec3(slot, col_h + 1.2f, z_back), Vec3(hx, roof, z_front), stone);
    shapes::box(b, Vec3(-slot, col_h + 1.2f, z_back), Vec3(slot, roof, z0 - 1.f), stone);
    shapes::box(b, Vec3(-slot, col_h + 1.2f, z0 + dz * float(per_row - 1) + 1.f),
                Vec3(slot, roof, z_front), stone);
    // Seated colossi flanking the sanctuary door.
    const uint32_t statue_levels = c.n("statue_detail");
    for (int s = -1; s <= 1; s += 2) {
        const Vec3 o(2.05f * float(s), 0.f, z_back + 2.2f);
        shapes::box(b, o + Vec3(-1.f, 0.f, -1.9f), o + Vec3(1.f, 0.35f, 0.9f), stone);
        shapes::box(b, o + Vec3(-0.85f, 0.35f, -1.8f), o + Vec3(0.85f, 2.f, 0.f), stone);
        shapes::box(b, o + Vec3(-0.85f, 2.f, -1.8f), o + Vec3(0.85f, 3.6f, -1.35f), stone);
        struct Part {
            Vec3 c, r;
        };
        const Part parts[] = {
            {{-0.35f, 1.15f, 0.35f}, {0.24f, 0.85f, 0.27f}},
            {{0.35f, 1.15f, 0.35f}, {0.24f, 0.85f, 0.27f}},
            {{-0.35f, 0.47f, 0.62f}, {0.19f, 0.12f, 0.33f}},
            {{0.35f, 0.47f, 0.62f}, {0.19f, 0.12f, 0.33f}},
            {{-0.35f, 2.15f, -0.3f}, {0.28f, 0.24f, 0.78f}},
            {{0.35f, 2.15f, -0.3f}, {0.28f, 0.24f, 0.78f}},
            {{0.f, 2.95f, -0.95f}, {0.55f, 0.8f, 0.38f}},
            {{0.f, 3.65f, -0.95f}, {0.78f, 0.3f, 0.36f}},
            {{0.f, 4.3f, -0.9f}, {0.28f, 0.36f, 0.3f}},
            {{0.f, 4.4f, -1.02f}, {0.46f, 0.46f, 0.36f}},
            {{-0.35f, 2.5f, -0.15f}, {0.12f, 0.12f, 0.55f}},
            {{0.35f, 2.5f, -0.15f}, {0.12f, 0.12f, 0.55f}},
            {{-0.66f, 3.15f, -0.9f}, {0.16f, 0.5f, 0.17f}},
            {{0.66f, 3.15f, -0.9f}, {0.16f, 0.5f, 0.17f}},
        };
        uint64_t k = 0;
        for (const Part& p : parts)
            shapes::rock(b, o + p.c, p.r, statue_levels, seed * 7919 + uint64_t(s + 1) * 100 + k++,
                         0.06f, stone);
        shapes::lathe(b, o + Vec3(0.f, 4.7f, -0.95f), 0.55f, 48, 12, stone, [](float, float t) {
            return 0.22f - 0.1f * t + 0.04f * std::sin(t * 3.14159f);  // crown
        });
    }
    // Rubble: piles of fallen stones along the walls and around column bases.
    const uint32_t rocks = c.n("rubble_stones");
    const uint32_t rock_levels = c.n("rubble_detail");
    const uint32_t piles = 40;
    b.expect(uint64_t(rocks) * (shapes::icosphere(rock_levels).indices.size() / 3));
    for (uint32_t i = 0; i < rocks; ++i) {
        const uint32_t pile = uint32_t(hash_float(seed, i, 50) * float(piles));
        float px, pz;
        const float side = hash_float(seed, pile, 51) < 0.5f ? -1.f : 1.f;
        if (pile % 2 == 0) {  // against a side wall
            px = side * (hx - 1.1f);
            pz = z_back + 1.f + (len - 3.f) * hash_float(seed, pile, 52);
        } else {  // at the foot of a column of the outer rows
            const uint32_t col = uint32_t(hash_float(seed, pile, 53) * float(per_row));
            px = side * (row_x[3] + 0.9f);
            pz = z0 + dz * float(std::min(col, per_row - 1)) + 0.8f;
        }
        const float a = 6.2832f * hash_float(seed, i, 54);
        const float d = 0.8f * std::sqrt(hash_float(seed, i, 55));
        const float size = 0.04f + 0.3f * std::pow(hash_float(seed, i, 56), 3.f);
        const Vec3 stretch(1.f + 0.6f * hash_float(seed, i, 57), 0.7f,
                           1.f + 0.6f * hash_float(seed, i, 58));
        shapes::rock(b, Vec3(px + d * std::cos(a), size * 0.45f, pz + d * std::sin(a)),
                     stretch * size, rock_levels, seed * 104729 + i, 0.5f, stone);
    }
    // Lights: the roof slot over the aisle and the glow of the sanctuary.
    b.begin_object();
    shapes::quad(b, Vec3(-slot, roof, z0 - 1.f), Vec3(2.f * slot, 0.f, 0.f),
                 Vec3(0.f, 0.f, dz * float(per_row - 1) + 2.f), c.m("sky"));
    b.begin_object();
    shapes::quad(b, Vec3(-door, 0.f, z_back - 2.4f), Vec3(2.f * door, 0.f, 0.f),
                 Vec3(0.f, door_h, 0.f), c.m("sanctuary"));
    b.begin_object();
}

}  // namespace

GeneratorInfo temple_generator() {
    return {"temple",
            "Egyptian hypostyle hall: papyrus columns, relief walls, colossi, rubble, roof slot",
            {P("relief_density", 25, 1, 400, true, "relief grid cells per metre of wall"),
             P("column_segments", 96, 3, 1024, true, "segments around a column"),
             P("column_rings", 120, 1, 2048, true, "rings up a column"),
             P("columns_per_row", 6, 1, 32, true, "columns in each of the four rows"),
             P("statue_detail", 4, 0, 7, true, "icosphere subdivisions of a statue part"),
             P("rubble_stones", 1950, 0, 1000000, true, "fallen stones"),
             P("rubble_detail", 2, 0, 6, true, "icosphere subdivisions of a stone")},
            {"stone", "relief", "floor", "sky", "sanctuary"},
            build_temple};
}

}  // namespace sfx
