#include "sweeps/sweep.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <unordered_set>
#include <sstream>
#include <stdexcept>

#include "hw_model/node_clock.h"
#include "sweeps/point_group.h"
#include "sweeps/sha256.h"
#include "base/input_error.h"
#include "base/user_files.h"
#include "workloads/ray_layout.h"
#include "workloads/scene_loader.h"
#include "base/strict_number.h"
#include "base/shipped_files.h"
#include "base/strict_yaml.h"

#ifndef SFX_VERSION
#define SFX_VERSION "unknown"
#endif

namespace fs = std::filesystem;

namespace sfx {

const char* sfx_version() { return SFX_VERSION; }

namespace {

using strict_yaml::line_of;

using strict_yaml::check_keys;

std::string scalar(const YAML::Node& n, const std::string& file, const std::string& key) {
    if (!n.IsScalar()) throw InputError(file, line_of(n), key, "expected a single value");
    return n.Scalar();
}

// A scene given as a plain name is a built-in; anything else is a path relative to the sweep.
std::string resolve_scene_name(const std::string& value, const std::string& base_dir) {
    const bool plain = value.find('/') == std::string::npos &&
                       value.find(".yaml") == std::string::npos &&
                       value.find('.') == std::string::npos;
    if (plain) return value;
    fs::path p(value);
    if (p.is_relative()) p = fs::path(base_dir) / p;
    return p.lexically_normal().string();
}

// Sets one workload field from scalar text (through WorkloadConfig's visit); a scene given
// as a path is taken relative to `base_dir`. `key` names it in errors.
void set_workload(WorkloadConfig& w, const std::string& field, const std::string& value,
                  const std::string& base_dir, const std::string& file, int line,
                  const std::string& key) {
    set_workload_field(w, field, value, file, line, key);
    if (field == "scene") w.scene = resolve_scene_name(value, base_dir);
}

Fidelity parse_fidelity_at(const std::string& value, const std::string& file, int line,
                           const std::string& key) {
    try {
        return parse_fidelity(value);
    } catch (const std::exception&) {
        throw InputError(file, line, key, "expected analytic, sampled or full, got '" + value + "'");
    }
}

// Sets a hardware parameter, naming the sweep's dotted key (not the bare path) in errors.
void set_hw_at(HwConfig& c, const std::string& path, const std::string& value,
               const std::string& file, int line, const std::string& key) {
    try {
        set_hw_param(c, path, value, file, line);
    } catch (const InputError& e) {
        throw InputError(file, line, key, e.message());
    }
}

// Each field's text, in visit() order.
struct WorkloadTextCollector {
    std::vector<std::string> values;
    void text(const char*, std::string& value, const char*, const char* const* = nullptr) {
        values.push_back(value);
    }
    template <class T>
    void param(const char*, T& value, const char*, const char*, uint64_t, uint64_t,
               const char* = nullptr) {
        values.push_back(std::to_string(value));
    }
};

// A resolved workload and fidelity as text: equal texts, one render.
std::string workload_identity(const WorkloadConfig& w, Fidelity fidelity) {
    WorkloadTextCollector fields;
    const_cast<WorkloadConfig&>(w).visit(fields);  // the collector only reads
    std::string text = to_string(fidelity);
    for (const std::string& v : fields.values) text += '\n' + v;
    return text;
}

std::string too_many(size_t max_points, const char* what) {
    return std::string("more than ") + std::to_string(max_points) + " " + what +
           " (sfx sweep --max-points raises the limit)";
}

struct Axis {
    std::string section = "axes";  // the file's key above it, for messages ("knobs" in explores)
    std::string path;   // "hw.simd.width", "workload.tile", "fidelity"
    std::string field;  // the path below hw./workload.
    enum Kind { hw, workload, fidelity } kind = hw;
    int line = 0;
    std::vector<std::string> values;
    std::vector<int> value_lines;
};

// Values of one axis: a list of scalars, {values: [...]} or {from, to, step}.
void read_axis_values(Axis& axis, const YAML::Node& node, const std::string& file,
                      size_t max_points) {
    const std::string key = axis.section + "." + axis.path;
    YAML::Node list = node;
    if (node.IsMap() && node["values"]) {
        check_keys(node, file, key, {"values"});
        list = node["values"];
    }
    if (list.IsSequence()) {
        if (list.size() == 0) throw InputError(file, line_of(list), key, "an axis needs at least one value");
        for (size_t i = 0; i < list.size(); ++i) {
            axis.values.push_back(scalar(list[i], file, key + "[" + std::to_string(i) + "]"));
            axis.value_lines.push_back(line_of(list[i]));
        }
        return;
    }
    if (!node.IsMap())
        throw InputError(file, line_of(node), key,
                         "expected a list of values, {values: [...]} or {from, to, step}");
    check_keys(node, file, key, {"from", "to", "step"});
    for (const char* k : {"from", "to", "step"})
        if (!node[k]) throw InputError(file, line_of(node), key + "." + k, "missing (a range needs from, to and step)");
    // A range's bounds are numbers, so plain scalars (base/strict_yaml.h); axis values are
    // text, as on the command line (--set), and checked by the field they set.
    for (const char* k : {"from", "to", "step"})
        if (node[k].IsScalar() && !strict_yaml::is_plain_scalar(node[k]))
            throw InputError(file, line_of(node[k]), key + "." + k, "expected a number");
    const std::string from = scalar(node["from"], file, key + ".from");
    const std::string to = scalar(node["to"], file, key + ".to");
    const std::string step = scalar(node["step"], file, key + ".step");
    const int line = line_of(node);
    uint64_t ifrom = 0, ito = 0, istep = 0;
    if (parse_unsigned(from, ifrom) && parse_unsigned(to, ito) && parse_unsigned(step, istep)) {
        if (istep == 0) throw InputError(file, line_of(node["step"]), key + ".step", "must be positive");
        if (ito < ifrom) throw InputError(file, line_of(node["to"]), key + ".to", "must not be below from");
        if ((ito - ifrom) / istep >= max_points)
            throw InputError(file, line, key, too_many(max_points, "values"));
        for (uint64_t v = ifrom; v <= ito; v += istep) {
            axis.values.push_back(std::to_string(v));
            axis.value_lines.push_back(line);
        }
        return;
    }
    double dfrom = 0, dto = 0, dstep = 0;
    if (!parse_finite(from, dfrom)) throw InputError(file, line_of(node["from"]), key + ".from", "expected a number");
    if (!parse_finite(to, dto)) throw InputError(file, line_of(node["to"]), key + ".to", "expected a number");
    if (!parse_finite(step, dstep) || dstep <= 0)
        throw InputError(file, line_of(node["step"]), key + ".step", "expected a positive number");
    if (dto < dfrom) throw InputError(file, line_of(node["to"]), key + ".to", "must not be below from");
    // Inclusive of `to` up to rounding: 0.1 to 0.3 step 0.1 has three values.
    const double count = std::floor((dto - dfrom) / dstep * (1 + 1e-12) + 1e-9) + 1;
    if (count > double(max_points))
        throw InputError(file, line, key, too_many(max_points, "values"));
    for (uint64_t i = 0; i < uint64_t(count); ++i) {
        axis.values.push_back(shortest_text(dfrom + double(i) * dstep));
        axis.value_lines.push_back(line);
    }
}

}  // namespace

// The parsed sweep (base, axes, dimensions) that expands it and makes its points.
class SweepExpansion {
public:
    SweepExpansion(std::string file, std::string base_dir, size_t max_points)
        : m_file(std::move(file)), m_base_dir(std::move(base_dir)), m_max_points(max_points) {}

    Sweep parse(const std::string& text, const std::vector<std::string>& sets) {
        const YAML::Node root = parse_yaml_document(text, m_file);
        if (!root.IsMap()) throw InputError(m_file, line_of(root), "(top level)", "expected a mapping");
        check_keys(root, m_file, "",
                   {"version", "name", "hw", "hw_overrides", "workload", "fidelity", "axes", "zip"});
        if (!root["version"]) throw InputError(m_file, 1, "version", "missing (this format is version: 1)");
        if (scalar(root["version"], m_file, "version") != "1")
            throw InputError(m_file, line_of(root["version"]), "version", "only version 1 is supported");

        Sweep sweep;
        sweep.file = m_file;
        sweep.name = root["name"] ? scalar(root["name"], m_file, "name") : default_name();
        read_hw(root);
        read_workload(root);
        if (root["fidelity"])
            m_fidelity = parse_fidelity_at(scalar(root["fidelity"], m_file, "fidelity"), m_file,
                                           line_of(root["fidelity"]), "fidelity");
        apply_sets(sets);
        if (root["axes"]) read_axes(root["axes"]);
        read_zip(root["zip"]);
        for (const Axis& a : m_axes) sweep.axes.push_back(a.path);
        expand(sweep);
        return sweep;
    }

    // An explore file's space: its base (hw, hw_overrides, workload without a scene), the
    // scenes of `workloads` as the first axis and the `knobs` (hardware paths) as the others.
    // The caller has checked the explore's own keys.
    Sweep parse_space(const YAML::Node& root, const std::string& name, Fidelity fidelity,
                      const std::vector<std::string>& sets) {
        Sweep sweep;
        sweep.file = m_file;
        sweep.name = name;
        read_hw(root);
        Axis scenes;
        scenes.path = "workload.scene";
        scenes.field = "scene";
        scenes.kind = Axis::workload;
        scenes.section = "workloads";
        const YAML::Node list = root["workloads"];
        scenes.line = line_of(list);
        for (size_t i = 0; i < list.size(); ++i) {
            const std::string key = "workloads[" + std::to_string(i) + "].scene";
            scenes.values.push_back(scalar(list[i]["scene"], m_file, key));
            scenes.value_lines.push_back(line_of(list[i]["scene"]));
        }
        m_workload.scene = scenes.values.at(0);
        read_workload(root, false);
        apply_sets(sets);
        m_fidelity = fidelity;
        for (size_t i = 0; i < scenes.values.size(); ++i) apply(scenes, i, m_base, m_workload, m_fidelity, true);
        m_axes.push_back(std::move(scenes));
        read_axes(root["knobs"], "knobs");
        read_zip(root["zip"]);  // none: the explore's keys have no zip
        for (const Axis& a : m_axes) {
            sweep.axes.push_back(a.path);
            sweep.axis_choices.push_back(a.values);
        }
        expand(sweep);
        return sweep;
    }

private:
    std::string default_name() const {
        std::string n = fs::path(m_file).filename().string();
        const std::string suffix = ".sweep.yaml";
        if (n.size() > suffix.size() && n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
            n.resize(n.size() - suffix.size());
        return n;
    }

    void read_hw(const YAML::Node& root) {
        if (!root["hw"]) throw InputError(m_file, 1, "hw", "missing (a base hardware file, e.g. gr08.hw.yaml)");
        const std::string value = scalar(root["hw"], m_file, "hw");
        fs::path p(value);
        if (p.is_relative()) p = fs::path(m_base_dir) / p;
        std::error_code ec;
        // A plain name that is no file beside the sweep is a preset, as on the command line.
        if (is_shipped_name(value) && !fs::exists(p, ec)) {
            const std::vector<std::string> presets = builtin_preset_names();
            if (std::find(presets.begin(), presets.end(), value) == presets.end()) {
                std::string list;
                for (const std::string& n : presets) list += (list.empty() ? "" : ", ") + n;
                throw InputError(m_file, line_of(root["hw"]), "hw",
                                 "no such file or preset: '" + value + "' (presets: " + list + ")");
            }
            m_base = load_hw_config(value);
        } else if (!fs::is_regular_file(p, ec)) {
            throw InputError(m_file, line_of(root["hw"]), "hw", "no such file: " + p.string());
        } else {
            m_base = load_hw_config(p.string());  // errors inside it name that file
        }
        const YAML::Node over = root["hw_overrides"];
        if (!over) return;
        if (!over.IsMap())
            throw InputError(m_file, line_of(over), "hw_overrides", "expected a mapping of dotted parameter paths to values");
        apply_overrides(over);
    }

    // An explore's scenes are its `workloads`: its workload has none (scene_here false).
    void read_workload(const YAML::Node& root, bool scene_here = true) {
        const YAML::Node w = root["workload"];
        if (!w) {
            if (!scene_here) return;
            throw InputError(m_file, 1, "workload", "missing (at least workload.scene)");
        }
        if (!w.IsMap()) throw InputError(m_file, line_of(w), "workload", "expected a mapping");
        std::vector<std::string> allowed = workload_field_names();
        allowed.push_back("res");
        if (!scene_here) allowed.erase(std::find(allowed.begin(), allowed.end(), "scene"));
        check_keys(w, m_file, "workload", allowed);
        if (scene_here && !w["scene"]) throw InputError(m_file, line_of(w), "workload.scene", "missing");
        if (w["res"] && (w["width"] || w["height"]))
            throw InputError(m_file, line_of(w["res"]), "workload.res", "give res or width/height, not both");
        for (const auto& kv : w) {
            const std::string field = kv.first.as<std::string>();
            set_workload(m_workload, field, scalar(kv.second, m_file, "workload." + field),
                         m_base_dir, m_file, line_of(kv.second), "workload." + field);
            m_workload_lines[field] = line_of(kv.second);
        }
    }

    // Dotted paths below hw (`simd.width: 8`), applied to the base in file order.
    void apply_overrides(const YAML::Node& over) {
        std::set<std::string> seen;
        for (const auto& kv : over) {
            const std::string path = kv.first.as<std::string>();
            const std::string key = "hw_overrides." + path;
            if (!seen.insert(path).second) throw InputError(m_file, line_of(kv.first), key, "duplicate key");
            set_hw_at(m_base, path, scalar(kv.second, m_file, key), m_file, line_of(kv.second), key);
            m_hw_lines[path] = line_of(kv.second);
        }
        check_base();
    }
    void check_base() {
        try {
            check_hw_config(m_base, m_file, m_hw_lines);
        } catch (const InputError& e) {
            throw InputError(m_file, e.line(), "hw_overrides." + e.key(), e.message());
        }
    }

    // Command-line `--set PATH=VALUE`: changes the base point (an axis on PATH still moves it).
    void apply_sets(const std::vector<std::string>& sets) {
        for (const std::string& s : sets) {
            const size_t eq = s.find('=');
            const std::string path = s.substr(0, eq);
            const std::string key = "--set " + path;
            if (eq == std::string::npos || eq == 0)
                throw InputError("command line", 0, "--set", "expected PATH=VALUE, got '" + s + "'");
            const std::string value = s.substr(eq + 1);
            if (path.rfind("hw.", 0) == 0) {
                set_hw_at(m_base, path.substr(3), value, "command line", 0, key);
                try {
                    check_hw_config(m_base, "command line");
                } catch (const InputError& e) {
                    throw InputError("command line", 0, key, e.message());
                }
            } else if (path.rfind("workload.", 0) == 0) {
                const std::string field = path.substr(9);
                if (field == "res" || field == "width" || field == "height") m_workload_lines.erase(field);
                set_workload(m_workload, field, value, fs::current_path().string(), "command line", 0, key);
                m_workload_lines[field] = 0;
            } else if (path == "fidelity") {
                m_fidelity = parse_fidelity_at(value, "command line", 0, key);
            } else {
                throw InputError("command line", 0, key, "a path starts with hw. or workload., or is fidelity");
            }
        }
    }

    // `section` "knobs" (an explore's): hardware paths only.
    void read_axes(const YAML::Node& axes, const std::string& section = "axes") {
        if (!axes.IsMap()) throw InputError(m_file, line_of(axes), section, "expected a mapping of dotted paths to values");
        std::set<std::string> seen;
        for (const auto& kv : axes) {
            Axis axis;
            axis.section = section;
            axis.path = kv.first.as<std::string>();
            axis.line = line_of(kv.first);
            const std::string key = section + "." + axis.path;
            if (!seen.insert(axis.path).second) throw InputError(m_file, axis.line, key, "duplicate " + std::string(section == "axes" ? "axis" : "knob"));
            if (section != "axes" && axis.path.rfind("hw.", 0) != 0)
                throw InputError(m_file, axis.line, key, "a knob is a hardware path: hw.simd.width, hw.ray_buffer.kib, ...");
            if (axis.path.rfind("hw.", 0) == 0) {
                axis.kind = Axis::hw;
                axis.field = axis.path.substr(3);
            } else if (axis.path.rfind("workload.", 0) == 0) {
                axis.kind = Axis::workload;
                axis.field = axis.path.substr(9);
            } else if (axis.path == "fidelity") {
                axis.kind = Axis::fidelity;
            } else {
                throw InputError(m_file, axis.line, key,
                                 "an axis path starts with hw. or workload., or is fidelity");
            }
            read_axis_values(axis, kv.second, m_file, m_max_points);
            // Every value is checked now, on scratch copies, before anything runs.
            for (size_t i = 0; i < axis.values.size(); ++i) apply(axis, i, m_base, m_workload, m_fidelity, true);
            m_axes.push_back(std::move(axis));
        }
        auto has = [&](const char* p) { return seen.count(p) > 0; };
        if (has("workload.res") && (has("workload.width") || has("workload.height")))
            throw InputError(m_file, line_of(axes), "axes.workload.res", "give res or width/height axes, not both");
    }

    void apply(const Axis& axis, size_t i, HwConfig& hw, WorkloadConfig& w, Fidelity& f,
               bool scratch) const {
        // An explore's scenes are items of its workloads list.
        const std::string key = axis.section == "workloads" ? "workloads[" + std::to_string(i) + "].scene"
                                                            : axis.section + "." + axis.path;
        const std::string& value = axis.values[i];
        const int line = axis.value_lines[i];
        if (axis.kind == Axis::hw) {
            HwConfig copy;
            HwConfig& target = scratch ? (copy = hw) : hw;
            set_hw_at(target, axis.field, value, m_file, line, key);
        } else if (axis.kind == Axis::workload) {
            WorkloadConfig copy;
            WorkloadConfig& target = scratch ? (copy = w) : w;
            set_workload(target, axis.field, value, m_base_dir, m_file, line, key);
            if (scratch && axis.field == "scene") scene_info(target.scene, line, key);
        } else {
            const Fidelity parsed = parse_fidelity_at(value, m_file, line, key);
            if (!scratch) f = parsed;
        }
    }

    void read_zip(const YAML::Node& zip) {
        m_dimension_of.assign(m_axes.size(), -1);
        if (zip) {
            if (!zip.IsSequence()) throw InputError(m_file, line_of(zip), "zip", "expected a list of lists of axis paths");
            for (size_t g = 0; g < zip.size(); ++g) {
                const std::string key = "zip[" + std::to_string(g) + "]";
                const YAML::Node group = zip[g];
                if (!group.IsSequence() || group.size() < 2)
                    throw InputError(m_file, line_of(group), key, "expected a list of at least two axis paths");
                std::vector<size_t> members;
                for (size_t k = 0; k < group.size(); ++k) {
                    const std::string path = scalar(group[k], m_file, key);
                    size_t a = 0;
                    while (a < m_axes.size() && m_axes[a].path != path) ++a;
                    if (a == m_axes.size())
                        throw InputError(m_file, line_of(group[k]), key + "." + path, "not an axis of this sweep");
                    if (m_dimension_of[a] >= 0)
                        throw InputError(m_file, line_of(group[k]), key + "." + path, "axis is already zipped");
                    if (m_axes[a].values.size() != m_axes[members.empty() ? a : members[0]].values.size())
                        throw InputError(m_file, line_of(group[k]), key + "." + path,
                                         "zipped axes need equal lengths (" +
                                             std::to_string(m_axes[a].values.size()) + " vs " +
                                             std::to_string(m_axes[members[0]].values.size()) + ")");
                    m_dimension_of[a] = int(g);  // provisional: the zip group number
                    members.push_back(a);
                }
                m_zips.push_back(members);
            }
        }
        // Dimensions in file order of their first axis: a zip group moves as one axis.
        std::vector<int> zip_dimension(m_zips.size(), -1);
        std::vector<int> final_dimension(m_axes.size(), -1);
        for (size_t a = 0; a < m_axes.size(); ++a) {
            const int z = m_dimension_of[a];
            if (z < 0) {
                final_dimension[a] = int(m_dimensions.size());
                m_dimensions.push_back({a});
            } else if (zip_dimension[z] < 0) {
                zip_dimension[z] = int(m_dimensions.size());
                final_dimension[a] = zip_dimension[z];
                m_dimensions.push_back(m_zips[z]);
            } else {
                final_dimension[a] = zip_dimension[z];
            }
        }
    }

    struct SceneInfo {
        FeatureSet features;
        uint32_t primitives = 0;
    };
    const SceneInfo& scene_info(const std::string& scene, int line, const std::string& key) const {
        auto it = m_scenes.find(scene);
        if (it != m_scenes.end()) return it->second;
        try {
            const Scene s = load_scene(scene);
            return m_scenes.emplace(scene, SceneInfo{s.features(), s.primitive_count()}).first->second;
        } catch (const InputError& e) {
            if (e.file() == scene && e.line() == 0) throw InputError(m_file, line, key, e.message());
            throw;  // an error inside the scene file names that file
        }
    }

    // Every point is checked and grouped here, but none is kept: odometer order (the last
    // dimension fastest), re-applying only the dimensions that moved, so a point costs a few
    // microseconds. A point is a duplicate when its group already holds its hardware class:
    // the tuple of its dimensions' first indices with the same hardware values.
    void expand(Sweep& sweep) {
        const size_t dims = m_dimensions.size();
        m_sizes.assign(dims, 0);
        size_t total = 1;
        for (size_t d = 0; d < dims; ++d) {
            m_sizes[d] = m_axes[m_dimensions[d][0]].values.size();
            if (total > m_max_points / m_sizes[d])
                throw InputError(m_file, line_of_axes(), "axes", too_many(m_max_points, "points"));
            total *= m_sizes[d];
        }
        std::vector<size_t> hw_class_of_value_stride(dims, 0);
        std::vector<std::vector<size_t>> hw_class_of_value(dims);
        size_t hw_stride = 1;
        for (size_t d = dims; d-- > 0;) {
            bool has_hw = false;
            for (size_t a : m_dimensions[d]) has_hw |= m_axes[a].kind == Axis::hw;
            if (!has_hw) continue;
            std::map<std::string, size_t> first;
            for (size_t i = 0; i < m_sizes[d]; ++i) {
                std::string values;
                for (size_t a : m_dimensions[d])
                    if (m_axes[a].kind == Axis::hw) {
                        // "8" and "8.0" set the same number: equal values, one class.
                        double x = 0;
                        const std::string& v = m_axes[a].values[i];
                        values += (parse_finite(v, x) ? shortest_text(x) : v) + '\n';
                    }
                hw_class_of_value[d].push_back(first.emplace(values, i).first->second);
            }
            hw_class_of_value_stride[d] = hw_stride;
            hw_stride *= m_sizes[d];
        }

        HwConfig hw = m_base;
        WorkloadConfig w = m_workload;
        Fidelity f = m_fidelity;
        std::vector<size_t> at(dims, 0);
        size_t first_moved = 0;  // dimensions from here on take new values
        WorkloadConfig resolved;
        size_t group = 0;
        std::map<std::string, size_t> group_of_workload;
        std::vector<std::unordered_set<uint64_t>> classes_of_group;
        for (size_t n = 0; n < total; ++n) {
            bool hw_moved = n == 0, workload_moved = n == 0;
            for (size_t d = first_moved; d < dims; ++d)
                for (size_t a : m_dimensions[d]) {
                    apply(m_axes[a], at[d], hw, w, f, false);
                    (m_axes[a].kind == Axis::hw ? hw_moved : workload_moved) = true;
                }
            if (hw_moved) {
                check_point_hw(hw, n, at);
                if (hw.clock.core_written || hw.clock.interconnect_written) {
                    HwConfig clocked = hw;  // a written clock above its node's: said once
                    for (std::string& warning : resolve_node_clocks(clocked))
                        if (std::find(sweep.warnings.begin(), sweep.warnings.end(), warning) ==
                            sweep.warnings.end())
                            sweep.warnings.push_back(std::move(warning));
                }
            }
            if (hw_moved || workload_moved) {
                const SceneInfo& scene = scene_info(w.scene, line_at(at, "scene"), "workload.scene");
                WorkloadConfig r = resolve(w, hw, scene.features, n, at);
                if (n == 0 || !(r == resolved) || f != sweep.groups[group].fidelity) {
                    resolved = std::move(r);
                    const std::string identity = workload_identity(resolved, f);
                    auto [it, added] = group_of_workload.emplace(identity, sweep.groups.size());
                    if (added) {
                        sweep.groups.push_back({{}, resolved, f, scene.primitives});
                        classes_of_group.emplace_back();
                    }
                    group = it->second;
                }
            }
            uint64_t hw_class = 0;
            for (size_t d = 0; d < dims; ++d)
                if (!hw_class_of_value[d].empty()) hw_class += hw_class_of_value[d][at[d]] * hw_class_of_value_stride[d];
            if (classes_of_group[group].insert(hw_class).second)
                sweep.groups[group].points.push_back(n);
            else
                ++sweep.duplicates;
            // Odometer: the last dimension moves fastest.
            for (size_t d = dims; d-- > 0;) {
                if (++at[d] < m_sizes[d]) {
                    first_moved = d;
                    break;
                }
                at[d] = 0;
            }
        }
        sweep.point_count = total - sweep.duplicates;
    }

public:
    // One point, made again from its expansion index (checked when the sweep was expanded).
    SweepPoint point(size_t n) const {
        const size_t dims = m_dimensions.size();
        const std::vector<size_t> at = position(n);
        SweepPoint p;
        p.index = n;
        p.hw = m_base;
        WorkloadConfig w = m_workload;
        p.fidelity = m_fidelity;
        for (size_t d = 0; d < dims; ++d)
            for (size_t a : m_dimensions[d]) {
                apply(m_axes[a], at[d], p.hw, w, p.fidelity, false);
                p.axis_values.emplace_back(m_axes[a].path, m_axes[a].values[at[d]]);
            }
        resolve_node_clocks(p.hw);  // clocks not written follow the point's node
        p.workload = resolve(w, p.hw, scene_info(w.scene, 0, "workload.scene").features, n, at);
        p.config_yaml = point_config_yaml(p.hw, p.workload, p.fidelity);
        p.key = point_key(p.config_yaml);
        return p;
    }

    std::vector<std::pair<std::string, std::string>> axis_values(size_t n) const {
        const std::vector<size_t> at = position(n);
        std::vector<std::pair<std::string, std::string>> out;
        for (size_t d = 0; d < at.size(); ++d)
            for (size_t a : m_dimensions[d]) out.emplace_back(m_axes[a].path, m_axes[a].values[at[d]]);
        return out;
    }

private:
    // Each dimension's value index at expansion index n (the last dimension fastest).
    std::vector<size_t> position(size_t n) const {
        std::vector<size_t> at(m_dimensions.size(), 0);
        for (size_t d = at.size(); d-- > 0;) {
            at[d] = n % m_sizes[d];
            n /= m_sizes[d];
        }
        return at;
    }

    int line_of_axes() const { return m_axes.empty() ? 0 : m_axes.front().line; }

    // The line of a hardware or workload field at a point: its axis value's, else the base's.
    int line_at(const std::vector<size_t>& at, const std::string& field, bool hw = false) const {
        for (size_t d = 0; d < at.size(); ++d)
            for (size_t a : m_dimensions[d])
                if (m_axes[a].field == field && (m_axes[a].kind == Axis::hw) == hw)
                    return m_axes[a].value_lines[at[d]];
        const auto& lines = hw ? m_hw_lines : m_workload_lines;
        auto it = lines.find(field);
        return it == lines.end() ? 0 : it->second;
    }

    std::string describe(size_t n, const std::vector<size_t>& at) const {
        std::string s;
        for (size_t d = 0; d < at.size(); ++d)
            for (size_t a : m_dimensions[d])
                s += (s.empty() ? "" : ", ") + m_axes[a].path + "=" + m_axes[a].values[at[d]];
        return "at point " + std::to_string(n) + ": " + (s.empty() ? "the base point" : s);
    }

    void check_point_hw(const HwConfig& hw, size_t n, const std::vector<size_t>& at) const {
        try {
            check_hw_config(hw, m_file);
        } catch (const InputError&) {
            // Failures only: the lines of this point's values, for the message.
            HwLineMap lines = m_hw_lines;
            for (size_t d = 0; d < at.size(); ++d)
                for (size_t a : m_dimensions[d])
                    if (m_axes[a].kind == Axis::hw) lines[m_axes[a].field] = m_axes[a].value_lines[at[d]];
            try {
                check_hw_config(hw, m_file, lines);
            } catch (const InputError& e) {
                throw InputError(m_file, e.line() > 0 ? e.line() : line_of_axes(), "hw." + e.key(),
                                 e.message() + " (" + describe(n, at) + ")");
            }
            throw;
        }
    }

    // tile: auto is resolved per point (its own buffer), so a buffer-size axis changes the
    // tile; points then group by the resolved tile.
    WorkloadConfig resolve(const WorkloadConfig& w, const HwConfig& hw, const FeatureSet& features,
                           size_t n, const std::vector<size_t>& at) const {
        try {
            return resolve_workload(w, features, {hw}, "workload.tile").config;
        } catch (const InputError& e) {
            throw InputError(m_file, line_at(at, "tile"), "workload.tile",
                             e.message() + " (" + describe(n, at) + ")");
        }
    }

    std::string m_file, m_base_dir;
    size_t m_max_points;
    HwConfig m_base;
    HwLineMap m_hw_lines;
    WorkloadConfig m_workload;
    std::map<std::string, int> m_workload_lines;
    Fidelity m_fidelity = Fidelity::full;
    std::vector<Axis> m_axes;
    std::vector<int> m_dimension_of;
    std::vector<std::vector<size_t>> m_zips;
    std::vector<std::vector<size_t>> m_dimensions;  // axes moving together, outermost first
    std::vector<size_t> m_sizes;                    // values per dimension
    mutable std::map<std::string, SceneInfo> m_scenes;
};

Sweep parse_sweep(const std::string& text, const std::string& file, const std::string& base_dir,
                  const std::vector<std::string>& sets, size_t max_points) {
    auto expansion = std::make_shared<SweepExpansion>(file, base_dir, max_points);
    Sweep sweep = expansion->parse(text, sets);
    sweep.expansion = std::move(expansion);
    return sweep;
}

Sweep parse_explore_space(const YAML::Node& root, const std::string& name, Fidelity fidelity,
                          const std::string& file, const std::string& base_dir,
                          const std::vector<std::string>& sets, size_t max_points) {
    auto expansion = std::make_shared<SweepExpansion>(file, base_dir, max_points);
    Sweep sweep = expansion->parse_space(root, name, fidelity, sets);
    sweep.expansion = std::move(expansion);
    return sweep;
}

Sweep load_sweep(const std::string& path, const std::vector<std::string>& sets, size_t max_points) {
    const std::string text = read_input_file(path, "sweep file");
    const fs::path dir = fs::absolute(fs::path(path)).parent_path();
    return parse_sweep(text, path, dir.string(), sets, max_points);
}

SweepPoint Sweep::point(size_t index) const { return expansion->point(index); }

std::vector<std::pair<std::string, std::string>> Sweep::axis_values(size_t index) const {
    return expansion->axis_values(index);
}

std::vector<size_t> Sweep::point_indices() const {
    std::vector<size_t> out;
    out.reserve(point_count);
    for (const PointGroup& g : groups) out.insert(out.end(), g.points.begin(), g.points.end());
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<SweepPoint> Sweep::all_points() const {
    std::vector<SweepPoint> out;
    for (size_t i : point_indices()) out.push_back(point(i));
    return out;
}

namespace {
// Writes each workload field as YAML: the scene double-quoted, numbers as they are.
// Option fields (WorkloadConfig::is_option_field) are written only when they differ from their
// default, so points of workloads without the option keep the text, and the key, they had
// before the option existed.
struct WorkloadYamlWriter {
    std::string& out;
    std::vector<std::string> default_text;  // per field in visit() order, of `defaults`
    size_t field = 0;

    void write(const char* name, const std::string& value, bool quoted) {
        const size_t i = field++;
        if (i < default_text.size() && WorkloadConfig::is_option_field(name) &&
            default_text[i] == value)
            return;
        out += std::string("  ") + name + ": " + (quoted ? strict_yaml::double_quoted(value) : value) + "\n";
    }
    void text(const char* name, std::string& value, const char*, const char* const* = nullptr) {
        write(name, value, true);
    }
    template <class T>
    void param(const char* name, T& value, const char*, const char*, uint64_t, uint64_t,
               const char* = nullptr) {
        write(name, std::to_string(value), false);
    }
};

}  // namespace

std::string point_config_yaml(const HwConfig& hw, const WorkloadConfig& w, Fidelity fidelity) {
    // Values only, in a fixed order: the key must not change when a description does. Written
    // directly, not through yaml-cpp's emitter: a sweep writes one per point.
    std::string out = "hw:\n" + hw_config_values_yaml(hw, 2) + "workload:\n";
    static const std::vector<std::string> defaults = [] {
        WorkloadTextCollector c;
        WorkloadConfig().visit(c);
        return c.values;
    }();
    WorkloadYamlWriter writer{out, defaults};
    const_cast<WorkloadConfig&>(w).visit(writer);  // the writer only reads
    return out + "fidelity: " + to_string(fidelity) + "\n";
}

std::string point_key(const std::string& config_yaml) {
    return sha256_hex(config_yaml + "\n" + sfx_version());
}

ParsedPoint parse_point_config(const std::string& text, const std::string& file) {
    const YAML::Node root = parse_yaml_document(text, file);
    if (!root.IsMap()) throw InputError(file, line_of(root), "(top level)", "expected a mapping");
    check_keys(root, file, "", {"hw", "workload", "fidelity"});
    for (const char* k : {"hw", "workload", "fidelity"})
        if (!root[k]) throw InputError(file, 1, k, "missing");
    ParsedPoint p;
    // The hw section is a whole configuration, as hw_config_values_yaml writes it.
    p.hw = hw_config_from_yaml(root["hw"], file + " (hw)");

    const YAML::Node w = root["workload"];
    if (!w.IsMap()) throw InputError(file, line_of(w), "workload", "expected a mapping");
    const std::vector<std::string> fields = workload_field_names();
    check_keys(w, file, "workload", fields);
    for (const std::string& k : fields) {
        const std::string key = "workload." + k;
        if (!w[k]) {
            if (WorkloadConfig::is_option_field(k)) continue;  // absent: the default
            throw InputError(file, line_of(w), key, "missing");
        }
        // The scene is stored resolved (a built-in name or an absolute path): taken as is.
        set_workload_field(p.workload, k, scalar(w[k], file, key), file, line_of(w[k]), key);
    }
    if (p.workload.tile == WorkloadConfig::k_auto_tile)
        throw InputError(file, line_of(w["tile"]), "workload.tile", "must be resolved, not auto");
    p.fidelity = parse_fidelity_at(scalar(root["fidelity"], file, "fidelity"), file,
                                   line_of(root["fidelity"]), "fidelity");
    return p;
}

}  // namespace sfx
