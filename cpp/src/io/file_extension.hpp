#pragma once
// The lower-case extension of a path, shared by the io module's file readers and writers.
#include <cctype>
#include <string>

namespace mipraster {

/// ".png" for "dir/Image.PNG"; empty when the last path component has no dot.
inline std::string lower_extension(const std::string& path) {
    const std::size_t slash = path.find_last_of("/\\");
    const std::size_t dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot);
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace mipraster
