#pragma once
// Strict number text, for every parser of user input (scenes, hardware files, sweeps, flags):
// the whole text must be the number ("16x", "-1" as unsigned, "1e999" are not), and doubles
// print as the shortest text that reads back as the same value.

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace sfx {

inline bool parse_unsigned(const std::string& s, uint64_t& out) {
    if (s.empty() || s[0] == '-' || s[0] == '+') return false;
    char* end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
    if (errno || *end != '\0') return false;
    out = v;
    return true;
}

inline bool parse_finite(const std::string& s, double& out) {
    if (s.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s.c_str(), &end);
    if (errno || *end != '\0' || !std::isfinite(v)) return false;
    out = v;
    return true;
}

inline std::string shortest_text(double v) {
    char buf[64];
    for (int precision = 1; precision <= 17; ++precision) {
        std::snprintf(buf, sizeof buf, "%.*g", precision, v);
        if (std::strtod(buf, nullptr) == v) break;
    }
    return buf;
}

}  // namespace sfx
