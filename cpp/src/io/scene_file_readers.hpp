#pragma once
// What the scene-file readers (obj_file.cpp, gltf_file.cpp) share: errors that name the file,
// path helpers, limits against absurd files, and the readers themselves (private to the io module).
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mipraster/io/scene_file.hpp"

namespace mipraster {
namespace scene_files {

/// Limits against absurd files: a mesh's vertex and triangle counts must fit the 32-bit indices.
constexpr std::size_t kMaxElements = std::numeric_limits<std::uint32_t>::max();
static_assert(kMaxElements > 0, "limits must be positive");

/// The folder of a path, with its trailing slash ("./" for a bare file name).
inline std::string directory_of(const std::string& path) {
    const auto slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string("./") : path.substr(0, slash + 1);
}

[[noreturn]] inline void fail(const std::string& path, const std::string& problem) {
    throw std::runtime_error(path + ": " + problem);
}

/// s without trailing line ends and spaces.
inline std::string trim(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
    return s;
}

/// Each non-empty line of a reader library's warning text, prefixed with the file.
inline void add_warnings(std::vector<std::string>& out, const std::string& path, const std::string& text) {
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) {
        line = trim(line);
        if (!line.empty()) out.push_back(path + ": " + line);
    }
}

/// A Wavefront OBJ file and its MTL files (obj_file.cpp).
LoadedScene load_obj(const std::string& path);
/// A glTF 2.0 file, .gltf (binary = false) or .glb (gltf_file.cpp).
LoadedScene load_gltf(const std::string& path, bool binary);

}  // namespace scene_files
}  // namespace mipraster
