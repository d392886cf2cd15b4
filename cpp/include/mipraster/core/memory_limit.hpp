#pragma once
// Bounded memory: before a render or a texture allocates anything large, it estimates the bytes
// and refuses above a process-wide, configurable limit, with an error that gives both numbers.
#include <cstdint>
#include <stdexcept>
#include <string>

namespace mipraster {

/// The limit a fresh process starts with.
inline constexpr std::uint64_t kDefaultMemoryLimit = std::uint64_t{16} << 30;

/// The current limit in bytes.
std::uint64_t memory_limit();

/// Sets the limit for the whole process (thread-safe); 0 restores kDefaultMemoryLimit.
void set_memory_limit(std::uint64_t bytes);

/// Work refused because its estimate exceeds memory_limit(). A std::invalid_argument, so
/// callers that report bad input (the CLI, ValueError in Python) report it too.
class MemoryLimitError : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

/// "1.5 GiB", "512 MiB", "12 KiB", "100 bytes": binary units, three significant digits.
std::string format_bytes(std::uint64_t bytes);

/// Throws MemoryLimitError("<what> needs <bytes>; the memory limit is <limit> ...") when bytes
/// exceeds memory_limit().
void check_memory(std::uint64_t bytes, const std::string& what);

}  // namespace mipraster
