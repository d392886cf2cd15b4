// Scene files: OBJ/MTL through tinyobjloader, glTF 2.0 through tinygltf. The only file that
// includes either library.
#include "mipraster/io/scene_file.hpp"

#include "file_extension.hpp"
#include "mipraster/core/memory_limit.hpp"
#include "mipraster/io/texture_file.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

namespace mipraster {

namespace {

/// Limits against absurd files: a mesh's vertex and triangle counts must fit the 32-bit indices,
/// and the node hierarchy is walked at most this deep (a deeper one is a cycle or hostile).
constexpr std::size_t kMaxElements = std::numeric_limits<std::uint32_t>::max();
constexpr int kMaxNodeDepth = 1024;
static_assert(kMaxNodeDepth > 0 && kMaxElements > 0, "limits must be positive");

std::string directory_of(const std::string& path) {
    const auto slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string("./") : path.substr(0, slash + 1);
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
    throw std::runtime_error(path + ": " + problem);
}

std::string trim(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
    return s;
}

void add_warnings(std::vector<std::string>& out, const std::string& path, const std::string& text) {
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) {
        line = trim(line);
        if (!line.empty()) out.push_back(path + ": " + line);
    }
}
// ---------------------------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------------------------
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
/// be a finite float; every index of the f lines must be an integer that fits an int and refer to
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
    std::vector<ObjCorner> corners;
    for_each_line(bytes, [&](std::size_t number, std::string_view line, int joined) {
        const auto bad = [&](const std::string& what) { fail(path, line_what(number, line) + ": " + what); };
        std::string_view rest = line;
        const std::string_view keyword = next_word(rest);
        const int kind = keyword == "v" ? 0 : keyword == "vt" ? 1 : keyword == "vn" ? 2 : -1;
        if (kind >= 0) {
            double value = 0.0;
            for (std::string_view word = next_word(rest); !word.empty(); word = next_word(rest)) {
                if (!parse_number(word, value) || !std::isfinite(value))
                    bad("'" + std::string(word) + "' is not a finite number");
                // (tinyobjloader keeps floats: 1e39 became inf.)
                if (std::fabs(value) > std::numeric_limits<float>::max())
                    bad("'" + std::string(word) + "' is beyond float's range");
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

/// A material of an MTL file, as the loader draws it.
struct ObjMaterial {
    std::string name, mtl_path;  ///< its name and the MTL file defining it (map_Kd is relative to it)
    std::size_t line = 0;        ///< its newmtl line
    glm::vec3 kd{1.0f};          ///< Kd; white when the file gives none (map_Kd shows as it is)
    double d = 1.0, tr = 0.0;    ///< d (dissolve) and Tr (transparency, 1 − d) as given
    bool has_d = false, has_tr = false;
    std::string map_kd;                          ///< the map_Kd file as written; empty: none
    glm::vec2 uv_scale{1.0f}, uv_offset{0.0f};   ///< map_Kd -s and -o (u and v)
    bool clamp = false, linear = false;          ///< map_Kd -clamp on, -colorspace linear

    /// The opacity: d, else 1 − Tr, else 1.
    double dissolve() const { return has_d ? d : has_tr ? 1.0 - tr : 1.0; }
};

/// Parses "map_Kd [options] file". Options this renderer applies: -s and -o (u, v; w ignored),
/// -clamp and -colorspace. Those that change the look but are not applied (-mm, -t, -cc on) are
/// warned about; those without meaning for a colour map here (-bm, -blendu, -blendv, -boost,
/// -texres, -imfchan, -type) are skipped quietly. The file name is the rest of the line (names
/// may hold spaces).
void parse_map_kd(std::string_view rest, ObjMaterial& m, const std::function<void(const std::string&)>& bad,
                  const std::function<void(const std::string&)>& warn) {
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
                if (!std::isfinite(value)) bad("map_Kd " + std::string(option) + " values must be finite");
                numbers.push_back(value);
                after = probe;
            }
        }
        rest = trim_blanks(after);
        if (known == kOptions.end()) {
            warn("map_Kd option '" + std::string(option) + "' is unknown; ignored");
        } else if (option == "-s" || option == "-o") {
            glm::vec2& v = option == "-s" ? m.uv_scale : m.uv_offset;
            for (std::size_t i = 0; i < numbers.size() && i < 2; ++i)
                v[static_cast<int>(i)] = static_cast<float>(numbers[i]);
        } else if (option == "-clamp") {
            m.clamp = word == "on";
        } else if (option == "-colorspace") {
            m.linear = word == "linear";
        } else if ((option == "-mm" && !numbers.empty() &&
                    (numbers[0] != 0.0 || (numbers.size() > 1 && numbers[1] != 1.0))) ||
                   (option == "-t" && std::any_of(numbers.begin(), numbers.end(), [](double x) { return x != 0.0; })) ||
                   (option == "-cc" && word == "on")) {
            warn("map_Kd option " + std::string(option) + " is not supported; the texture is drawn without it");
        }
    }
    m.map_kd = std::string(rest);
    if (m.map_kd.empty()) warn("map_Kd names no file; drawn without a texture");
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
            warn("map_d (an alpha mask) is not supported; drawn with the constant dissolve");
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
/// ear clipping cannot finish (a self-intersecting or degenerate polygon) is fanned, and
/// `fanned` is set.
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

/// The texture of a material's map_Kd: the file relative to its MTL file's folder (as MTL files
/// mean it), else the OBJ's (see locate), decoded as sRGB unless -colorspace linear, its alpha
/// used only when the material blends (d < 1), as glTF does for alphaMode BLEND; a file found
/// elsewhere than written is used with a warning, and a missing or unreadable one becomes the
/// error texture with a warning.
Texture map_kd_texture(const std::string& obj_path, const ObjMaterial& m, std::vector<std::string>& warnings) {
    const std::string where = m.mtl_path + ": material '" + m.name + "': ";
    std::vector<std::string> dirs = {directory_of(m.mtl_path)};
    if (directory_of(obj_path) != dirs[0]) dirs.push_back(directory_of(obj_path));
    std::string file = locate(m.map_kd, dirs);
    std::string as_written = m.map_kd;
    std::replace(as_written.begin(), as_written.end(), '\\', '/');
    if (!is_drive_path(as_written) && (as_written.empty() || as_written[0] != '/')) as_written = dirs[0] + as_written;
    if (file.empty()) {
        file = as_written;
    } else if (std::filesystem::path(file).lexically_normal() != std::filesystem::path(as_written).lexically_normal()) {
        warnings.push_back(where + "map_Kd '" + m.map_kd + "' is not at '" + as_written + "'; using '" + file + "'");
    }
    TextureFileOptions options;
    options.ignore_alpha = m.dissolve() >= 1.0;
    options.srgb = !m.linear;
    try {
        return load_texture(file, options);
    } catch (const std::exception& e) {  // missing, unreadable, corrupt or too large
        warnings.push_back(where + "cannot load its map_Kd texture '" + file + "' (" + e.what() +
                           "); drawing the error texture instead");
        return error_texture();
    }
}

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
    auto is_textured = [&](int material) { return material >= 0 && !materials[material].map_kd.empty(); };

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
                                 " polygon(s) are self-intersecting or degenerate; triangulated as fans");

    // Step 2: one compact mesh and draw per group; vertices are split by their (position,
    // texture coordinate, normal) indices, those the group keeps.
    std::map<int, Texture> textures;  // by material
    for (ObjGroup& g : groups) {
        const std::string name = material_name(g.material);
        const bool keep_uvs = g.all_uvs && (g.textured || !is_textured(g.material));
        const bool keep_normals = g.all_normals;
        if (is_textured(g.material) && !g.textured)
            scene.warnings.push_back(path + ": " + name + ": " + std::to_string(g.triangles.size()) +
                                     " triangle(s) have no texture coordinates; they are drawn without its map_Kd "
                                     "texture");

        // The material's map_Kd -s / -o scale and offset the uvs (an affine map, exact per vertex).
        glm::vec2 uv_scale(1.0f), uv_offset(0.0f);
        if (g.textured) {
            uv_scale = materials[g.material].uv_scale;
            uv_offset = materials[g.material].uv_offset;
        }

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
                        const glm::vec2 uv = vt * uv_scale + uv_offset;
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
            draw.texture = it->second;
            if (materials[g.material].clamp) draw.sampler.wrap_u = draw.sampler.wrap_v = WrapMode::clamp;
        }
        scene.meshes.push_back(std::move(mesh));
        scene.draws.push_back(draw);
    }
    return scene;
}

// ---------------------------------------------------------------------------------------------
// glTF
// ---------------------------------------------------------------------------------------------

/// The encoded bytes of data-URI images, by image index, kept by keep_data_uri_image.
struct EmbeddedImages {
    std::map<int, std::vector<unsigned char>> bytes;
};

// tinygltf's image callback: decode nothing (textures are decoded by the io module's
// load_texture through OpenImageIO). Only data-URI images are kept, as encoded bytes: external
// files are read again relative to the glTF file by load_texture (which shares them), and
// bufferView images are read from their buffer, with bounds checks, by the loader (tinygltf
// passes a pointer it has not checked, so it is not touched here).
bool keep_data_uri_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                         const unsigned char* bytes, int size, void* user) {
    if (image->uri.empty() && image->bufferView < 0 && bytes != nullptr && size > 0)
        static_cast<EmbeddedImages*>(user)->bytes[index].assign(bytes, bytes + size);
    return true;
}

/// A URI reference with its %XX escapes decoded (glTF URIs are percent-encoded); an invalid
/// escape is kept as it is.
std::string percent_decode(const std::string& uri) {
    auto hex = [](char c) {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
            out += static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

/// Reads an accessor's elements as doubles (normalized integers mapped to [0, 1] / [−1, 1]),
/// after checking that every byte it names lies inside its buffer. A sparse accessor is
/// materialized first into an owned, tightly packed copy, which is then read like a dense one.
class AccessorReader {
public:
    AccessorReader(const tinygltf::Model& model, int index, const std::string& path, const std::string& what)
        : path_(path), what_(what) {
        if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
            fail(path, what + ": accessor " + std::to_string(index) + " does not exist (the file has " +
                           std::to_string(model.accessors.size()) + ")");
        const tinygltf::Accessor& a = model.accessors[index];
        what_ = what + " (accessor " + std::to_string(index) + (a.name.empty() ? "" : " '" + a.name + "'") + ")";
        count_ = a.count;
        components_ = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
        component_type_ = a.componentType;
        size_ = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
        normalized_ = a.normalized;
        if (components_ <= 0 || components_ > 4 || size_ <= 0)
            fail(path, what_ + ": unsupported type " + std::to_string(a.type) + " / component type " +
                           std::to_string(a.componentType));
        if (count_ > kMaxElements) fail(path, what_ + ": absurd count " + std::to_string(count_));
        if (a.sparse.isSparse) {
            materialize_sparse(model, a);
        } else if (count_ > 0) {
            read_dense(model, a);
        }
    }
    // data_ may point into owned_: a copy would point into the original's.
    AccessorReader(const AccessorReader&) = delete;
    AccessorReader& operator=(const AccessorReader&) = delete;

    std::size_t count() const { return count_; }
    int components() const { return components_; }
    int component_type() const { return component_type_; }
    bool normalized() const { return normalized_; }
    const std::string& what() const { return what_; }

    double get(std::size_t i, int c) const {
        const unsigned char* p = data_ + i * stride_ + static_cast<std::size_t>(c) * size_;
        switch (component_type_) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: return load<float>(p);
            case TINYGLTF_COMPONENT_TYPE_DOUBLE: return load<double>(p);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return scaled(load<std::uint8_t>(p), 255.0);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return scaled(load<std::uint16_t>(p), 65535.0);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return static_cast<double>(load<std::uint32_t>(p));
            case TINYGLTF_COMPONENT_TYPE_BYTE: return signed_scaled(load<std::int8_t>(p), 127.0);
            case TINYGLTF_COMPONENT_TYPE_SHORT: return signed_scaled(load<std::int16_t>(p), 32767.0);
            case TINYGLTF_COMPONENT_TYPE_INT: return static_cast<double>(load<std::int32_t>(p));
            default: fail(path_, what_ + ": unsupported component type " + std::to_string(component_type_));
        }
    }

    /// An unsigned integer element (indices), unscaled.
    std::uint64_t get_index(std::size_t i) const {
        const unsigned char* p = data_ + i * stride_;
        switch (component_type_) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load<std::uint8_t>(p);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load<std::uint16_t>(p);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return load<std::uint32_t>(p);
            default:
                fail(path_, what_ + ": indices must be unsigned byte, short or int, got component type " +
                                std::to_string(component_type_));
        }
    }

private:
    template <class T>
    static T load(const unsigned char* p) {
        T v;
        std::memcpy(&v, p, sizeof v);
        return v;
    }
    double scaled(double v, double max) const { return normalized_ ? v / max : v; }
    double signed_scaled(double v, double max) const { return normalized_ ? std::max(v / max, -1.0) : v; }

    std::size_t element_size() const { return static_cast<std::size_t>(components_) * static_cast<std::size_t>(size_); }

    /// Buffer view `index`, after checking that it and its buffer exist and that it lies inside the
    /// buffer; `part` ("" or "sparse indices: " / "sparse values: ") says which part of the accessor
    /// uses it.
    const tinygltf::BufferView& checked_view(const tinygltf::Model& model, int index, const std::string& part) const {
        if (index < 0 || static_cast<std::size_t>(index) >= model.bufferViews.size())
            fail(path_, what_ + ": " + part + "buffer view " + std::to_string(index) + " does not exist");
        const tinygltf::BufferView& view = model.bufferViews[index];
        if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size())
            fail(path_, what_ + ": " + part + "buffer " + std::to_string(view.buffer) + " does not exist");
        const std::size_t buffer_size = model.buffers[view.buffer].data.size();
        if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset)
            fail(path_, what_ + ": " + part + "buffer view " + std::to_string(index) + " (offset " +
                            std::to_string(view.byteOffset) + ", length " + std::to_string(view.byteLength) +
                            ") lies outside its buffer of " + std::to_string(buffer_size) + " bytes");
        return view;
    }

    /// The bytes [offset, offset + needed) of buffer view `index`, which hold `elements` elements,
    /// after checking that they lie inside the view (and the view inside its buffer).
    const unsigned char* view_range(const tinygltf::Model& model, int index, std::size_t offset, std::size_t needed,
                                    std::size_t elements, const std::string& part) const {
        const tinygltf::BufferView& view = checked_view(model, index, part);
        if (offset > view.byteLength || needed > view.byteLength - offset)
            fail(path_, what_ + ": " + part + std::to_string(elements) + " elements need " + std::to_string(needed) +
                            " bytes from byte offset " + std::to_string(offset) + ", buffer view " +
                            std::to_string(index) + " has " + std::to_string(view.byteLength));
        return model.buffers[view.buffer].data.data() + view.byteOffset + offset;
    }

    /// Points data_ at the accessor's count_ (> 0) elements in its buffer view, stride_ apart.
    void read_dense(const tinygltf::Model& model, const tinygltf::Accessor& a) {
        const tinygltf::BufferView& view = checked_view(model, a.bufferView, "");
        const std::size_t element = element_size();
        stride_ = view.byteStride ? view.byteStride : element;
        if (stride_ < element || stride_ > 252 + element)
            fail(path_, what_ + ": byte stride " + std::to_string(view.byteStride) + " is invalid");
        // count ≤ 2^32 and stride ≤ 256: the product does not overflow.
        data_ = view_range(model, a.bufferView, a.byteOffset, (count_ - 1) * stride_ + element, count_, "");
    }

    /// A sparse accessor (glTF 2.0 §3.6.2.3) copied into owned_, tightly packed: the base values
    /// from its buffer view (zeros when it has none), then element sparse.indices[k] replaced by
    /// sparse.values[k]. The indices must be unsigned byte/short/int, strictly increasing and below
    /// count; both arrays are tightly packed in their views.
    void materialize_sparse(const tinygltf::Model& model, const tinygltf::Accessor& a) {
        const auto& sparse = a.sparse;
        if (sparse.count < 1)
            fail(path_, what_ + ": sparse count " + std::to_string(sparse.count) + " must be at least 1");
        const std::size_t n = static_cast<std::size_t>(sparse.count);
        if (n > count_)
            fail(path_, what_ + ": sparse count " + std::to_string(n) + " is larger than the accessor's count " +
                            std::to_string(count_));
        const int index_type = sparse.indices.componentType;
        if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(path_, what_ + ": sparse indices must be unsigned byte, short or int, got component type " +
                            std::to_string(index_type));
        if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0)
            fail(path_, what_ + ": sparse byte offsets must not be negative");

        const std::size_t element = element_size();
        // Without a base view, a few bytes of JSON can ask for count × element bytes of zeros.
        check_memory(static_cast<std::uint64_t>(count_) * element, path_ + ": " + what_ + " (a sparse accessor)");
        owned_.assign(count_ * element, 0);
        if (a.bufferView >= 0) {
            read_dense(model, a);
            for (std::size_t i = 0; i < count_; ++i) std::memcpy(&owned_[i * element], data_ + i * stride_, element);
        }
        const std::size_t index_size = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(index_type));
        const unsigned char* indices = view_range(model, sparse.indices.bufferView, sparse.indices.byteOffset,
                                                  n * index_size, n, "sparse indices: ");
        const unsigned char* values = view_range(model, sparse.values.bufferView, sparse.values.byteOffset,
                                                 n * element, n, "sparse values: ");
        for (std::size_t k = 0; k < n; ++k) {
            const std::uint64_t i = unsigned_at(indices + k * index_size, index_type);
            if (i >= count_)
                fail(path_, what_ + ": sparse index " + std::to_string(i) + " (element " + std::to_string(k) +
                                ") is out of range (the accessor's count is " + std::to_string(count_) + ")");
            if (k > 0 && i <= unsigned_at(indices + (k - 1) * index_size, index_type))
                fail(path_, what_ + ": sparse indices are not strictly increasing: " +
                                std::to_string(unsigned_at(indices + (k - 1) * index_size, index_type)) +
                                " is followed by " + std::to_string(i) + " (element " + std::to_string(k) + ")");
            std::memcpy(&owned_[i * element], values + k * element, element);
        }
        data_ = owned_.data();
        stride_ = element;
    }

    /// The unsigned integer of component type `type` (unsigned byte, short or int) at p.
    static std::uint64_t unsigned_at(const unsigned char* p, int type) {
        switch (type) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load<std::uint8_t>(p);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load<std::uint16_t>(p);
            default: return load<std::uint32_t>(p);
        }
    }

    std::string path_, what_;
    std::vector<unsigned char> owned_;  // a sparse accessor's materialized elements
    const unsigned char* data_ = nullptr;
    std::size_t count_ = 0, stride_ = 0;
    int components_ = 0, component_type_ = 0, size_ = 0;
    bool normalized_ = false;
};

glm::dmat4 node_matrix(const tinygltf::Node& node, const std::string& path, int index) {
    const std::string what = "node " + std::to_string(index) + " ('" + node.name + "')";
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) fail(path, what + ": matrix must have 16 numbers");
        glm::dmat4 m;
        for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = node.matrix[i];  // column-major, as glTF stores it
        return m;
    }
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    if (!node.translation.empty()) {
        if (node.translation.size() != 3) fail(path, what + ": translation must have 3 numbers");
        t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    if (!node.rotation.empty()) {
        if (node.rotation.size() != 4) fail(path, what + ": rotation must have 4 numbers");
        glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);  // (w, x, y, z)
        const double len = glm::length(q);
        if (!(len > 0.0) || !std::isfinite(len)) fail(path, what + ": rotation is not a valid quaternion");
        r = glm::mat4_cast(q / len);
    }
    if (!node.scale.empty()) {
        if (node.scale.size() != 3) fail(path, what + ": scale must have 3 numbers");
        s[0][0] = node.scale[0];
        s[1][1] = node.scale[1];
        s[2][2] = node.scale[2];
    }
    return t * r * s;
}

/// Whether a primitive mode is one of triangles (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN; −1: not
/// given, TRIANGLES) rather than POINTS, LINES, LINE_LOOP, LINE_STRIP or a value glTF does not define.
bool draws_triangles(int mode) {
    return mode == -1 || mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
           mode == TINYGLTF_MODE_TRIANGLE_FAN;
}

/// Which texture coordinate set (TEXCOORD_<set>) becomes a primitive's uvs, and the affine map
/// that KHR_texture_transform applies to it: uv' = T(offset)·R(rotation)·S(scale)·uv.
struct UvChoice {
    int set = 0;
    bool transformed = false;  // (the identity is skipped: it would turn an infinite v into NaN u)
    glm::dvec2 offset{0.0}, scale{1.0};
    double rotation = 0.0;

    /// The transformed uv. R is [[cos, sin], [−sin, cos]] (row by row), the rotation Khronos'
    /// sample models, Blender and three.js use: the extension's GLSL listing fills a column-major
    /// mat3 with the same numbers, which reads as the transpose (KhronosGroup/glTF issue #1563);
    /// its example (offset (0, 1), rotation π/2, scale ½ selects the lower-left quadrant) agrees
    /// with this form only.
    glm::vec2 apply(glm::dvec2 uv) const {
        const double c = std::cos(rotation), s = std::sin(rotation);
        const glm::dvec2 scaled = uv * scale;
        return glm::vec2(c * scaled.x + s * scaled.y + offset.x, -s * scaled.x + c * scaled.y + offset.y);
    }
};

struct GltfLoader {
    const tinygltf::Model& model;
    const std::string& path;
    const EmbeddedImages& embedded;
    LoadedScene scene;
    std::map<std::pair<int, int>, std::shared_ptr<Mesh>> mesh_cache;  // (mesh, primitive) → mesh
    std::map<std::pair<int, bool>, Texture> texture_cache;            // (image, ignore alpha) → texture
    std::set<std::string> warned;                                     // warnings given once
    std::size_t skipped_primitives = 0;
    std::vector<bool> on_path;  // nodes on the current root-to-node path (cycle detection)
    bool quantized = false;     // the file uses KHR_mesh_quantization (integer texture coordinates)

    GltfLoader(const tinygltf::Model& m, const std::string& p, const EmbeddedImages& e)
        : model(m), path(p), embedded(e), on_path(m.nodes.size(), false) {
        const auto lists = [&](const std::vector<std::string>& names) {
            return std::find(names.begin(), names.end(), "KHR_mesh_quantization") != names.end();
        };
        quantized = lists(m.extensionsUsed) || lists(m.extensionsRequired);
    }

    void warn_once(const std::string& message) {
        if (warned.insert(message).second) scene.warnings.push_back(path + ": " + message);
    }

    static std::string material_name(const tinygltf::Material& mat, int index) {
        const std::string where = "materials[" + std::to_string(index) + "]";
        return mat.name.empty() ? "material " + where : "material '" + mat.name + "' (" + where + ")";
    }

    /// The draw's colour, blending, culling, base colour texture and sampler from its material.
    void apply_material(Draw& draw, const tinygltf::Primitive& prim, int mesh_index, int prim_index) {
        const std::string prim_what =
            "meshes[" + std::to_string(mesh_index) + "].primitives[" + std::to_string(prim_index) + "]";
        if (prim.material < 0) {
            draw.state.cull = CullMode::back;  // the default material is single-sided
            return;
        }
        if (static_cast<std::size_t>(prim.material) >= model.materials.size())
            fail(path, prim_what + ": material " + std::to_string(prim.material) + " does not exist (the file has " +
                           std::to_string(model.materials.size()) + ")");
        const tinygltf::Material& mat = model.materials[prim.material];
        const std::string name = material_name(mat, prim.material);
        const std::vector<double>& f = mat.pbrMetallicRoughness.baseColorFactor;
        if (f.size() != 4) fail(path, name + ": baseColorFactor must have 4 numbers");
        for (double v : f)
            if (!std::isfinite(v)) fail(path, name + ": baseColorFactor is not finite");
        const bool blend = mat.alphaMode == "BLEND";
        if (blend) {
            draw.color = glm::vec4(f[0] * f[3], f[1] * f[3], f[2] * f[3], f[3]);
            draw.state.blend = BlendMode::over;
        } else {
            draw.color = glm::vec4(f[0], f[1], f[2], 1.0);
        }
        if (!mat.doubleSided) draw.state.cull = CullMode::back;

        // Base colour texture, on the uvs base_color_uvs chose (and transformed) for the mesh.
        const tinygltf::TextureInfo& info = mat.pbrMetallicRoughness.baseColorTexture;
        if (info.index < 0) return;
        if (static_cast<std::size_t>(info.index) >= model.textures.size())
            fail(path, name + ": baseColorTexture index " + std::to_string(info.index) +
                           " does not exist (the file has " + std::to_string(model.textures.size()) + " textures)");
        const tinygltf::Texture& tex = model.textures[info.index];
        const std::string tex_what = "textures[" + std::to_string(info.index) + "]";
        Sampler sampler = sampler_of(tex.sampler, tex_what);  // checks the index even when unused below
        if (tex.source >= 0 && static_cast<std::size_t>(tex.source) >= model.images.size())
            fail(path, tex_what + ": source image " + std::to_string(tex.source) + " does not exist (the file has " +
                           std::to_string(model.images.size()) + " images)");
        if (!draw.mesh->has_uvs()) {
            warn_once(prim_what + " has no TEXCOORD_" + std::to_string(base_color_uvs(prim.material).set) +
                      " but its " + name +
                      " has a baseColorTexture; drawn without the texture");
            return;
        }
        if (tex.source < 0) {
            warn_once(tex_what + " (used by " + name +
                      ") has no source image (only extension images such as KTX2/WebP?); drawn without it");
            return;
        }
        draw.texture = image_texture(tex.source, name, /*ignore_alpha=*/!blend);
        draw.sampler = sampler;
    }

    /// glTF sampler → Sampler. Undefined filters keep the library default (trilinear); undefined
    /// wraps are REPEAT. Unknown enum values are warned about and replaced by the defaults.
    Sampler sampler_of(int index, const std::string& tex_what) {
        Sampler s;
        if (index < 0) return s;
        if (static_cast<std::size_t>(index) >= model.samplers.size())
            fail(path, tex_what + ": sampler " + std::to_string(index) + " does not exist (the file has " +
                           std::to_string(model.samplers.size()) + " samplers)");
        const tinygltf::Sampler& g = model.samplers[index];
        const std::string what = "samplers[" + std::to_string(index) + "]";
        auto wrap = [&](int mode, const char* field) {
            switch (mode) {
                case TINYGLTF_TEXTURE_WRAP_REPEAT: return WrapMode::repeat;
                case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return WrapMode::clamp;
                case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return WrapMode::mirror;
                default:
                    warn_once(what + ": " + field + " " + std::to_string(mode) + " is not a glTF wrap mode; using REPEAT");
                    return WrapMode::repeat;
            }
        };
        s.wrap_u = wrap(g.wrapS, "wrapS");
        s.wrap_v = wrap(g.wrapT, "wrapT");
        switch (g.magFilter) {
            case -1: break;
            case TINYGLTF_TEXTURE_FILTER_NEAREST: s.mag_filter = TexelFilter::nearest; break;
            case TINYGLTF_TEXTURE_FILTER_LINEAR: s.mag_filter = TexelFilter::linear; break;
            default:
                warn_once(what + ": magFilter " + std::to_string(g.magFilter) + " is not a glTF filter; using LINEAR");
        }
        // minFilter = texel filter within a level + filter between levels.
        switch (g.minFilter) {
            case -1: break;
            case TINYGLTF_TEXTURE_FILTER_NEAREST: s.min_filter = TexelFilter::nearest, s.mip_filter = MipFilter::none; break;
            case TINYGLTF_TEXTURE_FILTER_LINEAR: s.min_filter = TexelFilter::linear, s.mip_filter = MipFilter::none; break;
            case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
                s.min_filter = TexelFilter::nearest, s.mip_filter = MipFilter::nearest;
                break;
            case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
                s.min_filter = TexelFilter::linear, s.mip_filter = MipFilter::nearest;
                break;
            case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
                s.min_filter = TexelFilter::nearest, s.mip_filter = MipFilter::linear;
                break;
            case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR:
                s.min_filter = TexelFilter::linear, s.mip_filter = MipFilter::linear;
                break;
            default:
                warn_once(what + ": minFilter " + std::to_string(g.minFilter) +
                          " is not a glTF filter; using LINEAR_MIPMAP_LINEAR");
        }
        return s;
    }

    /// The texture of image `index` (sRGB colour; alpha ignored for opaque materials), decoded once
    /// per load. An image that cannot be read gives the error texture and a warning naming the
    /// material and the file; an image whose bufferView lies outside its buffer is an error.
    Texture image_texture(int index, const std::string& material, bool ignore_alpha) {
        const auto key = std::make_pair(index, ignore_alpha);
        if (auto it = texture_cache.find(key); it != texture_cache.end()) return it->second;
        const tinygltf::Image& image = model.images[index];
        const std::string what = "images[" + std::to_string(index) + "]" + (image.name.empty() ? "" : " ('" + image.name + "')");
        TextureFileOptions options;
        options.srgb = true;  // glTF base colour textures are sRGB
        options.ignore_alpha = ignore_alpha;
        Texture texture;
        std::string source;  // the file or the embedded image, for the warning
        const unsigned char* view_bytes = nullptr;
        std::size_t view_size = 0;
        if (image.uri.empty() && image.bufferView >= 0)
            buffer_view_bytes(image.bufferView, what, view_bytes, view_size);  // a bad view is an error, not a warning
        try {
            if (!image.uri.empty()) {
                if (image.uri.rfind("data:", 0) == 0) {  // tinygltf decodes PNG, JPEG, BMP and GIF data URIs only
                    source = what + " (data URI)";
                    const std::string type = image.uri.substr(5, std::min<std::size_t>(image.uri.find_first_of(";,"), 64) - 5);
                    throw std::runtime_error("data URI of media type '" + type + "' is not supported");
                }
                const std::string uri = percent_decode(image.uri);
                source = "'" + uri + "'";
                if (uri.find("://") != std::string::npos)
                    throw std::runtime_error("only relative file URIs are supported");
                source = "'" + directory_of(path) + uri + "'";
                texture = load_texture(directory_of(path) + uri, options);
            } else if (image.bufferView >= 0) {
                source = what + " (bufferView " + std::to_string(image.bufferView) + ")";
                texture = load_texture_from_memory(view_bytes, view_size, path + " " + what, options);
            } else {
                source = what + " (data URI)";
                const auto it = embedded.bytes.find(index);
                if (it == embedded.bytes.end()) throw std::runtime_error("the data URI holds no bytes");
                texture = load_texture_from_memory(it->second.data(), it->second.size(), path + " " + what, options);
            }
        } catch (const std::exception& e) {  // missing, unreadable, corrupt or too large
            warn_once(material + ": cannot load its base colour texture " + source + " (" + e.what() +
                      "); drawing the error texture instead");
            texture = error_texture();
        }
        texture_cache.emplace(key, texture);
        return texture;
    }

    /// The bytes of a bufferView, after checking that they lie inside its buffer.
    void buffer_view_bytes(int index, const std::string& what, const unsigned char*& bytes, std::size_t& size) const {
        if (index < 0 || static_cast<std::size_t>(index) >= model.bufferViews.size())
            fail(path, what + ": buffer view " + std::to_string(index) + " does not exist");
        const tinygltf::BufferView& view = model.bufferViews[index];
        if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size())
            fail(path, what + ": buffer " + std::to_string(view.buffer) + " does not exist");
        const std::vector<unsigned char>& buffer = model.buffers[view.buffer].data;
        if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
            fail(path, what + ": buffer view " + std::to_string(index) + " (offset " + std::to_string(view.byteOffset) +
                           ", length " + std::to_string(view.byteLength) + ") lies outside its buffer of " +
                           std::to_string(buffer.size()) + " bytes");
        bytes = buffer.data() + view.byteOffset;
        size = view.byteLength;
    }

    bool material_blends(int material) const {
        return material >= 0 && static_cast<std::size_t>(material) < model.materials.size() &&
               model.materials[material].alphaMode == "BLEND";
    }

    /// The primitive's vertices in drawing order: its indices (any unsigned component type, each
    /// checked against the vertex count), or 0, 1, …, vertex_count − 1 when it has none.
    std::vector<std::uint32_t> vertex_sequence(const tinygltf::Primitive& prim, std::size_t vertex_count,
                                               const std::string& what) const {
        std::vector<std::uint32_t> sequence;
        if (prim.indices < 0) {
            sequence.resize(vertex_count);
            for (std::size_t i = 0; i < vertex_count; ++i) sequence[i] = static_cast<std::uint32_t>(i);
            return sequence;
        }
        const AccessorReader idx(model, prim.indices, path, what + " indices");
        if (idx.components() != 1) fail(path, idx.what() + ": indices must be SCALAR");
        sequence.resize(idx.count());
        for (std::size_t i = 0; i < idx.count(); ++i) {
            const std::uint64_t v = idx.get_index(i);
            if (v >= vertex_count)
                fail(path, idx.what() + ": index " + std::to_string(v) + " (element " + std::to_string(i) +
                               ") is out of range (" + std::to_string(vertex_count) + " vertices)");
            sequence[i] = static_cast<std::uint32_t>(v);
        }
        return sequence;
    }

    /// The triangles of a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN vertex sequence v, in the order
    /// of the glTF 2.0 spec (§3.7.2.1): strip triangle i is (v[i], v[i+1+i%2], v[i+2−i%2]), i.e. odd
    /// triangles swap their last two vertices so that all keep the strip's winding (back-face
    /// culling depends on it); fan triangle i is (v[i+1], v[i+2], v[0]). Leftover vertices (a
    /// TRIANGLES count that is no multiple of 3) and strips or fans of fewer than 3 vertices give
    /// a warning.
    std::vector<glm::uvec3> assemble_triangles(int mode, const std::vector<std::uint32_t>& v,
                                               const std::string& what) {
        const std::size_t n = v.size();
        std::vector<glm::uvec3> triangles;
        if (mode == TINYGLTF_MODE_TRIANGLES || mode == -1) {
            if (n % 3 != 0)
                scene.warnings.push_back(path + ": " + what + ": vertex count " + std::to_string(n) +
                                         " is not a multiple of 3; the last vertices are ignored");
            triangles.resize(n / 3);
            for (std::size_t t = 0; t < triangles.size(); ++t) triangles[t] = {v[3 * t], v[3 * t + 1], v[3 * t + 2]};
            return triangles;
        }
        const bool strip = mode == TINYGLTF_MODE_TRIANGLE_STRIP;
        if (n < 3) {
            scene.warnings.push_back(path + ": " + what + ": a triangle " + (strip ? "strip" : "fan") + " of " +
                                     std::to_string(n) + " vertices has no triangle");
            return triangles;
        }
        triangles.resize(n - 2);
        for (std::size_t i = 0; i < n - 2; ++i)
            triangles[i] = strip ? glm::uvec3(v[i], v[i + 1 + i % 2], v[i + 2 - i % 2])
                                 : glm::uvec3(v[i + 1], v[i + 2], v[0]);
        return triangles;
    }

    /// The texture coordinate set the base colour texture of material `material` reads
    /// (baseColorTexture.texCoord, or its KHR_texture_transform's texCoord) and that extension's
    /// transform; set 0 and the identity for no material, an untextured one or one that does not
    /// exist (apply_material reports that). Malformed transform values are an error naming the
    /// material.
    UvChoice base_color_uvs(int material) const {
        UvChoice choice;
        if (material < 0 || static_cast<std::size_t>(material) >= model.materials.size()) return choice;
        const tinygltf::Material& mat = model.materials[material];
        const tinygltf::TextureInfo& info = mat.pbrMetallicRoughness.baseColorTexture;
        if (info.index < 0) return choice;
        choice.set = info.texCoord;
        const auto ext = info.extensions.find("KHR_texture_transform");
        if (ext == info.extensions.end()) return choice;

        choice.transformed = true;
        const std::string what = material_name(mat, material) + ": KHR_texture_transform ";
        const tinygltf::Value& t = ext->second;  // (an object: tinygltf drops extensions that are not)
        const auto finite_number = [](const tinygltf::Value& v) {
            return v.IsNumber() && std::isfinite(v.GetNumberAsDouble());
        };
        const auto pair = [&](const char* key, glm::dvec2 value) {
            if (!t.Has(key)) return value;
            const tinygltf::Value& v = t.Get(key);
            if (!v.IsArray() || v.ArrayLen() != 2 || !finite_number(v.Get(0)) || !finite_number(v.Get(1)))
                fail(path, what + key + " must be 2 finite numbers");
            return glm::dvec2(v.Get(0).GetNumberAsDouble(), v.Get(1).GetNumberAsDouble());
        };
        choice.offset = pair("offset", choice.offset);
        choice.scale = pair("scale", choice.scale);
        if (t.Has("rotation")) {
            if (!finite_number(t.Get("rotation"))) fail(path, what + "rotation must be a finite number");
            choice.rotation = t.Get("rotation").GetNumberAsDouble();
        }
        if (t.Has("texCoord")) {  // overrides the textureInfo's
            const tinygltf::Value& v = t.Get("texCoord");
            if (!v.IsInt() || v.GetNumberAsInt() < 0) fail(path, what + "texCoord must be an integer >= 0");
            choice.set = v.GetNumberAsInt();
        }
        return choice;
    }

    /// Whether a TEXCOORD_n component type is allowed: float or normalized unsigned byte/short
    /// (glTF 2.0), and in files that use KHR_mesh_quantization also byte and short (normalized or
    /// not) and unnormalized unsigned byte/short, read as their integer values.
    bool texcoord_type_allowed(int type, bool normalized) const {
        if (type == TINYGLTF_COMPONENT_TYPE_FLOAT) return true;
        const bool small_unsigned =
            type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        if (small_unsigned && normalized) return true;
        return quantized &&
               (small_unsigned || type == TINYGLTF_COMPONENT_TYPE_BYTE || type == TINYGLTF_COMPONENT_TYPE_SHORT);
    }

    std::shared_ptr<Mesh> primitive_mesh(int mesh_index, int prim_index) {
        const auto key = std::make_pair(mesh_index, prim_index);
        if (auto it = mesh_cache.find(key); it != mesh_cache.end()) return it->second;
        const tinygltf::Primitive& prim = model.meshes[mesh_index].primitives[prim_index];
        const std::string what = "meshes[" + std::to_string(mesh_index) + "].primitives[" + std::to_string(prim_index) + "]";
        auto mesh = std::make_shared<Mesh>();

        // Positions.
        const auto pos_it = prim.attributes.find("POSITION");
        if (pos_it == prim.attributes.end()) fail(path, what + ": no POSITION attribute");
        const AccessorReader pos(model, pos_it->second, path, what + " POSITION");
        if (pos.components() != 3) fail(path, pos.what() + ": POSITION must be VEC3");
        mesh->positions.resize(pos.count());
        for (std::size_t i = 0; i < pos.count(); ++i)
            mesh->positions[i] = glm::vec3(pos.get(i, 0), pos.get(i, 1), pos.get(i, 2));

        // Vertex colours (linear); premultiplied by their alpha when the material blends,
        // opaque otherwise (alpha is ignored for OPAQUE/MASK materials).
        if (const auto col_it = prim.attributes.find("COLOR_0"); col_it != prim.attributes.end()) {
            const AccessorReader col(model, col_it->second, path, what + " COLOR_0");
            if (col.components() != 3 && col.components() != 4) fail(path, col.what() + ": COLOR_0 must be VEC3 or VEC4");
            const int ct = col.component_type();
            if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT &&
                !((ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) &&
                  col.normalized()))
                fail(path, col.what() + ": COLOR_0 must be float or normalized unsigned byte/short");
            if (col.count() != pos.count())
                fail(path, col.what() + ": COLOR_0 has " + std::to_string(col.count()) + " elements, POSITION " +
                               std::to_string(pos.count()));
            const bool blend = material_blends(prim.material);
            mesh->colors.resize(col.count());
            for (std::size_t i = 0; i < col.count(); ++i) {
                const double a = col.components() == 4 && blend ? col.get(i, 3) : 1.0;
                mesh->colors[i] = glm::vec4(col.get(i, 0) * a, col.get(i, 1) * a, col.get(i, 2) * a, a);
            }
        }

        // Texture coordinates: the set the material's base colour texture reads (TEXCOORD_0 when it
        // has none), with its KHR_texture_transform applied here (an affine map of the uvs commutes
        // with perspective-correct interpolation, so this is exact); float or normalized unsigned
        // byte/short (glTF's uv convention is ours). The material is this primitive's own, as is
        // this mesh (cached by (mesh, primitive)), so neither choice reaches another draw.
        const UvChoice choice = base_color_uvs(prim.material);
        const std::string uv_name = "TEXCOORD_" + std::to_string(choice.set);
        if (const auto uv_it = prim.attributes.find(uv_name); uv_it != prim.attributes.end()) {
            const AccessorReader uv(model, uv_it->second, path, what + " " + uv_name);
            if (uv.components() != 2) fail(path, uv.what() + ": " + uv_name + " must be VEC2");
            const int ct = uv.component_type();
            if (!texcoord_type_allowed(ct, uv.normalized()))
                fail(path, uv.what() + ": " + uv_name + " must be float or normalized unsigned byte/short" +
                               (quantized ? " (or byte/short, normalized or not, and unsigned byte/short with "
                                            "KHR_mesh_quantization)"
                                          : "") +
                               ", got component type " + std::to_string(ct) + (uv.normalized() ? " (normalized)" : ""));
            if (uv.count() != pos.count())
                fail(path, uv.what() + ": " + uv_name + " has " + std::to_string(uv.count()) + " elements, POSITION " +
                               std::to_string(pos.count()));
            mesh->uvs.resize(uv.count());
            for (std::size_t i = 0; i < uv.count(); ++i) {
                const glm::dvec2 value(uv.get(i, 0), uv.get(i, 1));
                mesh->uvs[i] = choice.transformed ? choice.apply(value) : glm::vec2(value);
            }
        }

        // Normals: float (or normalized signed byte/short, as KHR_mesh_quantization allows).
        if (const auto n_it = prim.attributes.find("NORMAL"); n_it != prim.attributes.end()) {
            const AccessorReader nrm(model, n_it->second, path, what + " NORMAL");
            if (nrm.components() != 3) fail(path, nrm.what() + ": NORMAL must be VEC3");
            const int ct = nrm.component_type();
            if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT &&
                !((ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_SHORT) && nrm.normalized()))
                fail(path, nrm.what() + ": NORMAL must be float or normalized byte/short, got component type " +
                               std::to_string(ct));
            if (nrm.count() != pos.count())
                fail(path, nrm.what() + ": NORMAL has " + std::to_string(nrm.count()) + " elements, POSITION " +
                               std::to_string(pos.count()));
            mesh->normals.resize(nrm.count());
            for (std::size_t i = 0; i < nrm.count(); ++i)
                mesh->normals[i] = glm::vec3(nrm.get(i, 0), nrm.get(i, 1), nrm.get(i, 2));
        }

        // Triangles: the vertex sequence (the indices, or the vertices in order) assembled by mode.
        mesh->triangles = assemble_triangles(prim.mode, vertex_sequence(prim, pos.count(), what), what);
        mesh->validate(path + " " + what);
        scene.meshes.push_back(mesh);
        mesh_cache.emplace(key, mesh);
        return mesh;
    }

    void add_node(int index, const glm::dmat4& parent, int depth) {
        if (index < 0 || static_cast<std::size_t>(index) >= model.nodes.size())
            fail(path, "node " + std::to_string(index) + " does not exist (the file has " +
                           std::to_string(model.nodes.size()) + " nodes)");
        if (on_path[index] || depth > kMaxNodeDepth)
            fail(path, "node " + std::to_string(index) + " is its own ancestor (a cycle in the node hierarchy)");
        on_path[index] = true;
        const tinygltf::Node& node = model.nodes[index];
        const glm::dmat4 world = parent * node_matrix(node, path, index);
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 4; ++row)
                if (!std::isfinite(world[col][row]))
                    fail(path, "node " + std::to_string(index) + ": its world matrix is not finite");

        if (node.mesh >= 0) {
            if (static_cast<std::size_t>(node.mesh) >= model.meshes.size())
                fail(path, "node " + std::to_string(index) + ": mesh " + std::to_string(node.mesh) + " does not exist");
            const tinygltf::Mesh& m = model.meshes[node.mesh];
            for (std::size_t p = 0; p < m.primitives.size(); ++p) {
                const tinygltf::Primitive& prim = m.primitives[p];
                if (!draws_triangles(prim.mode)) {
                    ++skipped_primitives;
                    continue;
                }
                Draw draw;
                draw.mesh = primitive_mesh(node.mesh, static_cast<int>(p)).get();
                draw.model = world;
                apply_material(draw, prim, node.mesh, static_cast<int>(p));
                scene.draws.push_back(draw);
            }
        }

        if (node.camera >= 0) {
            if (static_cast<std::size_t>(node.camera) >= model.cameras.size())
                fail(path, "node " + std::to_string(index) + ": camera " + std::to_string(node.camera) + " does not exist");
            scene.cameras.push_back(make_camera(model.cameras[node.camera], node.camera, world));
        }

        for (int child : node.children) add_node(child, world, depth + 1);
        on_path[index] = false;
    }

    NamedCamera make_camera(const tinygltf::Camera& c, int index, const glm::dmat4& world) const {
        const std::string what = "camera " + std::to_string(index) + " ('" + c.name + "')";
        NamedCamera cam;
        cam.name = c.name.empty() ? "camera " + std::to_string(index) : c.name;
        cam.view = glm::inverse(world);
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 4; ++row)
                if (!std::isfinite(cam.view[col][row])) fail(path, what + ": its node's world matrix is singular");
        if (c.type == "perspective") {
            const auto& p = c.perspective;
            cam.projection = NamedCamera::Projection::perspective;
            cam.yfov = p.yfov;
            cam.aspect_ratio = p.aspectRatio;
            cam.znear = p.znear;
            cam.zfar = p.zfar > 0.0 ? p.zfar : kInfiniteFar;  // tinygltf: 0 = not given = infinite
            if (!(cam.yfov > 0.0 && cam.yfov < M_PI)) fail(path, what + ": yfov must be in (0, pi), got " + std::to_string(cam.yfov));
            if (!(cam.znear > 0.0 && std::isfinite(cam.znear))) fail(path, what + ": znear must be > 0");
            if (!(cam.zfar > cam.znear)) fail(path, what + ": zfar must be > znear");
            if (!(cam.aspect_ratio >= 0.0 && std::isfinite(cam.aspect_ratio))) fail(path, what + ": aspectRatio must be > 0");
        } else if (c.type == "orthographic") {
            const auto& o = c.orthographic;
            cam.projection = NamedCamera::Projection::orthographic;
            cam.xmag = o.xmag;
            cam.ymag = o.ymag;
            cam.znear = o.znear;
            cam.zfar = o.zfar;
            if (!(cam.xmag != 0.0 && cam.ymag != 0.0 && std::isfinite(cam.xmag) && std::isfinite(cam.ymag)))
                fail(path, what + ": xmag and ymag must be finite and non-zero");
            if (!(std::isfinite(cam.znear) && std::isfinite(cam.zfar) && cam.zfar > cam.znear && cam.znear >= 0.0))
                fail(path, what + ": expected 0 <= znear < zfar, both finite");
        } else {
            fail(path, what + ": unknown camera type '" + c.type + "'");
        }
        return cam;
    }
};

/// The glTF extensions a file may list in extensionsRequired and still load as its author meant:
/// those this loader reads (KHR_texture_transform on the base colour texture; KHR_mesh_quantization's
/// integer POSITION, NORMAL and TEXCOORD_n) and those that do not change what it draws
/// (KHR_materials_unlit: its renders are unlit anyway).
const std::set<std::string> kSupportedRequiredExtensions = {"KHR_materials_unlit", "KHR_mesh_quantization",
                                                            "KHR_texture_transform"};

/// A file that requires another extension (compressed geometry, other image formats, …) cannot
/// be drawn right: an error naming it. tinygltf only records the list, and without this the load
/// failed later on what the extension changes, e.g. "accessor[1] invalid bufferView" for Draco.
void check_required_extensions(const tinygltf::Model& model, const std::string& path) {
    for (const std::string& extension : model.extensionsRequired) {
        if (kSupportedRequiredExtensions.count(extension)) continue;
        std::string supported;
        for (const std::string& e : kSupportedRequiredExtensions) supported += (supported.empty() ? "" : ", ") + e;
        fail(path, "the file requires the glTF extension '" + extension +
                       "', which this loader does not support (it supports " + supported + ")");
    }
}

// tinygltf's FileExists callback, for regular files only: a buffer whose uri named a directory
// was opened and its "size" allocated (std::bad_alloc).
bool regular_file_exists(const std::string& path, void*) {
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}

LoadedScene load_gltf(const std::string& path, bool binary) {
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks({regular_file_exists, tinygltf::ExpandFilePath, tinygltf::ReadWholeFile,
                           tinygltf::WriteWholeFile, nullptr});
    EmbeddedImages embedded;
    loader.SetImageLoader(keep_data_uri_image, &embedded);
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    try {
        ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                    : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    } catch (const std::exception& e) {  // e.g. a JSON parser exception
        fail(path, std::string("cannot parse glTF: ") + e.what());
    }
    // tinygltf reads extensionsRequired before the buffers and accessors, so the list is there even
    // when the load failed on what an unsupported extension changes: that is the error to report.
    check_required_extensions(model, path);
    if (!ok) fail(path, "cannot read glTF: " + trim(err.empty() ? warn : err));

    GltfLoader g(model, path, embedded);
    // tinygltf's notes about external image files it could not read are dropped: images are
    // loaded (or warned about, naming the material) by image_texture.
    std::istringstream lines(warn);
    std::string kept, line;
    while (std::getline(lines, line))
        if (line.rfind("File not found : ", 0) != 0 && line.rfind("File read error : ", 0) != 0 &&
            line.rfind("File is empty : ", 0) != 0 && line.rfind("Failed to load external 'uri' for image[", 0) != 0)
            kept += line + "\n";
    add_warnings(g.scene.warnings, path, kept);

    // Roots: the default scene, else scene 0, else every node that is no other node's child.
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        int s = model.defaultScene;
        if (s < 0) s = 0;
        if (static_cast<std::size_t>(s) >= model.scenes.size())
            fail(path, "default scene " + std::to_string(s) + " does not exist");
        roots = model.scenes[s].nodes;
    } else {
        std::vector<bool> is_child(model.nodes.size(), false);
        for (const auto& n : model.nodes)
            for (int c : n.children)
                if (c >= 0 && static_cast<std::size_t>(c) < model.nodes.size()) is_child[c] = true;
        for (std::size_t i = 0; i < model.nodes.size(); ++i)
            if (!is_child[i]) roots.push_back(static_cast<int>(i));
    }
    for (int r : roots) g.add_node(r, glm::dmat4(1.0), 0);
    if (g.skipped_primitives)
        g.scene.warnings.push_back(path + ": skipped " + std::to_string(g.skipped_primitives) +
                                   " primitive(s) of mode POINTS or LINES, or of an unknown mode (only triangles "
                                   "are drawn)");
    return std::move(g.scene);
}

}  // namespace

std::string to_string(NamedCamera::Projection projection) {
    return projection == NamedCamera::Projection::perspective ? "perspective" : "orthographic";
}

Camera NamedCamera::build(double aspect) const {
    if (!(aspect > 0.0 && std::isfinite(aspect)))
        throw std::invalid_argument("NamedCamera::build: aspect must be finite and > 0, got " + std::to_string(aspect));
    Camera camera;
    camera.view = view;
    camera.depth_convention = DepthConvention::reverse_z;
    if (projection == Projection::perspective) {
        camera.projection = perspective(yfov, aspect_ratio > 0.0 ? aspect_ratio : aspect, znear, zfar);
    } else {
        camera.projection = orthographic(-xmag, xmag, -ymag, ymag, znear, zfar);
    }
    return camera;
}

std::string NamedCamera::to_string() const {
    std::ostringstream s;
    s << "NamedCamera('" << name << "', " << mipraster::to_string(projection);
    if (projection == Projection::perspective) {
        s << ", yfov=" << yfov << ", aspect_ratio=" << aspect_ratio;
    } else {
        s << ", xmag=" << xmag << ", ymag=" << ymag;
    }
    s << ", znear=" << znear << ", zfar=" << zfar << ")";
    return s.str();
}

LoadedScene load_scene(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext != ".obj" && ext != ".gltf" && ext != ".glb")
        throw std::invalid_argument("load_scene: cannot tell the format of '" + path +
                                    "' from its extension; supported: .obj, .gltf, .glb");
    LoadedScene scene = ext == ".obj" ? load_obj(path) : load_gltf(path, ext == ".glb");
    // Not an error (an empty file is a valid scene), but a render of it shows only the clear
    // colour: say so rather than leave a blank image unexplained.
    const bool any_triangle = std::any_of(scene.draws.begin(), scene.draws.end(),
                                          [](const Draw& d) { return d.mesh && !d.mesh->triangles.empty(); });
    if (!any_triangle) scene.warnings.push_back(path + ": the file holds no triangles; a render shows only the clear colour");
    return scene;
}

bool scene_bounds(const std::vector<Draw>& draws, glm::dvec3& lo, glm::dvec3& hi) {
    bool any = false;
    glm::dvec3 a(std::numeric_limits<double>::infinity()), b(-std::numeric_limits<double>::infinity());
    for (const Draw& d : draws) {
        if (!d.mesh) continue;
        for (const glm::vec3& p : d.mesh->positions) {
            const glm::dvec4 w = d.model * glm::dvec4(glm::dvec3(p), 1.0);
            if (!(std::abs(w.w) > 0.0)) continue;
            const glm::dvec3 q = glm::dvec3(w) / w.w;
            a = glm::min(a, q);
            b = glm::max(b, q);
            any = true;
        }
    }
    if (any) {
        lo = a;
        hi = b;
    }
    return any;
}

Camera framing_camera(const std::vector<Draw>& draws, double fovy, double aspect) {
    glm::dvec3 lo, hi;
    if (!scene_bounds(draws, lo, hi))
        return Camera::look_at_perspective({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, fovy, aspect, 0.01);
    const glm::dvec3 centre = (lo + hi) * 0.5;
    double radius = glm::length(hi - lo) * 0.5;
    if (!(radius > 0.0)) radius = 1.0;  // a single point (or degenerate bounds)
    // The sphere fits when its distance is radius / sin(half the narrower field of view).
    const double half_fov = std::min(fovy * 0.5, std::atan(std::tan(fovy * 0.5) * aspect));
    const double distance = radius / std::sin(half_fov);
    const glm::dvec3 direction = glm::normalize(glm::dvec3(1.0, 0.6, 1.4));
    const double near = std::max((distance - radius) * 0.5, distance * 1e-4);
    return Camera::look_at_perspective(centre + direction * distance, centre, {0, 1, 0}, fovy, aspect, near);
}

}  // namespace mipraster
