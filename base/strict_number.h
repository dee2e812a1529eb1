#pragma once
// Strict number text, for every parser of user input (scenes, hardware files, technology
// tables, sweeps, flags): plain decimal only, and the whole text must be the number ("16x",
// "-1" as unsigned, "+1", "0x10", "inf", "1e999" are not). Doubles print as the shortest text
// that reads back as the same value.

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace sfx {

inline bool parse_unsigned(const std::string& s, uint64_t& out) {
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos) return false;
    char* end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
    if (errno || *end != '\0') return false;
    out = v;
    return true;
}

// Digits with an optional leading '-' (no '+': one spelling per number).
inline bool parse_signed(const std::string& s, int64_t& out) {
    const size_t digits = s[0] == '-' ? 1 : 0;
    if (s.size() <= digits || s.find_first_not_of("0123456789", digits) != std::string::npos)
        return false;
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(s.c_str(), &end, 10);
    if (errno || *end != '\0') return false;
    out = v;
    return true;
}

// Text made of what a decimal number may hold: strtod alone would also read hex, "inf", "nan".
inline bool is_decimal_text(const std::string& s) {
    return !s.empty() && s[0] != '+' && s.find_first_not_of("0123456789+-.eE") == std::string::npos;
}

inline bool parse_finite(const std::string& s, double& out) {
    if (!is_decimal_text(s)) return false;
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
