#pragma once
// Option parsing shared by the benchmark programs of cpp/apps/.
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace mipraster {
namespace apps {

/// Parses a whole decimal integer ≥ lo into `out`; false (out unchanged) for anything else.
inline bool parse_count(const char* text, long long lo, long long& out) {
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(text, &end, 10);
    if (errno || end == text || *end != '\0' || v < lo) return false;
    out = v;
    return true;
}

/// Prints "program: message", a blank line and the usage to stderr; returns exit status 2.
inline int usage_error(const char* program, const std::string& message, const char* usage) {
    std::fprintf(stderr, "%s: %s\n\n%s", program, message.c_str(), usage);
    return 2;
}

}  // namespace apps
}  // namespace mipraster
