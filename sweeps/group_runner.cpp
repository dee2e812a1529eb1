#include "sweeps/group_runner.h"

#include <cmath>
#include <limits>

#include "kernels/bvh.h"
#include "sweeps/point_group.h"
#include "base/input_error.h"
#include "workloads/scene_loader.h"

namespace sfx {

nlohmann::json group_spec_json(const std::vector<SweepPoint>& points, uint32_t threads) {
    nlohmann::json spec;
    spec["threads"] = threads;
    spec["points"] = nlohmann::json::array();
    for (const SweepPoint& p : points) spec["points"].push_back(p.config_yaml);
    return spec;
}

std::vector<PointRun> run_group(const nlohmann::json& spec) {
    const std::string file = "group spec";
    if (!spec.is_object() || !spec.contains("points") || !spec["points"].is_array() ||
        spec["points"].empty())
        throw InputError(file, 0, "points", "expected a non-empty list of point configurations");
    const uint32_t threads =
        spec.contains("threads") && spec["threads"].is_number_unsigned() ? spec["threads"].get<uint32_t>() : 0;
    std::vector<ParsedPoint> points;
    std::vector<std::string> keys;
    for (size_t i = 0; i < spec["points"].size(); ++i) {
        const nlohmann::json& p = spec["points"][i];
        if (!p.is_string()) throw InputError(file, 0, "points[" + std::to_string(i) + "]", "expected YAML text");
        points.push_back(parse_point_config(p.get<std::string>(), "points[" + std::to_string(i) + "]"));
        // The key is computed here, with this sfx's version: a worker running another version
        // produces other keys, which the client rejects.
        keys.push_back(point_key(p.get<std::string>()));
        if (points.back().workload != points.front().workload ||
            points.back().fidelity != points.front().fidelity)
            throw InputError(file, 0, "points[" + std::to_string(i) + "]",
                             "a group's points must share scene, resolution, spp, depth, tile, seed and fidelity");
    }
    const WorkloadConfig& w = points.front().workload;
    const std::string started = iso8601_now();
    const Scene scene = load_scene(w.scene);
    const Bvh bvh(scene);
    const RenderSettings settings = w.render_settings(threads);
    std::vector<HwConfig> configs;
    for (const ParsedPoint& p : points) configs.push_back(p.hw);
    const PointGroupResult result = run_point_group(scene, bvh, settings, configs, points.front().fidelity);
    const std::string finished = iso8601_now();
    std::vector<PointRun> rows;
    for (size_t i = 0; i < points.size(); ++i) {
        PointRun r;
        r.key = keys[i];
        r.sfx_version = sfx_version();
        r.started_at = started;
        r.finished_at = finished;
        for (const Stat& s : result.predictions[i].stats()) {
            r.metrics.emplace_back(s.name, s.value);
            r.units[s.name] = {s.unit, s.description};
        }
        rows.push_back(std::move(r));
    }
    return rows;
}

nlohmann::ordered_json point_run_json(const PointRun& run) {
    nlohmann::ordered_json j;
    j["key"] = run.key;
    j["sfx_version"] = run.sfx_version;
    j["started_at"] = run.started_at;
    j["finished_at"] = run.finished_at;
    nlohmann::ordered_json m = nlohmann::ordered_json::object();
    for (const auto& [name, value] : run.metrics) {
        if (std::isfinite(value)) m[name] = value;
        else m[name] = nullptr;  // JSON has no NaN or infinity; stored as NULL
    }
    j["metrics"] = m;
    nlohmann::ordered_json u = nlohmann::ordered_json::object();
    for (const auto& [name, unit] : run.units) u[name] = {unit.first, unit.second};
    j["units"] = u;
    return j;
}

PointRun point_run_from_json(const nlohmann::ordered_json& j) {
    PointRun r;
    r.key = j.at("key").get<std::string>();
    r.sfx_version = j.at("sfx_version").get<std::string>();
    r.started_at = j.at("started_at").get<std::string>();
    r.finished_at = j.at("finished_at").get<std::string>();
    // Ordered: new stat columns are added in Prediction::stats() order.
    for (const auto& [name, value] : j.at("metrics").items())
        r.metrics.emplace_back(name, value.is_null() ? std::numeric_limits<double>::quiet_NaN()
                                                     : value.get<double>());
    if (j.contains("units"))
        for (const auto& [name, unit] : j.at("units").items())
            r.units[name] = {unit.at(0).get<std::string>(), unit.at(1).get<std::string>()};
    return r;
}

}  // namespace sfx
