#include "mipraster/core/memory_limit.hpp"

#include <atomic>
#include <cstdio>

namespace mipraster {

namespace {
std::atomic<std::uint64_t> g_limit{kDefaultMemoryLimit};
}  // namespace

std::uint64_t memory_limit() { return g_limit.load(std::memory_order_relaxed); }

void set_memory_limit(std::uint64_t bytes) {
    g_limit.store(bytes == 0 ? kDefaultMemoryLimit : bytes, std::memory_order_relaxed);
}

std::string format_bytes(std::uint64_t bytes) {
    static const char* const kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
    double value = static_cast<double>(bytes) / 1024.0;
    int unit = 0;
    while (value >= 1024.0 && unit + 1 < 6) {
        value /= 1024.0;
        ++unit;
    }
    char text[32];
    std::snprintf(text, sizeof text, value < 10.0 ? "%.2f %s" : value < 100.0 ? "%.1f %s" : "%.0f %s", value,
                  kUnits[unit]);
    return text;
}

void check_memory(std::uint64_t bytes, const std::string& what) {
    const std::uint64_t limit = memory_limit();
    if (bytes <= limit) return;
    throw MemoryLimitError(what + " needs " + format_bytes(bytes) + " (" + std::to_string(bytes) +
                           " bytes); the memory limit is " + format_bytes(limit) +
                           " (raise it with set_memory_limit, or --memory-limit in the CLI)");
}

}  // namespace mipraster
