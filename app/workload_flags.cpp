#include <cstdio>

#include "app/commands.h"
#include "workloads/input_error.h"

namespace sfx {

void WorkloadFlags::add_to(CLI::App* c) {
    c->add_option("--res", res, "image size WxH")->capture_default_str();
    c->add_option("--spp", spp, "samples per pixel")->capture_default_str()->check(CLI::PositiveNumber);
    c->add_option("--depth", depth, "bounces after the camera ray (default: the scene's)");
    c->add_option("--tile", tile, "tile edge in pixels, or auto")->capture_default_str();
    c->add_option("--seed", seed, "random seed")->capture_default_str();
    c->add_option("--threads", threads, "worker threads (0: all cores)")->capture_default_str();
}

RenderSettings WorkloadFlags::resolve(const Scene& scene) const {
    RenderSettings s;
    unsigned w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(res.c_str(), "%ux%u%c", &w, &h, &tail) != 2 || w == 0 || h == 0 ||
        w > 65536 || h > 65536)
        throw InputError("command line", 0, "--res", "expected WxH with 1..65536, got '" + res + "'");
    s.width = w;
    s.height = h;
    s.spp = spp;
    if (depth < -1 || depth > 1000)
        throw InputError("command line", 0, "--depth", "expected 0..1000, got " + std::to_string(depth));
    s.max_depth = depth < 0 ? scene.max_depth : uint32_t(depth);
    if (tile == "auto") {
        s.tile = 64;  // the largest the paper's buffers hold; the hardware model refines this
    } else {
        unsigned t = 0;
        if (std::sscanf(tile.c_str(), "%u%c", &t, &tail) != 1 || t == 0 || t > 4096)
            throw InputError("command line", 0, "--tile", "expected 1..4096 or auto, got '" + tile + "'");
        s.tile = t;
    }
    s.seed = seed;
    s.threads = threads;
    return s;
}

}  // namespace sfx
