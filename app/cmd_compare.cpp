// sfx compare A.hw.yaml B.hw.yaml --scene SCENE: two hardware configurations timed on one
// functional render (one point group), side by side with ratios B/A and the largest difference
// named; or sfx compare --store DB --a SEL --b SEL: two selections of stored results.

#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "kernels/bvh.h"
#include "sweeps/point_group.h"
#include "sweeps/store_compare.h"
#include "base/input_error.h"
#include "workloads/scene_loader.h"

namespace sfx {
namespace {

struct Row {
    std::string stat;   // dotted stat name
    std::string label;  // what the table shows
    double a = 0, b = 0;
    double impact = 0;  // how much of the frame the difference moves (see largest_difference)
};

std::map<std::string, double> stat_map(const Prediction& p) {
    std::map<std::string, double> m;
    for (const Stat& s : p.stats()) m[s.name] = s.value;
    return m;
}

std::string number(double v) {
    std::ostringstream s;
    if (v != 0 && (std::fabs(v) >= 1e6 || std::fabs(v) < 1e-3)) s << std::scientific << std::setprecision(3) << v;
    else s << std::fixed << std::setprecision(std::fabs(v) >= 100 ? 1 : 4) << v;
    return s.str();
}

std::string ratio_text(double a, double b) {
    if (a == 0 && b == 0) return "=";
    if (a == 0) return "new";
    std::ostringstream s;
    s << std::fixed << std::setprecision(3) << b / a << "x";
    return s.str();
}

// The rows of the comparison: fps, utilization per stage, stalls by cause, operation mix.
// Each row's impact puts different units on one scale: utilization and op-mix shares move
// by their difference in fractions, a stall cause by its change as a fraction of the longer
// frame, so a 10x change of a negligible stall does not outrank a real one.
std::vector<Row> comparison_rows(const std::map<std::string, double>& a,
                                 const std::map<std::string, double>& b) {
    auto get = [](const std::map<std::string, double>& m, const std::string& k) {
        auto it = m.find(k);
        return it == m.end() ? 0.0 : it->second;
    };
    const double frame = std::max({1.0, get(a, "frame_cycles"), get(b, "frame_cycles")});
    std::vector<Row> rows;
    auto add = [&](const std::string& stat, const std::string& label, double scale) {
        Row r{stat, label, get(a, stat), get(b, stat), 0};
        r.impact = scale * std::fabs(r.b - r.a);
        rows.push_back(r);
    };
    add("fps", "fps", 0);
    add("fps_stall_free", "fps, stalls hidden", 0);
    add("frame_cycles", "frame cycles", 0);
    for (const char* s : {"traversal", "intersection", "shading"})
        add(std::string("simd_utilization.") + s, std::string("utilization ") + s, 1);
    for (const char* s : {"traversal", "intersection", "shading"})
        add(std::string("stage_cycles.") + s, std::string("cycles ") + s, 1 / frame);
    for (const char* c : {"bank_conflict", "alignment", "address_fetch", "partition", "scene_memory",
                          "interconnect", "pipeline_fill"})
        add(std::string("stall_cycles.") + c, std::string("stall ") + c, 1 / frame);
    add("stall_cycles.total", "stall total", 0);
    for (const char* m : {"load", "store", "compute", "scatter_gather", "partition"})
        add(std::string("op_mix.") + m + "_percent", std::string("op mix ") + m + " %", 0.01);
    add("op_mix.instructions", "instructions", 0);
    add("ray_buffer.bank_conflict_rate", "bank conflict rate", 1);
    // Area and energy (technology table): shown with ratios, not ranked against frame time.
    add("area.total_mm2", "area mm2", 0);
    add("energy.total_per_frame_mj", "energy per frame mJ", 0);
    add("power.w", "power W", 0);
    add("fps_per_mm2", "fps per mm2", 0);
    add("frames_per_joule", "frames per joule", 0);
    return rows;
}

const Row* largest_difference(const std::vector<Row>& rows) {
    const Row* best = nullptr;
    for (const Row& r : rows)
        if (r.impact > 0 && (!best || r.impact > best->impact)) best = &r;
    return best;
}

void print_rows(const std::vector<Row>& rows, const std::string& head_a, const std::string& head_b) {
    std::cout << std::left << std::setw(30) << "" << std::right << std::setw(14) << head_a
              << std::setw(14) << head_b << std::setw(10) << "B/A" << "\n";
    for (const Row& row : rows)
        std::cout << std::left << std::setw(30) << row.label << std::right << std::setw(14)
                  << number(row.a) << std::setw(14) << number(row.b) << std::setw(10)
                  << ratio_text(row.a, row.b) << "\n";
    if (const Row* largest = largest_difference(rows))
        std::cout << "\nlargest difference: " << largest->label << " (" << largest->stat << "), "
                  << number(largest->a) << " -> " << number(largest->b) << " ("
                  << ratio_text(largest->a, largest->b) << ")\n";
    else
        std::cout << "\nno difference in utilization, stalls or operation mix\n";
}

nlohmann::ordered_json rows_json(const std::vector<Row>& rows) {
    nlohmann::ordered_json ratios = nlohmann::ordered_json::object();
    for (const Row& row : rows)
        ratios[row.stat] = row.a != 0 ? nlohmann::ordered_json(row.b / row.a) : nlohmann::ordered_json(nullptr);
    return ratios;
}

nlohmann::ordered_json largest_json(const std::vector<Row>& rows) {
    const Row* largest = largest_difference(rows);
    if (!largest) return nullptr;
    return {{"stat", largest->stat}, {"a", largest->a}, {"b", largest->b},
            {"ratio", largest->a != 0 ? nlohmann::ordered_json(largest->b / largest->a) : nlohmann::ordered_json(nullptr)}};
}

// Two selections from a results store: ratios of means over rows matched on every other input.
void compare_stored(const std::string& db, const std::string& sel_a, const std::string& sel_b, bool json) {
    if (sel_a.empty() || sel_b.empty())
        throw InputError("command line", 0, sel_a.empty() ? "--a" : "--b", "--store needs --a and --b selections");
    const ResultsStore store(db, ResultsStore::Access::read_only);
    const StoreComparison c = compare_store(store, parse_selection(sel_a, "--a"), parse_selection(sel_b, "--b"));
    const std::vector<Row> rows = comparison_rows(c.mean_a, c.mean_b);
    if (json) {
        nlohmann::ordered_json j;
        j["store"] = db;
        j["a"] = {{"selection", sel_a}, {"rows", c.rows_a}};
        j["b"] = {{"selection", sel_b}, {"rows", c.rows_b}};
        j["matched"] = c.matched;
        for (const auto& [name, v] : c.mean_a) j["a"][name] = v;
        for (const auto& [name, v] : c.mean_b) j["b"][name] = v;
        j["ratios"] = rows_json(rows);
        j["largest_difference"] = largest_json(rows);
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::cout << "store " << db << "\nA: " << sel_a << " (" << c.rows_a << " rows)\nB: " << sel_b << " ("
              << c.rows_b << " rows)\nmeans over " << c.matched
              << " input combinations present on both sides (matched on every other workload, hw and "
                 "fidelity column)\n\n";
    print_rows(rows, "mean A", "mean B");
}

}  // namespace

void add_compare_command(CLI::App& app) {
    struct Options {
        std::string a, b, scene, fidelity = "full", store, sel_a, sel_b, tech;
        bool json = false;
        WorkloadFlags workload;
    };
    auto o = std::make_shared<Options>();
    CLI::App* c = app.add_subcommand(
        "compare", "two hardware configurations side by side on one render, or two selections from a store");
    c->add_option("a", o->a, "configuration A (*.hw.yaml or preset name)");
    c->add_option("b", o->b, "configuration B (*.hw.yaml or preset name)");
    c->add_option("--scene", o->scene, "scene file or built-in scene name");
    c->add_option("--fidelity", o->fidelity, "analytic | sampled | full")
        ->check(CLI::IsMember({"analytic", "sampled", "full"}))
        ->capture_default_str();
    c->add_option("--store", o->store, "compare two selections of this results store instead");
    c->add_option("--a", o->sel_a, "selection A: COLUMN=VALUE[,...], e.g. hw.simd.width=8");
    c->add_option("--b", o->sel_b, "selection B, e.g. hw.simd.width=16");
    c->add_flag("--json", o->json, "print one JSON document");
    add_tech_option(c, o->tech);
    o->workload.add_to(c);
    c->callback([o] {
        if (!o->store.empty()) {
            if (!o->a.empty()) throw InputError("command line", 0, "--store", "give --store with --a/--b, or two hardware files");
            compare_stored(o->store, o->sel_a, o->sel_b, o->json);
            return;
        }
        if (o->a.empty() || o->b.empty())
            throw InputError("command line", 0, "compare", "expected two hardware files A B (or --store DB --a ... --b ...)");
        if (o->scene.empty()) throw InputError("command line", 0, "--scene", "required with two hardware files");
        std::vector<HwConfig> configs = {load_hw_config(o->a), load_hw_config(o->b)};
        apply_tech_option(configs, o->tech);
        const Scene scene = load_scene(o->scene);
        const RenderSettings settings = o->workload.resolve(scene, configs);
        const Bvh bvh(scene);
        PointGroupResult r = run_point_group(scene, bvh, settings, configs, parse_fidelity(o->fidelity));
        const Prediction& pa = r.predictions[0];
        const Prediction& pb = r.predictions[1];
        const std::vector<Row> rows = comparison_rows(stat_map(pa), stat_map(pb));
        if (o->json) {
            nlohmann::ordered_json j;
            j["scene"] = scene.name;
            j["width"] = settings.width;
            j["height"] = settings.height;
            j["spp"] = settings.spp;
            j["tile"] = settings.tile;
            j["fidelity"] = o->fidelity;
            j["a"] = {{"file", o->a}, {"config", pa.config.name}};
            j["b"] = {{"file", o->b}, {"config", pb.config.name}};
            for (const Stat& s : pa.stats()) j["a"][s.name] = s.value;
            for (const Stat& s : pb.stats()) j["b"][s.name] = s.value;
            j["ratios"] = rows_json(rows);
            j["largest_difference"] = largest_json(rows);
            std::cout << j.dump(2) << "\n";
            return;
        }
        std::cout << "scene " << scene.name << ", " << settings.width << "x" << settings.height << " x "
                  << settings.spp << " spp, tile " << settings.tile << ", " << o->fidelity
                  << " fidelity, one render for both\n";
        std::cout << "A: " << o->a << " (" << pa.config.name << ")\nB: " << o->b << " (" << pb.config.name
                  << ")\n\n";
        print_rows(rows, "A", "B");
    });
}

}  // namespace sfx
