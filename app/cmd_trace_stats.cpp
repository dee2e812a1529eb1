// sfx trace-stats SCENE: stream lengths and ideal SIMD utilization per stage, from one
// functional stream render per tile size (all SIMD widths at once), in the layout of the
// paper's Tables 2, 3 and 4, plus per-frame operation counts (Table 1's columns).

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "kernels/bvh.h"
#include "kernels/stream/stream_tracer.h"
#include "base/input_error.h"
#include "workloads/scene_loader.h"

namespace sfx {

namespace {

std::vector<uint32_t> parse_list(const std::string& text, const std::string& key, uint32_t max) {
    std::vector<uint32_t> out;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        unsigned v = 0;
        char tail = 0;
        if (std::sscanf(item.c_str(), "%u%c", &v, &tail) != 1 || v == 0 || v > max)
            throw InputError("command line", 0, key,
                             "expected a comma-separated list of 1.." + std::to_string(max) +
                                 ", got '" + text + "'");
        out.push_back(v);
    }
    if (out.empty()) throw InputError("command line", 0, key, "expected at least one value");
    return out;
}

struct TileRun {
    uint32_t tile;
    CountingSink counts;
    RenderStats stats;
};

// Box tests per traced ray (primary, secondary) and the primary entry search's cost and depth.
struct SeedMeasures {
    double box_per_ray[2] = {0.0, 0.0};
    double entry_depth = 0.0;  // mean depth of the primary entry node (root: 0)
    uint64_t entry_lanes = 0;  // lanes of the search's ops (frustum bounds and tests)
    double reorder_lanes_per_ray = 0.0;  // lanes of the reordering's ops per traced ray
    // RayGrid: walk and enqueue lanes per secondary ray, queues traced, their mean length and
    // the share of them that were full.
    double batching_lanes_per_ray = 0.0;
    uint64_t queues = 0;
    double mean_queue = 0.0, full_share = 0.0;
};

SeedMeasures seed_measures(const TileRun& r) {
    SeedMeasures m;
    const double rays[2] = {double(r.stats.camera_rays),
                            double(r.stats.extension_rays + r.stats.shadow_rays)};
    for (int g = 0; g < 2; ++g)
        m.box_per_ray[g] =
            rays[g] > 0 ? double(r.counts.kind_lanes(OpKind::box_test, g)) / rays[g] : 0.0;
    const uint64_t search =
        r.counts.kind_lanes(OpKind::frustum_bounds) + r.counts.kind_lanes(OpKind::frustum_test);
    const uint64_t reorder = r.counts.kind_lanes(OpKind::reorder_lod_test) +
                             r.counts.kind_lanes(OpKind::reorder_key) +
                             r.counts.kind_lanes(OpKind::reorder_sort);
    m.reorder_lanes_per_ray = r.stats.rays() ? double(reorder) / double(r.stats.rays()) : 0.0;
    m.entry_depth =
        r.stats.entry_searches ? double(r.stats.entry_depth_sum) / r.stats.entry_searches : 0.0;
    m.entry_lanes = search;
    const uint64_t batching =
        r.counts.kind_lanes(OpKind::raygrid_walk) + r.counts.kind_lanes(OpKind::raygrid_enqueue);
    m.batching_lanes_per_ray = rays[1] > 0 ? double(batching) / rays[1] : 0.0;
    m.queues = r.stats.batch_queues;
    if (m.queues) {
        m.mean_queue = double(r.stats.batch_queued_rays) / double(m.queues);
        m.full_share = double(r.stats.batch_full_queues) / double(m.queues);
    }
    return m;
}

std::string percent(double u) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%.0f", 100.0 * u);
    return buf;
}

}  // namespace

void add_trace_stats_command(CLI::App& app) {
    struct Options {
        std::string scene;
        std::string widths = "4,8,12,16,64";
        std::string tiles = "32,64";
        bool json = false;
        WorkloadFlags workload;
    };
    auto options = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand(
        "trace-stats", "stream lengths and ideal SIMD utilization per stage (Tables 2-4)");
    c->add_option("scene", options->scene, "scene file or built-in scene name")->required();
    c->add_option("--widths", options->widths, "SIMD widths N, comma-separated")
        ->capture_default_str();
    c->add_option("--tiles", options->tiles, "tile edges T (stream of T x T rays), comma-separated")
        ->capture_default_str();
    c->add_flag("--json", options->json, "print one JSON document");
    options->workload.add_to(c);
    c->callback([options] {
        const Scene scene = load_scene(options->scene);
        RenderSettings settings = options->workload.resolve(scene);
        const std::vector<uint32_t> widths = parse_list(options->widths, "--widths", 1u << 16);
        const std::vector<uint32_t> tiles = parse_list(options->tiles, "--tiles", 4096);
        const Bvh bvh(scene);
        std::vector<TileRun> runs;
        for (uint32_t tile : tiles) {
            settings.tile = tile;
            TileRun run{tile, CountingSink(widths), {}};
            run.stats = render_stream(scene, bvh, settings, &run.counts).stats;
            runs.push_back(std::move(run));
        }
        const OpStage stages[3] = {OpStage::traversal, OpStage::intersection, OpStage::shading};

        if (options->json) {
            nlohmann::json j;
            j["scene"] = scene.name;
            j["width"] = settings.width;
            j["height"] = settings.height;
            j["spp"] = settings.spp;
            j["max_depth"] = settings.max_depth;
            j["widths"] = widths;
            j["tiles"] = tiles;
            for (const TileRun& r : runs) {
                const std::string t = "tile_" + std::to_string(r.tile) + ".";
                j[t + "rays"] = r.stats.rays();
                j[t + "traversal_ops"] = r.counts.kind_ops(OpKind::box_test);
                j[t + "intersection_ops"] = r.counts.kind_ops(OpKind::triangle_test) +
                                            r.counts.kind_ops(OpKind::sphere_test);
                j[t + "host_seconds"] = r.stats.host_seconds;
                const SeedMeasures m = seed_measures(r);
                j[t + "box_tests_per_ray.primary"] = m.box_per_ray[0];
                j[t + "box_tests_per_ray.secondary"] = m.box_per_ray[1];
                j[t + "entry.frustum_tests"] = r.counts.kind_ops(OpKind::frustum_test);
                j[t + "entry.mean_depth"] = m.entry_depth;
                j[t + "entry.lanes"] = m.entry_lanes;
                j[t + "reorder.lanes_per_ray"] = m.reorder_lanes_per_ray;
                j[t + "batching.lanes_per_ray"] = m.batching_lanes_per_ray;
                j[t + "batching.queues"] = m.queues;
                j[t + "batching.mean_queue_length"] = m.mean_queue;
                j[t + "batching.full_queue_share"] = m.full_share;
                for (uint32_t g = 0; g < 4; ++g) {
                    const auto& b = r.counts.bounce(g);
                    const std::string k = t + "bounce_" + std::to_string(g) + ".";
                    j[k + "rays"] = b.rays;
                    j[k + "rays_per_node"] = b.rays_per_node();
                    j[k + "rays_per_leaf"] = b.rays_per_leaf();
                    j[k + "box_tests_per_ray"] = b.box_tests_per_ray();
                }
                for (bool secondary : {false, true})
                    for (OpStage st : stages) {
                        const auto& s = r.counts.stage(secondary, st);
                        const std::string k =
                            t + (secondary ? "secondary." : "primary.") + to_string(st) + ".";
                        j[k + "ops"] = s.ops;
                        j[k + "lanes"] = s.lanes;
                        j[k + "passed"] = s.passed;
                        j[k + "average_length"] = s.average_length();
                        for (size_t i = 0; i < widths.size(); ++i)
                            j[k + "utilization.w" + std::to_string(widths[i])] =
                                s.utilization(i, widths[i]);
                        j[k + "length_histogram_log2"] = s.histogram;
                    }
            }
            std::cout << j.dump(2) << "\n";
            return;
        }

        auto size = [](uint32_t t) { return std::to_string(t) + "x" + std::to_string(t); };
        auto cell = [](std::string s, size_t w) {
            return s.size() < w ? s + std::string(w - s.size(), ' ') : s + " ";
        };
        std::cout << "scene " << scene.name << ": " << settings.width << "x" << settings.height
                  << " x " << settings.spp << " spp, depth " << settings.max_depth
                  << "; ideal SIMD utilization in %\n\n";
        std::cout << "Table 2: SIMD utilization (T / I), primary rays\n";
        for (size_t i = 0; i < widths.size(); ++i) {
            std::cout << "  SIMD width N = " << widths[i] << "\n";
            for (const TileRun& r : runs) {
                const auto& tr = r.counts.stage(false, OpStage::traversal);
                const auto& is = r.counts.stage(false, OpStage::intersection);
                std::cout << "    " << cell(size(r.tile), 10)
                          << percent(tr.utilization(i, widths[i])) << " / "
                          << percent(is.utilization(i, widths[i])) << "\n";
            }
        }
        std::cout << "\nTable 3: SIMD utilization (T / I / S), secondary rays\n";
        for (size_t i = 0; i < widths.size(); ++i) {
            std::cout << "  SIMD width N = " << widths[i] << "\n";
            for (const TileRun& r : runs) {
                std::cout << "    " << cell(size(r.tile), 10);
                for (int k = 0; k < 3; ++k)
                    std::cout << (k ? " / " : "")
                              << percent(r.counts.stage(true, stages[k]).utilization(i, widths[i]));
                std::cout << "\n";
            }
        }
        std::cout << "\nTable 4: average stream length, secondary rays\n"
                  << "    " << cell("size", 10) << cell("trav", 9) << cell("isec", 9) << "shade\n";
        for (const TileRun& r : runs) {
            std::cout << "    " << cell(size(r.tile), 10);
            for (int k = 0; k < 3; ++k) {
                char buf[32];
                std::snprintf(buf, sizeof buf, "%.1f",
                              r.counts.stage(true, stages[k]).average_length());
                std::cout << (k < 2 ? cell(buf, 9) : std::string(buf));
            }
            std::cout << "\n";
        }
        std::cout << "\nPer-frame operation counts (Table 1's columns; op = one stream filter)\n"
                  << "    " << cell("size", 10) << cell("# rays", 12) << cell("# trav ops", 12)
                  << cell("# isec ops", 12) << cell("# shade ops", 12) << "host s\n";
        for (const TileRun& r : runs) {
            auto sci = [](double v) {
                char buf[32];
                std::snprintf(buf, sizeof buf, "%.3g", v);
                return std::string(buf);
            };
            const uint64_t shade = r.counts.stage(false, OpStage::shading).ops +
                                   r.counts.stage(true, OpStage::shading).ops;
            char secs[32];
            std::snprintf(secs, sizeof secs, "%.2f", r.stats.host_seconds);
            std::cout << "    " << cell(size(r.tile), 10) << cell(sci(double(r.stats.rays())), 12)
                      << cell(sci(double(r.counts.kind_ops(OpKind::box_test))), 12)
                      << cell(sci(double(r.counts.kind_ops(OpKind::triangle_test) +
                                         r.counts.kind_ops(OpKind::sphere_test))),
                              12)
                      << cell(sci(double(shade)), 12) << secs << "\n";
        }
        std::cout << "\nBox tests per ray; the primary entry search (--primary-entry "
                  << options->workload.primary_entry << ") and the reordering's lanes per ray "
                  << "(--reorder " << options->workload.reorder << ")\n"
                  << "    " << cell("size", 10) << cell("primary", 10) << cell("secondary", 11)
                  << cell("frustum tests", 15) << cell("mean entry depth", 18)
                  << "reorder lanes/ray\n";
        for (const TileRun& r : runs) {
            const SeedMeasures m = seed_measures(r);
            char buf[4][32];
            std::snprintf(buf[0], sizeof buf[0], "%.2f", m.box_per_ray[0]);
            std::snprintf(buf[1], sizeof buf[1], "%.2f", m.box_per_ray[1]);
            std::snprintf(buf[2], sizeof buf[2], "%.2f", m.entry_depth);
            std::snprintf(buf[3], sizeof buf[3], "%.2f", m.reorder_lanes_per_ray);
            std::cout << "    " << cell(size(r.tile), 10) << cell(buf[0], 10) << cell(buf[1], 11)
                      << cell(std::to_string(r.counts.kind_ops(OpKind::frustum_test)), 15)
                      << cell(buf[2], 18) << buf[3] << "\n";
        }
        std::cout << "\nPer bounce (seeds/000 Tables 2 and 4): rays per visited node (box-test "
                     "stream length), per visited leaf (primitive-test stream length), box tests "
                     "per ray; RayGrid (--batching "
                  << options->workload.batching << ")\n"
                  << "    " << cell("size", 10) << cell("bounce", 8) << cell("rays", 11)
                  << cell("rays/node", 11) << cell("rays/leaf", 11) << "box tests/ray\n";
        for (const TileRun& r : runs)
            for (uint32_t g = 0; g < 4 && g <= settings.max_depth; ++g) {
                const auto& b = r.counts.bounce(g);
                char buf[3][32];
                std::snprintf(buf[0], sizeof buf[0], "%.2f", b.rays_per_node());
                std::snprintf(buf[1], sizeof buf[1], "%.2f", b.rays_per_leaf());
                std::snprintf(buf[2], sizeof buf[2], "%.2f", b.box_tests_per_ray());
                std::cout << "    " << cell(size(r.tile), 10)
                          << cell(g == 0 ? std::string("primary") : std::to_string(g), 8)
                          << cell(std::to_string(b.rays), 11) << cell(buf[0], 11)
                          << cell(buf[1], 11) << buf[2] << "\n";
            }
        if (options->workload.batching != "none") {
            std::cout << "    " << cell("size", 10) << cell("queues", 10) << cell("mean length", 13)
                      << cell("full", 8) << "walk+enqueue lanes per secondary ray\n";
            for (const TileRun& r : runs) {
                const SeedMeasures m = seed_measures(r);
                char buf[3][32];
                std::snprintf(buf[0], sizeof buf[0], "%.1f", m.mean_queue);
                std::snprintf(buf[1], sizeof buf[1], "%.0f%%", 100.0 * m.full_share);
                std::snprintf(buf[2], sizeof buf[2], "%.2f", m.batching_lanes_per_ray);
                std::cout << "    " << cell(size(r.tile), 10) << cell(std::to_string(m.queues), 10)
                          << cell(buf[0], 13) << cell(buf[1], 8) << buf[2] << "\n";
            }
        }
    });
}

}  // namespace sfx
