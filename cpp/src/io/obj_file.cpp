// Wavefront OBJ and MTL files: the text checked and rewritten for tinyobjloader (which reads the
// geometry), MTL files read here, polygons triangulated here. The only file that includes
// tinyobjloader.
#include "scene_file_readers.hpp"

#include "mipraster/core/constants.hpp"
#include "mipraster/io/image_io.hpp"
#include "mipraster/io/texture_file.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <tiny_obj_loader.h>

namespace mipraster {
namespace scene_files {

namespace {

/// One OBJ face corner: position, texture coordinate and normal indices (−1: none).
struct ObjCorner {
    int v = -1, t = -1, n = -1;
    bool operator==(const ObjCorner& o) const { return v == o.v && t == o.t && n == o.n; }
};

struct ObjCornerHash {
    std::size_t operator()(const ObjCorner& c) const {
        std::uint64_t h = static_cast<std::uint32_t>(c.v);
        h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(c.t);
        h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(c.n);
        return static_cast<std::size_t>(h ^ (h >> 29));
    }
};

/// The triangles of one OBJ draw: a material's faces (textured materials split into the faces
/// with texture coordinates, drawn textured, and those without).
struct ObjGroup {
    int material = -1;
    bool textured = false;
    std::vector<std::array<ObjCorner, 3>> triangles;
    bool all_uvs = true, all_normals = true;  // every corner has one
};

/// tinyobjloader stores a face's corner count in an unsigned char: longer polygons are kept
/// aside by read_obj_source and put back by load_obj.
constexpr std::size_t kMaxTinyobjCorners = std::numeric_limits<unsigned char>::max();
static_assert(kMaxTinyobjCorners >= 4, "quads must pass through tinyobjloader");

/// Polygons of more corners are fanned instead of ear-clipped (right for convex ones, such as a
/// cylinder's cap): ear clipping can take n³ steps, and a hostile face of 10⁵ corners (a 700 KB
/// line) would not finish. A 1024-corner star (the worst shape) takes 0.3 s.
constexpr std::size_t kMaxEarClippingCorners = 1024;
static_assert(kMaxEarClippingCorners > 4, "quads have their own split");

// --- OBJ and MTL text ------------------------------------------------------------------------

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim_blanks(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

/// Splits the first blank-separated word off `rest`.
std::string_view next_word(std::string_view& rest) {
    std::size_t begin = 0;
    while (begin < rest.size() && is_blank(rest[begin])) ++begin;
    std::size_t end = begin;
    while (end < rest.size() && !is_blank(rest[end])) ++end;
    const std::string_view word = rest.substr(begin, end - begin);
    rest.remove_prefix(end);
    return word;
}

std::string lowercase(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

/// The line without its comment: a '#' at the start of a word begins one (OBJ and MTL have no
/// quoting, and file names with " #" are rarer than "f 1 2 3 # comment").
std::string_view strip_comment(std::string_view line) {
    for (std::size_t i = 0; i < line.size(); ++i)
        if (line[i] == '#' && (i == 0 || is_blank(line[i - 1]))) return line.substr(0, i);
    return line;
}

/// Calls visit(number, line, joined) for each logical line of an OBJ or MTL file: a UTF-8 byte
/// order mark is skipped; lines end at \n, \r\n or a lone \r (classic Mac files); a line ending
/// in a backslash continues on the next (`joined` counts the lines appended, so `number` stays
/// the file's line number of the first); comments are cut off.
template <typename Visit>
void for_each_line(const std::string& text, Visit&& visit) {
    std::size_t pos = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    std::string joined_text;
    std::size_t number = 0, first = 0;
    int joined = 0;
    while (pos < text.size()) {
        std::size_t end = text.find_first_of("\r\n", pos);
        if (end == std::string::npos) end = text.size();
        const std::string_view line(text.data() + pos, end - pos);
        pos = end + (end < text.size() ? 1 : 0);
        if (end < text.size() && text[end] == '\r' && pos < text.size() && text[pos] == '\n') ++pos;
        ++number;
        const std::string_view body = trim_blanks(line);
        if (!body.empty() && body.back() == '\\' && pos < text.size()) {
            if (joined++ == 0) first = number;
            joined_text.append(body.substr(0, body.size() - 1)).push_back(' ');
            continue;
        }
        if (joined == 0) {
            visit(number, strip_comment(line), 0);
        } else {
            joined_text.append(line);
            visit(first, strip_comment(joined_text), joined);
            joined_text.clear();
            joined = 0;
        }
    }
}

std::string read_text_file(const std::string& path, const char* what) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) fail(path, std::string("cannot open ") + what + " file");
    const std::streamoff size = in.tellg();
    std::string text(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
    in.seekg(0);
    if (size < 0 || !in.read(text.data(), size)) fail(path, std::string("cannot read ") + what + " file");
    return text;
}

/// `word` as a number when all of it is one (a leading '+' allowed, as strtod allows it).
bool parse_number(std::string_view word, double& value) {
    if (!word.empty() && word[0] == '+') word.remove_prefix(1);
    if (word.empty()) return false;
    const char* end = word.data() + word.size();
    const auto result = std::from_chars(word.data(), end, value);
    if (result.ec == std::errc::result_out_of_range && result.ptr == end) {
        value = std::strtod(std::string(word).c_str(), nullptr);  // underflow to 0 (fine) or overflow to inf
        return true;
    }
    return result.ec == std::errc() && result.ptr == end;
}

/// `word` as an OBJ index when all of it is an integer that fits an int.
bool parse_index(std::string_view word, long long& value) {
    if (!word.empty() && word[0] == '+') word.remove_prefix(1);
    const char* end = word.data() + word.size();
    const auto result = std::from_chars(word.data(), end, value);
    return !word.empty() && result.ec == std::errc() && result.ptr == end &&
           value <= std::numeric_limits<int>::max() && value >= -std::numeric_limits<int>::max();
}

std::string line_what(std::size_t number, std::string_view line) {
    return "line " + std::to_string(number) + " ('" + std::string(trim_blanks(line)) + "')";
}

// --- OBJ text ----------------------------------------------------------------------------------

/// An OBJ file checked and rewritten for tinyobjloader, with what it would lose. tinyobjloader
/// reads a coordinate it cannot parse ("nan", "1,5") as 0, wraps indices beyond 32 bits, drops
/// a quad with an index out of range with a warning, fails on "f 1 2 3 # comment", loads only the
/// first MTL file of "mtllib a.mtl b.mtl", cuts "usemtl 01 - Default" at the first space, and
/// reads neither a byte order mark nor "\" line continuations: read_obj_source does those parts.
struct ObjSource {
    std::string text;  ///< the lines tinyobjloader reads (see read_obj_source)
    std::vector<std::pair<std::size_t, std::string>> mtllibs;  ///< (line, the file names as written)
    std::vector<std::string> usemtl_names;                     ///< by the id in "usemtl <id>"
    std::vector<std::size_t> usemtl_lines;                     ///< the first line using each
    std::map<std::size_t, std::vector<ObjCorner>> long_faces;  ///< by face ordinal
};

/// One face corner ("v", "v/vt", "v//vn", "v/vt/vn") with its indices made 0-based: negative
/// ones count back from the elements defined so far (`counts`: v, vt, vn); positive ones are
/// checked against the file's totals at the end (`largest`, `largest_line`).
template <typename Bad>
ObjCorner parse_corner(std::string_view word, const std::size_t (&counts)[3], long long (&largest)[3],
                       std::size_t (&largest_line)[3], std::size_t number, const Bad& bad) {
    static const char* const kKinds[3] = {"vertex", "texture coordinate", "normal"};
    std::string_view parts[3];
    int count = 0;
    for (std::string_view rest = word;; ++count) {
        const std::size_t slash = rest.find('/');
        if (count == 3) bad("'" + std::string(word) + "' is not a face corner (v, v/vt, v//vn or v/vt/vn)");
        parts[count] = rest.substr(0, slash);
        if (slash == std::string_view::npos) break;
        rest.remove_prefix(slash + 1);
    }
    int index[3] = {-1, -1, -1};
    for (int k = 0; k <= count; ++k) {
        if (parts[k].empty() && k == 1 && count == 2) continue;  // v//vn
        long long i = 0;
        if (!parse_index(parts[k], i))
            bad("'" + std::string(parts[k]) + "' is not an index (an integer of at most " +
                std::to_string(std::numeric_limits<int>::max()) + " in magnitude)");
        if (i == 0)
            bad("index 0 in '" + std::string(word) + "' (OBJ indices count from 1, negative ones back from the last)");
        if (i < 0 && static_cast<std::size_t>(-i) > counts[k])
            bad(std::string(kKinds[k]) + " index " + std::to_string(i) + " reaches before the first (" +
                std::to_string(counts[k]) + " defined above)");
        if (i > largest[k]) {
            largest[k] = i;
            largest_line[k] = number;
        }
        index[k] = static_cast<int>(i < 0 ? static_cast<long long>(counts[k]) + i : i - 1);
    }
    return ObjCorner{index[0], index[1], index[2]};
}

/// Reads and checks an OBJ file (every number of the v / vt / vn lines must parse completely and
/// be a finite float, and each line have as many as its kind allows; vertex colours outside [0, 1]
/// give a warning; every index of the f lines must be an integer that fits an int and refer to
/// an element of the file) into the text tinyobjloader reads: comments, continuations and a byte
/// order mark resolved; mtllib lines taken out (the loader reads the MTL files); "usemtl NAME"
/// written "usemtl <id>"; l / p elements and faces of fewer than three corners dropped (with a
/// warning); faces of more than kMaxTinyobjCorners kept aside, leaving "f 1 1 1" in their place.
/// Line numbers are kept, after one first line "mtllib ids" that hands tinyobjloader the ids.
ObjSource read_obj_source(const std::string& path, std::vector<std::string>& warnings) {
    const std::string bytes = read_text_file(path, "OBJ");
    ObjSource src;
    src.text.reserve(bytes.size() + 16);
    src.text += "mtllib ids\n";
    std::map<std::string, std::size_t, std::less<>> usemtl_ids;
    std::size_t counts[3] = {0, 0, 0}, largest_line[3] = {0, 0, 0}, faces = 0;
    long long largest[3] = {0, 0, 0};
    std::size_t not_drawn = 0, short_faces = 0, first_short = 0;
    std::size_t coloured = 0, colours_outside = 0, first_outside = 0;  // vertices with r g b; values not in [0, 1]
    std::string first_outside_value;
    std::vector<ObjCorner> corners;
    for_each_line(bytes, [&](std::size_t number, std::string_view line, int joined) {
        const auto bad = [&](const std::string& what) { fail(path, line_what(number, line) + ": " + what); };
        std::string_view rest = line;
        const std::string_view keyword = next_word(rest);
        const int kind = keyword == "v" ? 0 : keyword == "vt" ? 1 : keyword == "vn" ? 2 : -1;
        if (kind >= 0) {
            double value = 0.0;
            std::size_t numbers = 0;
            std::string_view words[6];
            for (std::string_view word = next_word(rest); !word.empty(); word = next_word(rest)) {
                if (!parse_number(word, value) || !std::isfinite(value))
                    bad("'" + std::string(word) + "' is not a finite number");
                // (tinyobjloader keeps floats: 1e39 became inf.)
                if (std::fabs(value) > std::numeric_limits<float>::max())
                    bad("'" + std::string(word) + "' is beyond float's range");
                if (numbers < 6) words[numbers] = word;
                ++numbers;
            }
            // tinyobjloader fills missing numbers with 0 and drops extra ones, silently: a vertex is
            // x y z [w] or x y z r g b (w, a rational curve's weight, is ignored); a texture coordinate
            // u [v [w]] (v defaults to 0, as the OBJ spec says; w is ignored); a normal i j k.
            const std::string got = ", got " + std::to_string(numbers);
            if (kind == 0 && numbers < 3) bad("a vertex needs 3 coordinates (x y z)" + got);
            if (kind == 0 && numbers != 3 && numbers != 4 && numbers != 6)
                bad("a vertex is x y z, x y z w or x y z r g b (with a colour)" + got + " numbers");
            if (kind == 1 && (numbers < 1 || numbers > 3))
                bad("a texture coordinate is u [v [w]] (1 to 3 numbers)" + got);
            if (kind == 2 && numbers != 3) bad("a normal needs 3 coordinates (i j k)" + got);
            if (kind == 0 && numbers == 6) {
                ++coloured;
                // Colours are in [0, 1]: 0-255 ones (some exporters') are drawn as written, with a warning.
                for (int c = 3; c < 6; ++c)
                    if (parse_number(words[c], value) && !(value >= 0.0 && value <= 1.0) && colours_outside++ == 0) {
                        first_outside = number;
                        first_outside_value = std::string(words[c]);
                    }
            }
            ++counts[kind];
            src.text.append(line);
        } else if (keyword == "f") {
            corners.clear();
            for (std::string_view word = next_word(rest); !word.empty(); word = next_word(rest))
                corners.push_back(parse_corner(word, counts, largest, largest_line, number, bad));
            if (corners.size() < 3) {
                if (short_faces++ == 0) first_short = number;
            } else if (corners.size() > kMaxTinyobjCorners) {
                src.long_faces.emplace(faces++, corners);
                src.text += "f 1 1 1";
            } else {
                ++faces;
                src.text.append(line);
            }
        } else if (keyword == "l" || keyword == "p") {
            ++not_drawn;
        } else if (keyword == "mtllib") {
            src.mtllibs.emplace_back(number, std::string(trim_blanks(rest)));
        } else if (keyword == "usemtl") {
            const std::string_view name = trim_blanks(rest);
            auto it = usemtl_ids.find(name);
            if (it == usemtl_ids.end()) {
                it = usemtl_ids.emplace(std::string(name), src.usemtl_names.size()).first;
                src.usemtl_names.emplace_back(name);
                src.usemtl_lines.push_back(number);
            }
            src.text += "usemtl " + std::to_string(it->second);
        } else {
            src.text.append(line);  // o, g, s and what tinyobjloader skips
        }
        src.text.append(static_cast<std::size_t>(1 + joined), '\n');
    });
    static const char* const kKinds[3] = {"vertex", "texture coordinate", "normal"};
    for (int k = 0; k < 3; ++k)
        if (largest[k] > static_cast<long long>(counts[k]))
            fail(path, "line " + std::to_string(largest_line[k]) + ": " + kKinds[k] + " index " +
                           std::to_string(largest[k]) + " out of range (the file has " +
                           std::to_string(counts[k]) + ")");
    if (short_faces > 0)
        warnings.push_back(path + ": " + std::to_string(short_faces) +
                           " face(s) with fewer than 3 corners skipped (line " + std::to_string(first_short) +
                           " is the first)");
    if (not_drawn > 0)
        warnings.push_back(path + ": " + std::to_string(not_drawn) + " line (l) or point (p) element(s) not drawn");
    if (colours_outside > 0 && coloured == counts[0])  // (colours are read only when every vertex has one)
        warnings.push_back(path + ": line " + std::to_string(first_outside) + ": vertex colour " + first_outside_value +
                           " is outside [0, 1] (" + std::to_string(colours_outside) +
                           " value(s) in all); colours are expected in [0, 1] (0-255 ones are not rescaled), "
                           "they are drawn as written");
    return src;
}

/// Hands tinyobjloader one material per usemtl id (read_obj_source writes "usemtl <id>"), so its
/// faces carry the id; the names are matched to the MTL files' materials by load_obj.
class UsemtlIds : public tinyobj::MaterialReader {
public:
    explicit UsemtlIds(std::size_t count) : count_(count) {}
    bool operator()(const std::string&, std::vector<tinyobj::material_t>* materials, std::map<std::string, int>* ids,
                    std::string*, std::string*) override {
        for (std::size_t i = materials->size(); i < count_; ++i) {
            ids->emplace(std::to_string(i), static_cast<int>(i));
            materials->emplace_back();
        }
        return true;
    }

private:
    std::size_t count_;
};

/// Reads from a string without copying it.
class StringViewBuffer : public std::streambuf {
public:
    explicit StringViewBuffer(std::string& s) { setg(s.data(), s.data(), s.data() + s.size()); }
};

// --- files named in OBJ and MTL files ----------------------------------------------------------

/// `relative` found under `dir`: as written, else matching each component's name with case
/// ignored (files written on Windows or macOS name "Wood.PNG" for "wood.png"; the first match in
/// name order wins). Empty when there is no such regular file.
std::string find_file(const std::string& dir, const std::string& relative) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path exact = fs::path(dir) / relative;
    if (fs::is_regular_file(exact, ec)) return exact.string();
    fs::path at = dir;
    for (const fs::path& part : fs::path(relative).relative_path()) {
        if (fs::exists(at / part, ec)) {
            at /= part;
            continue;
        }
        const std::string wanted = lowercase(part.string());
        std::string best;
        for (fs::directory_iterator it(at, ec), end; !ec && it != end; it.increment(ec)) {
            const std::string name = it->path().filename().string();
            if (lowercase(name) == wanted && (best.empty() || name < best)) best = name;
        }
        if (best.empty()) return {};
        at /= best;
    }
    return fs::is_regular_file(at, ec) ? at.string() : std::string();
}

/// A Windows drive path ("C:/...", after '\' became '/'): never a file here.
bool is_drive_path(const std::string& name) {
    return name.size() > 2 && std::isalpha(static_cast<unsigned char>(name[0])) && name[1] == ':' && name[2] == '/';
}

/// A file named in an OBJ or MTL file ('\' read as '/'), looked up in `dirs` in order: the path as
/// written (relative to each folder), else, for a path from another machine (C:\..., /home/...)
/// or a folder that is not there, its file name alone. Returns the file found (empty if none).
std::string locate(std::string written, const std::vector<std::string>& dirs) {
    std::replace(written.begin(), written.end(), '\\', '/');
    const bool drive = is_drive_path(written);
    const bool absolute = drive || (!written.empty() && written[0] == '/');
    std::error_code ec;
    if (!drive && absolute && std::filesystem::is_regular_file(written, ec)) return written;
    if (!absolute)
        for (const std::string& dir : dirs)
            if (std::string found = find_file(dir, written); !found.empty()) return found;
    const std::string name = written.substr(written.find_last_of('/') + 1);
    for (const std::string& dir : dirs)
        if (std::string found = find_file(dir, name); !found.empty()) return found;
    return {};
}

/// The MTL files of an mtllib line: the whole rest of the line when it names a file (Blender
/// writes names with spaces unescaped), else each word ("a.mtl b.mtl"; "\ " escapes a space).
/// A missing file is a warning: its materials' faces are drawn white.
std::vector<std::string> mtl_files(const std::string& obj_path, std::size_t line, std::string names,
                                   std::vector<std::string>& warnings) {
    const std::vector<std::string> dirs = {directory_of(obj_path)};
    for (std::size_t at; (at = names.find("\\ ")) != std::string::npos;) names.replace(at, 2, " ");
    if (std::string whole = locate(names, dirs); !whole.empty()) return {whole};
    std::vector<std::string> files;
    std::string_view rest = names;
    for (std::string_view word = next_word(rest); !word.empty(); word = next_word(rest)) {
        if (std::string found = locate(std::string(word), dirs); !found.empty()) {
            files.push_back(found);
        } else {
            warnings.push_back(obj_path + ": line " + std::to_string(line) + ": MTL file '" + std::string(word) +
                               "' not found next to the OBJ file; its materials are drawn white");
        }
    }
    return files;
}

// --- MTL -------------------------------------------------------------------------------------

/// Where a map statement places its image on the uvs: -s and -o (u and v), -clamp.
struct MapPlacement {
    glm::vec2 scale{1.0f}, offset{0.0f};
    bool clamp = false;
    bool operator==(const MapPlacement& o) const { return scale == o.scale && offset == o.offset && clamp == o.clamp; }
};

/// A material of an MTL file, as the loader draws it.
struct ObjMaterial {
    std::string name, mtl_path;  ///< its name and the MTL file defining it (map_Kd is relative to it)
    std::size_t line = 0;        ///< its newmtl line
    glm::vec3 kd{1.0f};          ///< Kd; white when the file gives none (map_Kd shows as it is)
    double d = 1.0, tr = 0.0;    ///< d (dissolve) and Tr (transparency, 1 − d) as given
    bool has_d = false, has_tr = false;
    std::string map_kd;                          ///< the map_Kd file as written; empty: none
    std::string map_d;                           ///< the map_d file (an alpha mask) as written; empty: none
    MapPlacement placement;                      ///< map_Kd's, or a map_d's without a map_Kd
    MapPlacement d_placement;                    ///< map_d's as written
    bool linear = false;                         ///< map_Kd -colorspace linear

    /// The opacity: d, else 1 − Tr, else 1.
    double dissolve() const { return has_d ? d : has_tr ? 1.0 - tr : 1.0; }
};

/// An option of a texture map statement: its name, its numbers or its word (lower case).
using MapOption = std::function<void(std::string_view option, const std::vector<double>& numbers,
                                     const std::string& word)>;

/// Parses "<keyword> [options] file" (map_Kd, map_d): each option, with its arguments, goes to
/// `apply` (an unknown one is warned about); returns the file name, the rest of the line (names
/// may hold spaces).
std::string parse_map_statement(std::string_view rest, const std::string& keyword,
                                const std::function<void(const std::string&)>& bad,
                                const std::function<void(const std::string&)>& warn, const MapOption& apply) {
    // Option name → (minimum, maximum) number of arguments; numbers unless the option is an on/off or a word.
    static const std::map<std::string_view, std::pair<int, int>> kOptions = {
        {"-blendu", {1, 1}}, {"-blendv", {1, 1}}, {"-cc", {1, 1}},    {"-clamp", {1, 1}}, {"-bm", {1, 1}},
        {"-boost", {1, 1}},  {"-texres", {1, 1}}, {"-mm", {1, 2}},    {"-o", {1, 3}},     {"-s", {1, 3}},
        {"-t", {1, 3}},      {"-imfchan", {1, 1}}, {"-type", {1, 1}}, {"-colorspace", {1, 1}}};
    static const std::set<std::string_view> kWordArgument = {"-blendu", "-blendv", "-cc", "-clamp", "-imfchan", "-type",
                                                             "-colorspace"};
    rest = trim_blanks(rest);
    while (!rest.empty() && rest[0] == '-') {
        std::string_view after = rest;
        const std::string_view option = next_word(after);
        const auto known = kOptions.find(option);
        std::vector<double> numbers;
        std::string word;
        // Arguments: a word, or up to the maximum of numbers; the last word is always the file name.
        auto more = [&] { std::string_view probe = after; next_word(probe); return !trim_blanks(probe).empty(); };
        if (known != kOptions.end() && kWordArgument.count(option)) {
            if (more()) word = lowercase(std::string(next_word(after)));
        } else {
            const int most = known == kOptions.end() ? 3 : known->second.second;
            double value = 0.0;
            for (std::string_view probe = after; static_cast<int>(numbers.size()) < most && more();) {
                if (!parse_number(next_word(probe), value)) break;
                if (!std::isfinite(value)) bad(keyword + " " + std::string(option) + " values must be finite");
                numbers.push_back(value);
                after = probe;
            }
        }
        rest = trim_blanks(after);
        if (known == kOptions.end()) warn(keyword + " option '" + std::string(option) + "' is unknown; ignored");
        else apply(option, numbers, word);
    }
    return std::string(rest);
}

/// Applies map option -s, -o (u and v; w ignored) or -clamp to `p`; false for any other option.
bool place_map(std::string_view option, const std::vector<double>& numbers, const std::string& word, MapPlacement& p) {
    if (option == "-s" || option == "-o") {
        glm::vec2& v = option == "-s" ? p.scale : p.offset;
        for (std::size_t i = 0; i < numbers.size() && i < 2; ++i)
            v[static_cast<int>(i)] = static_cast<float>(numbers[i]);
    } else if (option == "-clamp") {
        p.clamp = word == "on";
    } else {
        return false;
    }
    return true;
}

/// Whether map option -mm, -t or -cc, which this renderer does not apply, would change the look.
bool changes_look(std::string_view option, const std::vector<double>& numbers, const std::string& word) {
    return (option == "-mm" && !numbers.empty() && (numbers[0] != 0.0 || (numbers.size() > 1 && numbers[1] != 1.0))) ||
           (option == "-t" && std::any_of(numbers.begin(), numbers.end(), [](double x) { return x != 0.0; })) ||
           (option == "-cc" && word == "on");
}

/// Parses "map_Kd [options] file". Options this renderer applies: -s and -o (u, v; w ignored),
/// -clamp and -colorspace. Those that change the look but are not applied (-mm, -t, -cc on) are
/// warned about; those without meaning for a colour map here (-bm, -blendu, -blendv, -boost,
/// -texres, -imfchan, -type) are skipped quietly.
void parse_map_kd(std::string_view rest, ObjMaterial& m, const std::function<void(const std::string&)>& bad,
                  const std::function<void(const std::string&)>& warn) {
    m.map_kd = parse_map_statement(rest, "map_Kd", bad, warn, [&](std::string_view option,
                                                                  const std::vector<double>& numbers,
                                                                  const std::string& word) {
        if (place_map(option, numbers, word, m.placement)) return;
        if (option == "-colorspace") m.linear = word == "linear";
        else if (changes_look(option, numbers, word))
            warn("map_Kd option " + std::string(option) + " is not supported; the texture is drawn without it");
    });
    if (m.map_kd.empty()) warn("map_Kd names no file; drawn without a texture");
}

/// Parses "map_d [options] file". Its -s, -o and -clamp place the mask when there is no map_Kd;
/// with one, the mask is read at map_Kd's uvs (read_materials warns when they differ). -mm, -t and
/// -cc that would change the look are warned about; -imfchan, -texres, -boost, -bm, -blendu/v,
/// -type and -colorspace are skipped quietly (the mask is the file's alpha, or its first channel
/// when it has no alpha).
void parse_map_d(std::string_view rest, ObjMaterial& m, const std::function<void(const std::string&)>& bad,
                 const std::function<void(const std::string&)>& warn) {
    m.map_d = parse_map_statement(rest, "map_d", bad, warn, [&](std::string_view option,
                                                                const std::vector<double>& numbers,
                                                                const std::string& word) {
        if (!place_map(option, numbers, word, m.d_placement) && changes_look(option, numbers, word))
            warn("map_d option " + std::string(option) + " is not supported; the mask is drawn without it");
    });
    if (m.map_d.empty()) warn("map_d names no file; drawn without an alpha mask");
}

/// The materials of an MTL file (its own reader: tinyobjloader's takes a missing Kd as black, or
/// 0.6 grey with map_Kd, reads "d -halo 0.5" as 0 and a map_Kd option without all three numbers
/// as swallowing the file name). Malformed numbers are errors naming the file and line.
void read_mtl(const std::string& path, std::vector<ObjMaterial>& materials, std::vector<std::string>& warnings) {
    const std::string text = read_text_file(path, "MTL");
    ObjMaterial* m = nullptr;
    for_each_line(text, [&](std::size_t number, std::string_view line, int) {
        const auto bad = [&](const std::string& what) { fail(path, line_what(number, line) + ": " + what); };
        const auto warn = [&](const std::string& what) {
            warnings.push_back(path + ": line " + std::to_string(number) + ": material '" + m->name + "': " + what);
        };
        std::string_view rest = line;
        const std::string_view keyword = next_word(rest);
        if (keyword == "newmtl") {
            materials.push_back(ObjMaterial{});
            m = &materials.back();
            m->name = std::string(trim_blanks(rest));
            m->mtl_path = path;
            m->line = number;
            return;
        }
        if (!m) return;  // statements before the first newmtl belong to no material
        const auto numbers = [&](std::size_t most) {
            std::vector<double> values;
            double value = 0.0;
            for (std::string_view word = next_word(rest); !word.empty(); word = next_word(rest)) {
                if (!parse_number(word, value) || !std::isfinite(value))
                    bad("'" + std::string(word) + "' is not a finite number");
                values.push_back(value);
            }
            if (values.empty() || values.size() > most)
                bad(std::string(keyword) + " takes " + (most == 1 ? "one number" : "1 to 3 numbers"));
            return values;
        };
        if (keyword == "Kd") {
            std::string_view probe = rest;
            const std::string_view first = next_word(probe);
            if (first == "spectral" || first == "xyz") {
                warn("Kd " + std::string(first) + " is not supported; drawn white");
                return;
            }
            const std::vector<double> v = numbers(3);
            if (v.size() == 2) bad("Kd takes 1 or 3 numbers");
            for (double x : v)  // (the draw's colour is float: 1e39 would become inf)
                if (std::fabs(x) > std::numeric_limits<float>::max()) bad("Kd's numbers are beyond float's range");
            m->kd = glm::vec3(static_cast<float>(v[0]));
            if (v.size() == 3) m->kd = glm::vec3(glm::dvec3(v[0], v[1], v[2]));
        } else if (keyword == "d" || keyword == "Tr") {
            std::string_view probe = rest;
            if (keyword == "d" && next_word(probe) == "-halo") {
                rest = probe;
                warn("d -halo (dissolve by view angle) is drawn as a constant dissolve");
            }
            double value = numbers(1)[0];
            if (value < 0.0 || value > 1.0) {
                warn(std::string(keyword) + " " + std::to_string(value) + " is outside [0, 1]; clamped");
                value = std::clamp(value, 0.0, 1.0);
            }
            (keyword == "d" ? m->d : m->tr) = value;
            (keyword == "d" ? m->has_d : m->has_tr) = true;
        } else if (keyword == "map_Kd") {
            parse_map_kd(rest, *m, bad, warn);
        } else if (keyword == "map_d") {
            parse_map_d(rest, *m, bad, warn);
        }
    });
}

/// The materials of the OBJ's MTL files, by name (the first definition of a name wins, with a
/// warning), with warnings about dissolve values that disagree or hide a material.
std::vector<ObjMaterial> read_materials(const std::string& obj_path, const ObjSource& src,
                                        std::vector<std::string>& warnings) {
    std::vector<ObjMaterial> all;
    std::set<std::string> read;
    for (const auto& [line, names] : src.mtllibs)
        for (const std::string& file : mtl_files(obj_path, line, names, warnings))
            if (std::error_code ec; read.insert(std::filesystem::weakly_canonical(file, ec).string()).second)
                read_mtl(file, all, warnings);
    std::vector<ObjMaterial> materials;
    std::set<std::string> names;
    for (ObjMaterial& m : all) {
        const std::string where = m.mtl_path + ": line " + std::to_string(m.line) + ": material '" + m.name + "': ";
        if (!names.insert(m.name).second) {
            warnings.push_back(where + "defined again; the first definition is used");
            continue;
        }
        // Exporters write both, consistently (3ds Max: "d 1" and "Tr 0"); some write Tr as d.
        if (m.has_d && m.has_tr && std::abs(m.d - (1.0 - m.tr)) > 1e-6)
            warnings.push_back(where + "d " + std::to_string(m.d) + " and Tr " + std::to_string(m.tr) +
                               " disagree (Tr is 1 − d); using d");
        if (m.dissolve() == 0.0)
            warnings.push_back(where + "fully transparent (" + (m.has_d ? "d 0" : "Tr 1") +
                               "); its faces are invisible");
        // The mask is read at map_Kd's uvs, into map_Kd's texture, or alone (at its own) into a
        // white one (map_kd_texture).
        if (!m.map_d.empty() && m.map_kd.empty()) {
            m.placement = m.d_placement;
        } else if (!m.map_d.empty() && !(m.d_placement == m.placement)) {
            warnings.push_back(where + "map_d's -s, -o or -clamp differ from map_Kd's; they are ignored, the "
                                       "mask is read at map_Kd's uvs");
        }
        materials.push_back(std::move(m));
    }
    return materials;
}

// --- faces -------------------------------------------------------------------------------------

/// Twice the signed area of the 2D triangle abc (positive: counter-clockwise).
double cross2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// A polygon's triangles as indices into `p` (its corners in order), keeping its winding. A quad
/// is split along its shorter diagonal, as tinyobjloader did, unless that diagonal lies outside
/// it (a concave quad); a larger polygon is ear-clipped in the plane of its Newell normal. What
/// ear clipping cannot finish (a self-intersecting or degenerate polygon) and polygons of more
/// than kMaxEarClippingCorners corners are fanned, and `fanned` is set.
std::vector<std::array<std::size_t, 3>> triangulate(const std::vector<glm::dvec3>& p, bool& fanned) {
    const std::size_t n = p.size();
    glm::dvec3 normal(0.0);  // Newell's method: robust for non-planar and concave polygons
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3& a = p[i];
        const glm::dvec3& b = p[(i + 1) % n];
        normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    if (n == 4) {
        auto facing = [&](std::size_t a, std::size_t b, std::size_t c) {
            return glm::dot(glm::cross(p[b] - p[a], p[c] - p[a]), normal) > 0.0;
        };
        const bool split02 = glm::dot(p[2] - p[0], p[2] - p[0]) < glm::dot(p[3] - p[1], p[3] - p[1]);
        const bool valid02 = facing(0, 1, 2) && facing(0, 2, 3), valid13 = facing(0, 1, 3) && facing(1, 2, 3);
        if (split02 ? valid02 || !valid13 : !valid13 && valid02) return {{{0, 1, 2}}, {{0, 2, 3}}};
        return {{{0, 1, 3}}, {{1, 2, 3}}};
    }
    if (n > kMaxEarClippingCorners) {
        fanned = true;
        std::vector<std::array<std::size_t, 3>> fan;
        for (std::size_t k = 1; k + 1 < n; ++k) fan.push_back({0, k, k + 1});
        return fan;
    }
    // Project along the normal's largest axis, mirrored so that the polygon runs counter-clockwise.
    const glm::dvec3 a = glm::abs(normal);
    const int drop = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
    const int u = (drop + 1) % 3, v = (drop + 2) % 3;
    const double mirror = normal[drop] < 0.0 ? -1.0 : 1.0;
    std::vector<glm::dvec2> q(n);
    for (std::size_t i = 0; i < n; ++i) q[i] = glm::dvec2(p[i][u], mirror * p[i][v]);
    std::vector<std::size_t> left(n);
    for (std::size_t i = 0; i < n; ++i) left[i] = i;
    std::vector<std::array<std::size_t, 3>> out;
    std::size_t at = 0, tried = 0;
    while (left.size() > 3 && tried < left.size()) {
        const std::size_t m = left.size();
        const std::size_t i0 = left[(at + m - 1) % m], i1 = left[at % m], i2 = left[(at + 1) % m];
        bool ear = cross2(q[i0], q[i1], q[i2]) > 0.0;
        for (std::size_t k = 0; ear && k < m; ++k) {
            const glm::dvec2& r = q[left[k]];
            if (r == q[i0] || r == q[i1] || r == q[i2]) continue;
            ear = !(cross2(q[i0], q[i1], r) >= 0.0 && cross2(q[i1], q[i2], r) >= 0.0 && cross2(q[i2], q[i0], r) >= 0.0);
        }
        if (ear) {
            out.push_back({i0, i1, i2});
            left.erase(left.begin() + static_cast<std::ptrdiff_t>(at % m));
            tried = 0;
        } else {
            ++at;
            ++tried;
        }
        at %= left.size();
    }
    fanned = left.size() > 3;
    for (std::size_t k = 1; k + 1 < left.size(); ++k) out.push_back({left[0], left[k], left[k + 1]});
    return out;
}

// --- the loader --------------------------------------------------------------------------------

/// Where the map file `written` (map_Kd or map_d, `keyword`) of material m is: relative to its MTL
/// file's folder (as MTL files mean it), else the OBJ's (see locate); a file found elsewhere than
/// written comes with a warning; the path as written when there is none (loading it then fails).
std::string locate_map(const std::string& obj_path, const ObjMaterial& m, const std::string& written,
                       const char* keyword, std::vector<std::string>& warnings) {
    std::vector<std::string> dirs = {directory_of(m.mtl_path)};
    if (directory_of(obj_path) != dirs[0]) dirs.push_back(directory_of(obj_path));
    std::string file = locate(written, dirs);
    std::string as_written = written;
    std::replace(as_written.begin(), as_written.end(), '\\', '/');
    if (!is_drive_path(as_written) && (as_written.empty() || as_written[0] != '/')) as_written = dirs[0] + as_written;
    if (file.empty()) return as_written;
    if (std::filesystem::path(file).lexically_normal() != std::filesystem::path(as_written).lexically_normal())
        warnings.push_back(m.mtl_path + ": material '" + m.name + "': " + keyword + " '" + written + "' is not at '" +
                           as_written + "'; using '" + file + "'");
    return file;
}

/// A material's texture (map_Kd, or white under a map_d alone), and whether its alpha is a map_d mask.
struct MaterialTexture {
    Texture texture;
    bool masked = false;
};

/// map_Kd's colour with map_d's mask as alpha: the mask image's alpha where it has one (some value
/// below 1), else its first channel (a grey mask), read as data (code / max code); a mask of
/// another size is read at the nearest texel.
Texture masked_texture(const Image& colour, const Image& mask, const std::string& name) {
    bool mask_alpha = false;
    for (std::size_t i = 3; i < mask.pixels.size() && !mask_alpha; i += 4) mask_alpha = mask.pixels[i] < 1.0f;
    std::vector<float> texels(static_cast<std::size_t>(colour.width) * static_cast<std::size_t>(colour.height) * 4);
    for (int y = 0; y < colour.height; ++y) {
        const int my = static_cast<int>((std::int64_t{2} * y + 1) * mask.height / (std::int64_t{2} * colour.height));
        for (int x = 0; x < colour.width; ++x) {
            const int mx = static_cast<int>((std::int64_t{2} * x + 1) * mask.width / (std::int64_t{2} * colour.width));
            const float a = mask.at(mx, my, mask_alpha ? 3 : 0);
            float* t = &texels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(colour.width) + x) * 4];
            for (int c = 0; c < 3; ++c) t[c] = colour.at(x, y, c) * a;
            t[3] = a;
        }
    }
    return Texture::from_float(texels.data(), colour.width, colour.height, 4, /*premultiplied=*/true, name);
}

/// The texture of a material's map_Kd (located by locate_map), decoded as sRGB unless
/// -colorspace linear, its alpha used only when the material blends (d < 1), as glTF does for
/// alphaMode BLEND; a missing or unreadable file becomes the error texture with a warning. With a
/// map_d (an alpha mask), the texture's alpha is the mask instead: map_Kd's own alpha when map_d
/// names the same file, else masked_texture; a mask that cannot be read is a warning, and the
/// material is drawn without it. A map_d without a map_Kd masks a white texture (the material's Kd
/// colour shows where the mask keeps it); without the mask, the texture is plain white.
MaterialTexture map_kd_texture(const std::string& obj_path, const ObjMaterial& m, std::vector<std::string>& warnings) {
    const std::string where = m.mtl_path + ": material '" + m.name + "': ";
    const std::string file = m.map_kd.empty() ? "" : locate_map(obj_path, m, m.map_kd, "map_Kd", warnings);
    const std::string mask_file = m.map_d.empty() ? "" : locate_map(obj_path, m, m.map_d, "map_d", warnings);
    const bool own_alpha = !file.empty() && !mask_file.empty() &&
                           std::filesystem::path(mask_file).lexically_normal() ==
                               std::filesystem::path(file).lexically_normal();
    const auto unreadable = [&](const std::exception& e) {  // missing, unreadable, corrupt or too large
        warnings.push_back(where + "cannot load its map_Kd texture '" + file + "' (" + e.what() +
                           "); drawing the error texture instead");
        return MaterialTexture{error_texture(), false};
    };
    if (!mask_file.empty() && !own_alpha) {  // (each file read once)
        ImageReadOptions colour_options, mask_options;
        colour_options.srgb = !m.linear;
        colour_options.ignore_alpha = true;  // (the mask replaces it)
        mask_options.srgb = false;
        Image colour;
        if (!file.empty()) {
            try {
                colour = read_image(file, colour_options);
            } catch (const std::exception& e) {
                return unreadable(e);
            }
        }
        try {
            const Image mask = read_image(mask_file, mask_options);
            if (file.empty()) {  // a map_d alone masks white, at the mask's size
                colour = Image::unfilled(mask.width, mask.height, 4);
                std::fill(colour.pixels.begin(), colour.pixels.end(), 1.0f);
            }
            return {masked_texture(colour, mask, (file.empty() ? "" : file + " ") + "(map_d " + mask_file + ")"),
                    true};
        } catch (const std::exception& e) {
            warnings.push_back(where + "cannot load its map_d mask '" + mask_file + "' (" + e.what() +
                               "); drawn without it");
        }
    }
    if (file.empty()) {  // a map_d alone whose mask cannot be read: the Kd colour, unmasked
        const float white[4] = {1.0f, 1.0f, 1.0f, 1.0f};
        return {Texture::from_float(white, 1, 1, 4, /*premultiplied=*/true, "white"), false};
    }
    TextureFileOptions options;
    options.ignore_alpha = m.dissolve() >= 1.0 && !own_alpha;
    options.srgb = !m.linear;
    try {
        return {load_texture(file, options), own_alpha};
    } catch (const std::exception& e) {
        return unreadable(e);
    }
}

}  // namespace

LoadedScene load_obj(const std::string& path) {
    LoadedScene scene;
    ObjSource src = read_obj_source(path, scene.warnings);
    const std::vector<ObjMaterial> materials = read_materials(path, src, scene.warnings);

    // usemtl id → material index (−1: the default material), warning once per unknown name.
    std::vector<int> material_of(src.usemtl_names.size(), -1);
    for (std::size_t id = 0; id < src.usemtl_names.size(); ++id) {
        const auto it = std::find_if(materials.begin(), materials.end(),
                                     [&](const ObjMaterial& m) { return m.name == src.usemtl_names[id]; });
        if (it != materials.end()) {
            material_of[id] = static_cast<int>(it - materials.begin());
        } else {
            scene.warnings.push_back(path + ": line " + std::to_string(src.usemtl_lines[id]) + ": usemtl '" +
                                     src.usemtl_names[id] + "' names no material of its MTL files; drawn white");
        }
    }

    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> ids;
    std::string warn, err;
    UsemtlIds reader(src.usemtl_names.size());
    StringViewBuffer buffer(src.text);
    std::istream stream(&buffer);
    // No default vertex colours: attrib.colors stays empty unless every vertex has one.
    const bool ok = tinyobj::LoadObj(&attrib, &shapes, &ids, &warn, &err, &stream, &reader,
                                     /*triangulate=*/false, /*default_vcols_fallback=*/false);
    if (!ok) fail(path, "cannot read OBJ file: " + trim(err.empty() ? warn : err));
    std::string().swap(src.text);
    add_warnings(scene.warnings, path, err);
    add_warnings(scene.warnings, path, warn);

    const std::size_t vertex_count = attrib.vertices.size() / 3;
    const std::size_t uv_count = attrib.texcoords.size() / 2;
    const std::size_t normal_count = attrib.normals.size() / 3;
    if (vertex_count > kMaxElements) fail(path, "too many vertices (" + std::to_string(vertex_count) + ")");
    const bool has_colors = !attrib.colors.empty() && attrib.colors.size() == attrib.vertices.size();
    auto material_name = [&](int material) {
        return material < 0 ? std::string("default material") : "material '" + materials[material].name + "'";
    };
    auto is_textured = [&](int material) {  // (a map_d alone masks a white texture)
        return material >= 0 && (!materials[material].map_kd.empty() || !materials[material].map_d.empty());
    };

    // Step 1: triangulate the faces and gather their triangles per (material, textured) in order
    // of first use. A textured material's faces without texture coordinates go to its untextured
    // group.
    std::vector<ObjGroup> groups;
    std::map<std::pair<int, bool>, std::size_t> group_of;
    std::size_t face_ordinal = 0, fanned_faces = 0;
    std::vector<ObjCorner> corners;
    std::vector<glm::dvec3> polygon;
    for (std::size_t s = 0; s < shapes.size(); ++s) {
        const tinyobj::mesh_t& m = shapes[s].mesh;
        std::size_t offset = 0;
        for (std::size_t f = 0; f < m.num_face_vertices.size(); ++f, ++face_ordinal) {
            const std::size_t n = m.num_face_vertices[f];
            if (offset + n > m.indices.size()) fail(path, "shape '" + shapes[s].name + "': face indices truncated");
            corners.clear();
            for (std::size_t c = 0; c < n; ++c) {
                const tinyobj::index_t& idx = m.indices[offset + c];
                corners.push_back(ObjCorner{idx.vertex_index, idx.texcoord_index, idx.normal_index});
            }
            offset += n;
            if (const auto it = src.long_faces.find(face_ordinal); it != src.long_faces.end()) corners = it->second;
            bool face_uvs = true, face_normals = true;
            for (const ObjCorner& c : corners) {  // (read_obj_source checked them; a safety net)
                if (c.v < 0 || static_cast<std::size_t>(c.v) >= vertex_count ||
                    c.t >= static_cast<long long>(uv_count) || c.n >= static_cast<long long>(normal_count))
                    fail(path, "shape '" + shapes[s].name + "' face " + std::to_string(f) + ": index out of range");
                face_uvs &= c.t >= 0;
                face_normals &= c.n >= 0;
            }
            int material = f < m.material_ids.size() ? m.material_ids[f] : -1;
            const bool known = material >= 0 && static_cast<std::size_t>(material) < material_of.size();
            material = known ? material_of[material] : -1;
            const bool textured = is_textured(material) && face_uvs;
            auto it = group_of.find({material, textured});
            if (it == group_of.end()) {
                it = group_of.emplace(std::make_pair(material, textured), groups.size()).first;
                groups.push_back(ObjGroup{material, textured, {}, true, true});
            }
            ObjGroup& g = groups[it->second];
            g.all_uvs &= face_uvs;
            g.all_normals &= face_normals;
            if (corners.size() == 3) {
                g.triangles.push_back({corners[0], corners[1], corners[2]});
                continue;
            }
            polygon.clear();
            for (const ObjCorner& c : corners) {
                const std::size_t v = static_cast<std::size_t>(c.v);
                polygon.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
            }
            bool fanned = false;
            for (const auto& t : triangulate(polygon, fanned))
                g.triangles.push_back({corners[t[0]], corners[t[1]], corners[t[2]]});
            fanned_faces += fanned;
        }
    }
    if (fanned_faces > 0)
        scene.warnings.push_back(path + ": " + std::to_string(fanned_faces) +
                                 " polygon(s) are self-intersecting, degenerate or of more than " +
                                 std::to_string(kMaxEarClippingCorners) + " corners; triangulated as fans");

    // Step 2: one compact mesh and draw per group; vertices are split by their (position,
    // texture coordinate, normal) indices, those the group keeps.
    std::map<int, MaterialTexture> textures;  // by material
    for (ObjGroup& g : groups) {
        const std::string name = material_name(g.material);
        const bool keep_uvs = g.all_uvs && (g.textured || !is_textured(g.material));
        const bool keep_normals = g.all_normals;
        if (is_textured(g.material) && !g.textured)
            scene.warnings.push_back(path + ": " + name + ": " + std::to_string(g.triangles.size()) +
                                     " triangle(s) have no texture coordinates; they are drawn without its " +
                                     (materials[g.material].map_kd.empty() ? "map_d mask" : "map_Kd texture"));

        // The material's -s / -o (map_Kd's, or a map_d's alone) scale and offset the uvs (an affine
        // map, exact per vertex).
        MapPlacement placement;
        if (g.textured) placement = materials[g.material].placement;

        auto mesh = std::make_shared<Mesh>();
        std::unordered_map<ObjCorner, std::uint32_t, ObjCornerHash> remap;
        mesh->triangles.reserve(g.triangles.size());
        for (const auto& t : g.triangles) {
            glm::uvec3 out;
            for (int c = 0; c < 3; ++c) {
                const ObjCorner key{t[c].v, keep_uvs ? t[c].t : -1, keep_normals ? t[c].n : -1};
                auto [it, inserted] = remap.emplace(key, static_cast<std::uint32_t>(mesh->positions.size()));
                if (inserted) {
                    const std::size_t v = static_cast<std::size_t>(key.v);
                    mesh->positions.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1],
                                                 attrib.vertices[3 * v + 2]);
                    if (has_colors)
                        mesh->colors.emplace_back(attrib.colors[3 * v], attrib.colors[3 * v + 1],
                                                  attrib.colors[3 * v + 2], 1.0f);
                    if (keep_uvs) {
                        const std::size_t i = static_cast<std::size_t>(key.t);
                        const glm::vec2 vt(attrib.texcoords[2 * i], attrib.texcoords[2 * i + 1]);
                        const glm::vec2 uv = vt * placement.scale + placement.offset;
                        mesh->uvs.emplace_back(uv.x, 1.0f - uv.y);  // OBJ's v runs up the image, ours down
                    }
                    if (keep_normals) {
                        const std::size_t i = static_cast<std::size_t>(key.n);
                        mesh->normals.emplace_back(attrib.normals[3 * i], attrib.normals[3 * i + 1],
                                                   attrib.normals[3 * i + 2]);
                    }
                }
                out[c] = it->second;
            }
            mesh->triangles.push_back(out);
        }
        mesh->validate(path + " (" + name + ")");
        Draw draw;
        draw.mesh = mesh.get();
        if (g.material >= 0) {
            // Kd, and the dissolve as glTF's alphaMode BLEND does it: "over" with the colour
            // premultiplied by its alpha.
            const ObjMaterial& mat = materials[g.material];
            const float alpha = static_cast<float>(mat.dissolve());
            draw.color = glm::vec4(mat.kd, 1.0f);
            if (alpha < 1.0f) {
                draw.color = glm::vec4(mat.kd * alpha, alpha);
                draw.state.blend = BlendMode::over;
            }
        }
        if (g.textured) {
            auto it = textures.find(g.material);
            if (it == textures.end())
                it = textures.emplace(g.material, map_kd_texture(path, materials[g.material], scene.warnings)).first;
            draw.texture = it->second.texture;
            // A map_d mask: alpha-tested as glTF's MASK, or, under a dissolve, blended with it.
            if (it->second.masked && draw.state.blend == BlendMode::replace)
                draw.state.alpha_cutoff = kDefaultAlphaCutoff;
            if (materials[g.material].placement.clamp) draw.sampler.wrap_u = draw.sampler.wrap_v = WrapMode::clamp;
        }
        scene.meshes.push_back(std::move(mesh));
        scene.draws.push_back(draw);
    }
    return scene;
}

}  // namespace scene_files
}  // namespace mipraster
