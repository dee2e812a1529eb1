#pragma once
// Strict YAML: the scalar rules of every YAML reader (scenes, hardware configurations,
// technology tables, sweeps), and the reader of any struct described by a visit() (param /
// choice / group / list): every key must be visited, every value must parse and lie in range;
// errors name file, line and dotted key.
//
// The rules: a number or a boolean is a plain scalar (a quoted '1' is text); its whole text is
// the number, decimal only (base/strict_number.h); YAML's .inf and .nan, and decimal text beyond
// the double range, are numbers that are not finite, and refused as such.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "base/input_error.h"
#include "base/strict_number.h"

namespace sfx {

namespace strict_yaml {

// A scalar written without quotes: only those can be numbers or booleans.
inline bool is_plain_scalar(const YAML::Node& n) {
    return n.IsScalar() && n.Tag() != "!";
}

enum class NumberText { finite, not_finite, not_a_number };

// Reads a plain scalar as a finite number, saying why it is not one.
inline NumberText read_finite(const YAML::Node& n, double& out) {
    if (!is_plain_scalar(n)) return NumberText::not_a_number;
    const std::string& s = n.Scalar();
    if (parse_finite(s, out)) return NumberText::finite;
    static const std::set<std::string> k_yaml_non_finite = {
        ".inf", ".Inf", ".INF", "+.inf", "+.Inf", "+.INF", "-.inf", "-.Inf", "-.INF",
        ".nan", ".NaN", ".NAN"};
    char* end = nullptr;
    if (k_yaml_non_finite.count(s) ||
        (is_decimal_text(s) && (std::strtod(s.c_str(), &end), *end == '\0')))
        return NumberText::not_finite;
    return NumberText::not_a_number;
}

// Scalar text <-> typed values, strictly: "16x", "-1" for unsigned, "1e999" are errors.
inline bool parse_scalar(const std::string& s, uint32_t& out) {
    uint64_t v = 0;
    if (!parse_unsigned(s, v) || v > 0xffffffffull) return false;
    out = uint32_t(v);
    return true;
}
inline bool parse_scalar(const std::string& s, double& out) {
    return parse_finite(s, out);
}
inline bool parse_scalar(const std::string& s, bool& out) {
    if (s == "true") {
        out = true;
        return true;
    }
    if (s == "false") {
        out = false;
        return true;
    }
    return false;
}
inline bool parse_scalar(const std::string& s, std::string& out) {
    out = s;
    return true;
}
inline const char* type_name(uint32_t) {
    return "a non-negative integer";
}
inline const char* type_name(double) {
    return "a finite number";
}
inline const char* type_name(bool) {
    return "true or false";
}
inline const char* type_name(const std::string&) {
    return "a string";
}

inline std::string to_text(uint32_t v) {
    return std::to_string(v);
}
inline std::string to_text(bool v) {
    return v ? "true" : "false";
}
inline std::string to_text(const std::string& v) {
    return v;
}
inline std::string to_text(double v) {
    return shortest_text(v);
}

// Text as a YAML double-quoted scalar: backslash, quote and control characters escaped, so any
// string reads back as itself (written without yaml-cpp's emitter, which is slow on hot paths).
inline std::string double_quoted(const std::string& v) {
    std::string out = "\"";
    for (char ch : v) {
        const unsigned char c = static_cast<unsigned char>(ch);
        if (c == '"' || c == '\\') {
            out += '\\';
            out += ch;
        } else if (c < 0x20 || c == 0x7f) {
            static const char* const hex = "0123456789ABCDEF";
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
        } else {
            out += ch;
        }
    }
    return out + "\"";
}

template <class T>
bool in_range(const T& v, const T& lo, const T& hi) {
    return v >= lo && v <= hi;
}

inline int line_of(const YAML::Node& n) {
    return n.Mark().line >= 0 ? n.Mark().line + 1 : 0;
}

inline std::string join(const std::string& prefix, const std::string& name) {
    return prefix.empty() ? name : prefix + "." + name;
}

// Checks a mapping's keys against the allowed ones: an unknown key (the allowed ones listed)
// or a repeated key is an InputError naming file, line and dotted key. The one key rule of
// every reader: scenes, sweeps, and hardware configurations (YamlReader::finish).
inline void check_keys(const YAML::Node& map, const std::string& file, const std::string& prefix,
                       const std::vector<std::string>& allowed) {
    std::set<std::string> seen;
    for (const auto& kv : map) {
        const std::string key = kv.first.Scalar();
        const std::string dotted = join(prefix, key);
        if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
            std::string list;
            for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
            throw InputError(file, line_of(kv.first), dotted,
                             "unknown key (allowed: " + list + ")");
        }
        if (!seen.insert(key).second)
            throw InputError(file, line_of(kv.first), dotted, "duplicate key");
    }
}

// Reads a YAML map into a config: every key must be visited, every value must parse and lie
// in range. Absent keys keep their defaults.
class YamlReader {
  public:
    YamlReader(const YAML::Node& node, std::string file, std::string prefix,
               std::map<std::string, int>& lines)
        : m_node(node), m_file(std::move(file)), m_prefix(std::move(prefix)), m_lines(lines) {
        if (!m_node.IsMap())
            throw InputError(m_file, line_of(m_node), m_prefix.empty() ? "(top level)" : m_prefix,
                             "expected a mapping of keys to values");
    }

    template <class T, class B>
    void param(const char* name, T& value, const char*, const char*, B lo, B hi) {
        if (read(name, value) && !in_range(value, T(lo), T(hi)))
            throw InputError(m_file, line_of(m_node[name]), join(m_prefix, name),
                             "value " + to_text(value) + " is outside [" + to_text(T(lo)) + ", " +
                                 to_text(T(hi)) + "]");
    }
    template <class T>
    void param(const char* name, T& value, const char*, const char*) {
        read(name, value);
    }
    void choice(const char* name, std::string& value, std::initializer_list<const char*> allowed,
                const char*) {
        if (!read(name, value)) return;
        std::string list;
        for (const char* a : allowed) {
            if (value == a) return;
            list += list.empty() ? a : std::string(", ") + a;
        }
        throw InputError(m_file, line_of(m_node[name]), join(m_prefix, name),
                         "'" + value + "' is not one of: " + list);
    }
    template <class G>
    void group(const char* name, G& g) {
        m_seen.insert(name);
        const YAML::Node child = m_node[name];
        if (!child) return;
        m_lines[join(m_prefix, name)] = line_of(child);
        YamlReader r(child, m_file, join(m_prefix, name), m_lines);
        g.visit(r);
        r.finish();
    }
    template <class G>
    void list(const char* name, std::vector<G>& items, const char*) {
        m_seen.insert(name);
        const YAML::Node child = m_node[name];
        if (!child) return;
        if (!child.IsSequence())
            throw InputError(m_file, line_of(child), join(m_prefix, name), "expected a list");
        m_lines[join(m_prefix, name)] = line_of(child);
        items.assign(child.size(), G{});
        for (size_t i = 0; i < child.size(); ++i) {
            const std::string item = join(m_prefix, name) + "[" + std::to_string(i) + "]";
            m_lines[item] = line_of(child[i]);
            YamlReader r(child[i], m_file, item, m_lines);
            items[i].visit(r);
            r.finish();
        }
    }
    void finish() const {
        check_keys(m_node, m_file, m_prefix,
                   std::vector<std::string>(m_seen.begin(), m_seen.end()));
    }

  private:
    template <class T>
    bool read(const char* name, T& value) {
        m_seen.insert(name);
        const YAML::Node child = m_node[name];
        if (!child) return false;
        // Numbers and booleans must be plain scalars; a string may be quoted.
        const bool typed_scalar = std::is_same<T, std::string>::value ? child.IsScalar()
                                                                      : is_plain_scalar(child);
        if (!typed_scalar || !parse_scalar(child.Scalar(), value))
            throw InputError(m_file, line_of(child), join(m_prefix, name),
                             std::string("expected ") + type_name(value));
        m_lines[join(m_prefix, name)] = line_of(child);
        return true;
    }

    // A copy (a handle): group() and list() pass temporaries.
    const YAML::Node m_node;
    std::string m_file, m_prefix;
    std::map<std::string, int>& m_lines;
    std::set<std::string> m_seen;
};

}  // namespace strict_yaml
}  // namespace sfx
