// mipraster — the command-line renderer.
//
//   mipraster compare A B [--fail T] [--fail-fraction F] [--hard-fail H]
//   mipraster bench [options]     (runs python3 -m mipraster.bench, see python_executable)
//   mipraster stress [--full] [--json FILE] [--details]
//   mipraster render [SCENE] -o OUT.png [--camera N] [--size WxH] [--spp N] [--aa ssaa|msaa] [--pattern NAME]
//                    [--look-at EX,EY,EZ,TX,TY,TZ] [--fov DEG] [--threads N]
//                    [--filter F] [--max-aniso N] [--wrap W[,W]] [--lod-bias B] [--debug-view V]
//                    [--derivatives analytic|quad] [--resolve F] [--memory-limit SIZE] [--stats] [--stats-json PATH]
//                    [--error-map PATH] [--probe-pixels N] [--quiet]
//   mipraster resize IN -o OUT --size WxH [--filter F] [--threads N] [--quiet]
//   mipraster synthesize SAMPLE -o OUT --size WxH [--window N] [--seed S] [--epsilon E] [--periodic]
//                        [--tileable] [--threads N] [--quiet]
//
// SCENE is a scene file (.obj, .gltf, .glb; see mipraster/io/scene_file.hpp); with none it
// renders the built-in demo. Usage errors exit with status 2, failures with 1; every message names the bad input.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "mipraster/core/compare.hpp"
#include "mipraster/core/memory_limit.hpp"
#include "mipraster/core/resample.hpp"
#include "mipraster/io/image_io.hpp"
#include "mipraster/io/scene_file.hpp"
#include "mipraster/pipeline/error_probe.hpp"
#include "mipraster/pipeline/renderer.hpp"
#include "mipraster/scene/demo_scene.hpp"
#include "mipraster/stress/stress_cases.hpp"
#include "mipraster/texture/synthesis.hpp"

namespace {

using namespace mipraster;

constexpr const char* kVersion = "0.1.0";

// Scene files: the field of view of the framing camera (the demo's), and the clear colour, a
// neutral mid grey (linear 0.18, sRGB ≈ 118) that shows both dark and light geometry.
constexpr double kDefaultFovDegrees = 51.6;
constexpr float kSceneFileClear = 0.18f;
static_assert(kDefaultFovDegrees > 0.0 && kDefaultFovDegrees < 180.0, "a field of view in (0, 180)");
static_assert(kSceneFileClear >= 0.0f && kSceneFileClear <= 1.0f, "a displayable grey");

constexpr const char* kUsage =
    "usage: mipraster <command> [options]\n"
    "\n"
    "commands:\n"
    "  render     render a scene file (.obj, .gltf, .glb) or, without one, the built-in demo\n"
    "             (a textured cube on a textured checker plane to the horizon):\n"
    "             mipraster render [SCENE] -o OUT [options]\n"
    "  compare    compare two images value by value and print a report (idiff style)\n"
    "  bench      frame times against Mesa's llvmpipe on the shared benchmark scenes (--roofline:\n"
    "             each frame against the machine's limits; --growth, --omissions: cost studies);\n"
    "             runs in Python like study (`python3 -m mipraster.bench`); mipraster bench --help\n"
    "  stress     run the numerical stress suite and print one row per case:\n"
    "             what was tried, the figure measured, its bound, PASS/FAIL\n"
    "  resize     resize an image with a reconstruction filter (in linear colour, widened when shrinking)\n"
    "  synthesize grow a texture like a sample image (Efros & Leung non-parametric sampling)\n"
    "  study      error against run time of the quality knobs (samples, pattern, SSAA/MSAA,\n"
    "             texture filter, anisotropy, LOD bias): CSV, Markdown table and plot. It runs in\n"
    "             Python: the binary hands its arguments to `python3 -m mipraster.study` (the\n"
    "             python3 beside this binary, else $MIPRASTER_PYTHON, else the one on PATH);\n"
    "             mipraster study --help lists its options\n"
    "\n"
    "render options:\n"
    "  -o, --output PATH     output image: .png (sRGB) or .exr (linear float)  [required]\n"
    "  --bits N              bits per channel of a .png output, 8 or 16        [8]\n"
    "  --size WxH            image size in pixels                              [1280x720]\n"
    "  --spp N               samples per pixel, 1..64                          [4]\n"
    "  --aa ssaa|msaa        shade every sample, or once per pixel per triangle [msaa]\n"
    "  --pattern NAME        auto, center, grid, rotated, stratified           [auto]\n"
    "  --seed N              seed of the stratified pattern                    [0]\n"
    "  --camera N            use the scene file's N-th camera (0-based)\n"
    "  --look-at E,T         camera eye and target: EX,EY,EZ,TX,TY,TZ (+y up)   [the demo's]\n"
    "  --fov DEG             vertical field of view in degrees                  [51.6]\n"
    "                        a scene file's camera: --camera N, else --look-at/--fov, else its\n"
    "                        first camera, else one that frames the scene's bounding box\n"
    "  --threads N           worker threads, 0 = all cores                     [0]\n"
    "  --memory-limit SIZE   refuse renders and textures estimated above SIZE bytes\n"
    "                        (suffix K, M, G or T for KiB, MiB, GiB, TiB)       [16G]\n"
    "texture options (override every textured draw's sampler; default: the scene's own):\n"
    "  --filter F            nearest, bilinear (no mip levels), trilinear, anisotropic, ewa, sat\n"
    "  --max-aniso N         most probes (anisotropic) or largest axis ratio (ewa), >= 1\n"
    "  --wrap W[,W]          repeat, clamp, mirror, border; one for both axes or u,v\n"
    "  --lod-bias B          added to the level of detail (log2 texels per pixel)\n"
    "  --debug-view V        none, mip-level (a colour per mip level), uv (uv as colour)\n"
    "  --derivatives D       analytic (exact per sample) or quad (2x2 finite differences) [analytic]\n"
    "  --resolve F           resolve filter: box (mean of the pixel's samples), tent, mitchell,\n"
    "                        catmull-rom, lanczos3 (also weigh the samples of nearby pixels) [box]\n"
    "  --stats               print triangle, sample and per-stage time counts, and the estimated\n"
    "                        RMSE: a probe renders some pixels again at reference quality (the\n"
    "                        same estimate as Python's render(..., estimate_error=True))\n"
    "  --stats-json PATH     write the counts and times as JSON (- = stdout)\n"
    "  --error-map PATH      write the per-pixel error estimate (RMS over linear R, G, B): two\n"
    "                        interleaved halves of the samples, scaled to the probe's RMSE\n"
    "                        (.exr linear, .png sRGB grey); spp >= 2\n"
    "  --probe-pixels N      pixels the probe renders again; 0 = no probe (the raw halves\n"
    "                        estimate, spp >= 2)   [W*H*spp/(256*K) within 512..4096, K passes]\n"
    "  --quiet               print nothing but errors (no summary, no progress bar)\n"
    "\n"
    "compare A B [options]: values are compared as read (linear float; 8-bit files are decoded\n"
    "from sRGB and alpha-premultiplied); exit status 0 when they match, 1 when they differ beyond\n"
    "the thresholds, 2 when they cannot be compared (bad options, unreadable files, other sizes)\n"
    "  --fail T              a value fails when |a - b| > T                    [0.003921]\n"
    "  --fail-fraction F     the comparison fails when more than F of the values fail  [0]\n"
    "  --hard-fail H         ... or when any value differs by more than H      [1]\n"
    "\n"
    "stress [options]: exit status 0 when every row passes, 1 otherwise\n"
    "  --full                the issue's sizes (>= 10^7 samples, a 16384^2 texture; minutes, ~6 GiB)\n"
    "                        instead of the fast CI sizes\n"
    "  --json FILE           also write the rows as JSON (- = stdout)\n"
    "  --details             print the per-setting measurements under each row\n"
    "\n"
    "resize IN -o OUT --size WxH [options]: read any image, write .png (sRGB) or .exr\n"
    "  --filter F            box, tent, mitchell, catmull-rom, lanczos3          [mitchell]\n"
    "  --threads N           worker threads, 0 = all cores                     [0]\n"
    "  --bits N              bits per channel of a .png output, 8 or 16        [8]\n"
    "\n"
    "synthesize SAMPLE -o OUT --size WxH [options]: every output pixel is copied from the sample\n"
    "  --window N            odd neighbourhood side, at most the sample's sides [11]\n"
    "  --seed S              random seed; the same seed gives the same output   [0]\n"
    "  --epsilon E           draw among matches within (1 + E) of the best      [0.1]\n"
    "  --periodic            the sample tiles: its neighbourhoods wrap around its edges\n"
    "  --tileable            make the output tile (its neighbourhoods wrap around)\n"
    "  --threads N           worker threads, 0 = all cores                     [0]\n"
    "  --bits N              bits per channel of a .png output, 8 or 16        [8]\n"
    "\n"
    "  mipraster --help | --version\n";

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Every integer option's bounds unless it names tighter ones: ±2^30 (int, with room to spare).
constexpr long long kIntOptionLimit = 1LL << 30;

// A whole decimal integer in [lo, hi]: "not an integer" and "out of range" are told apart
// (99999999999 is an integer, only too large; std::stoll's out_of_range counts as out of range).
int parse_int(const std::string& option, const std::string& text, long long lo = -kIntOptionLimit,
              long long hi = kIntOptionLimit) {
    std::size_t used = 0;
    long long value = 0;
    bool out_of_range = false;
    try {
        value = std::stoll(text, &used);
    } catch (const std::out_of_range&) {  // digits (after an optional sign) beyond long long
        const std::size_t sign = text[0] == '-' || text[0] == '+';
        out_of_range = text.size() > sign && std::all_of(text.begin() + sign, text.end(), [](char c) {
            return std::isdigit(static_cast<unsigned char>(c));
        });
        used = out_of_range ? text.size() : 0;
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != text.size() || text.empty()) throw UsageError(option + ": expected an integer, got '" + text + "'");
    if (out_of_range || value < lo || value > hi)
        throw UsageError(option + ": " + text + " is out of range; expected an integer from " + std::to_string(lo) +
                         " to " + std::to_string(hi));
    return static_cast<int>(value);
}

// --bits N for the image written to `output`: 8 or 16, and 16 only for a PNG (checked before any
// work, which write_image would refuse only at the end).
ImageWriteOptions parse_bits(const std::string& text, const std::string& output) {
    ImageWriteOptions options;
    options.png_bits = parse_int("--bits", text);
    if (options.png_bits != 8 && options.png_bits != 16)
        throw UsageError("--bits: expected 8 or 16 (bits per PNG channel), got '" + text + "'");
    std::string ext = output.size() >= 4 ? output.substr(output.size() - 4) : "";
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (options.png_bits == 16 && ext != ".png")
        throw UsageError("--bits 16: only a .png output has 16-bit channels, not '" + output + "'");
    return options;
}

// A seed: any integer from 0 to 2^64 - 1, as the Python API takes.
std::uint64_t parse_seed(const std::string& option, const std::string& text) {
    std::size_t used = 0;
    unsigned long long value = 0;
    try {
        if (!text.empty() && std::isdigit(static_cast<unsigned char>(text[0]))) value = std::stoull(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size())
        throw UsageError(option + ": expected an integer from 0 to 18446744073709551615, got '" + text + "'");
    return value;
}

double parse_number(const std::string& option, const std::string& text) {
    std::size_t used = 0;
    double value = 0;
    try {
        value = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != text.size() || text.empty() || !std::isfinite(value))
        throw UsageError(option + ": expected a finite number, got '" + text + "'");
    return value;
}

// A comparison threshold (compare's --fail, --hard-fail): a finite number >= 0. Checked here to
// name the option; CompareSettings::validate would name its field.
double parse_threshold(const std::string& option, const std::string& text) {
    const double value = parse_number(option, text);
    if (!(value >= 0.0)) throw UsageError(option + ": expected a threshold >= 0, got '" + text + "'");
    return value;
}

// "512M", "16G", "1000000": bytes with an optional binary suffix K, M, G or T.
std::uint64_t parse_bytes(const std::string& option, const std::string& text) {
    std::string digits = text;
    int shift = 0;
    if (!digits.empty()) {
        const std::string suffixes = "KMGT";
        const std::size_t unit = suffixes.find(static_cast<char>(std::toupper(static_cast<unsigned char>(digits.back()))));
        if (unit != std::string::npos) {
            shift = 10 * static_cast<int>(unit + 1);
            digits.pop_back();
        }
    }
    const double value = digits.empty() ? -1.0 : parse_number(option, digits);
    const double bytes = std::ldexp(value, shift);
    if (!(bytes >= 1.0 && bytes < 0x1p63))
        throw UsageError(option + ": expected a size in bytes >= 1 (e.g. 512M, 16G), got '" + text + "'");
    return static_cast<std::uint64_t>(bytes);
}

// "a,b,c,..." with exactly `count` finite numbers.
std::vector<double> parse_numbers(const std::string& option, const std::string& text, std::size_t count) {
    std::vector<double> values;
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = text.find(',', start);
        values.push_back(parse_number(option, text.substr(start, comma - start)));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (values.size() != count)
        throw UsageError(option + ": expected " + std::to_string(count) + " comma-separated numbers, got '" + text + "'");
    return values;
}

struct RenderOptions {
    std::string scene;  ///< scene file; empty: the built-in demo
    int camera = -1;    ///< --camera N; −1: not given
    std::string output;
    std::string bits = "8";  ///< --bits as given, checked against the output once both are known
    ImageWriteOptions write;  ///< from --bits
    RenderSettings settings;
    bool print_stats = false;
    std::string stats_json;  ///< path, "-" for stdout, empty for none
    std::string error_map;   ///< --error-map PATH: the per-pixel error estimate; empty for none
    int probe_pixels = -1;   ///< --probe-pixels N; −1: default_probe_pixels, 0: no probe
    bool quiet = false;
    std::vector<double> look_at;  ///< empty: the demo's camera
    double fov_degrees = 0.0;     ///< 0: the demo's
    // Sampler overrides for every textured draw; unset ones keep the scene's values.
    std::string filter;
    double max_aniso = 0.0, lod_bias = 0.0;
    bool has_lod_bias = false;
    std::vector<WrapMode> wrap;
};

// Applies the command line's sampler overrides to the textured draws.
void override_samplers(const RenderOptions& o, std::vector<Draw>& draws) {
    for (Draw& d : draws) {
        if (!d.texture) continue;
        if (!o.filter.empty()) {
            const Sampler named = Sampler::from_filter_name(o.filter);
            d.sampler.mag_filter = named.mag_filter;
            d.sampler.min_filter = named.min_filter;
            d.sampler.mip_filter = named.mip_filter;
            d.sampler.footprint = named.footprint;
        }
        if (o.max_aniso > 0.0) d.sampler.max_anisotropy = static_cast<float>(o.max_aniso);
        if (o.has_lod_bias) d.sampler.lod_bias = static_cast<float>(o.lod_bias);
        if (!o.wrap.empty()) {
            d.sampler.wrap_u = o.wrap.front();
            d.sampler.wrap_v = o.wrap.back();
        }
    }
}

// A progress bar on stderr, redrawn as tiles finish.
void draw_progress(std::size_t done, std::size_t total) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * done / total);
    std::fprintf(stderr, "\rrendering [%.*s%*s] %3d%%", filled, "##############################", kWidth - filled, "",
                 static_cast<int>(100 * done / total));
    if (done == total) std::fputs("\r\033[K", stderr);  // erase the bar when done
    std::fflush(stderr);
}

// "WxH" as two integers, unchecked beyond their format.
std::pair<int, int> split_size(const std::string& text) {
    const auto x = text.find('x');
    if (x == std::string::npos) throw UsageError("--size: expected WxH (e.g. 1280x720), got '" + text + "'");
    return {parse_int("--size width", text.substr(0, x)), parse_int("--size height", text.substr(x + 1))};
}

RenderOptions parse_render_options(const std::vector<std::string>& args) {
    RenderOptions o;
    o.settings.width = 1280;
    o.settings.height = 720;
    o.settings.samples = 4;
    o.settings.anti_aliasing = AntiAliasing::msaa;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> const std::string& {
            if (i + 1 >= args.size()) throw UsageError(a + ": missing value");
            return args[++i];
        };
        if (a == "-o" || a == "--output") {
            o.output = value();
        } else if (a == "--size") {
            // Only the format here: the renderer checks the range and names the dimension.
            std::tie(o.settings.width, o.settings.height) = split_size(value());
        } else if (a == "--spp") {
            o.settings.samples = parse_int(a, value());
        } else if (a == "--aa") {
            o.settings.anti_aliasing = parse_anti_aliasing(value());
        } else if (a == "--pattern") {
            o.settings.pattern = parse_pattern_kind(value());
        } else if (a == "--seed") {
            o.settings.pattern_seed = parse_seed(a, value());
        } else if (a == "--threads") {
            o.settings.threads = parse_int(a, value());
        } else if (a == "--memory-limit") {
            set_memory_limit(parse_bytes(a, value()));
        } else if (a == "--camera") {
            o.camera = parse_int(a, value(), 0);  // a camera index
        } else if (a == "--look-at") {
            o.look_at = parse_numbers(a, value(), 6);
        } else if (a == "--fov") {
            o.fov_degrees = parse_number(a, value());
            if (!(o.fov_degrees > 0.0 && o.fov_degrees < 180.0))
                throw UsageError("--fov: expected degrees in (0, 180), got " + args[i]);
        } else if (a == "--filter") {
            o.filter = value();
            Sampler::from_filter_name(o.filter);  // checks the name
        } else if (a == "--max-aniso") {
            o.max_aniso = parse_number(a, value());
            if (!(o.max_aniso >= 1.0 && o.max_aniso <= 1024.0))
                throw UsageError("--max-aniso: expected a number in [1, 1024], got " + args[i]);
        } else if (a == "--wrap") {
            o.wrap.clear();
            const std::string& v = value();
            const auto comma = v.find(',');
            o.wrap.push_back(parse_wrap_mode(v.substr(0, comma)));
            if (comma != std::string::npos) o.wrap.push_back(parse_wrap_mode(v.substr(comma + 1)));
        } else if (a == "--lod-bias") {
            o.lod_bias = parse_number(a, value());
            if (std::fabs(o.lod_bias) > std::numeric_limits<float>::max())  // (the sampler's bias is a float)
                throw UsageError("--lod-bias: " + args[i] + " is beyond float's range");
            o.has_lod_bias = true;
        } else if (a == "--debug-view") {
            o.settings.debug_view = parse_debug_view(value());
        } else if (a == "--derivatives") {
            o.settings.derivatives = parse_derivative_mode(value());
        } else if (a == "--resolve") {
            o.settings.resolve_filter = parse_resolve_filter(value());
        } else if (a == "--stats") {
            o.print_stats = true;
        } else if (a == "--stats-json") {
            o.stats_json = value();
        } else if (a == "--error-map") {
            o.error_map = value();
        } else if (a == "--probe-pixels") {
            o.probe_pixels = parse_int(a, value(), 0);  // 0: no probe
        } else if (a == "--quiet") {
            o.quiet = true;
        } else if (a == "--bits") {
            o.bits = value();
        } else if (!a.empty() && a[0] != '-' && o.scene.empty()) {
            o.scene = a;
        } else if (!a.empty() && a[0] != '-') {
            throw UsageError("render: more than one scene file ('" + o.scene + "', '" + a + "')");
        } else {
            throw UsageError("render: unknown option '" + a + "'");
        }
    }
    if (o.camera >= 0 && o.scene.empty())
        throw UsageError("--camera: needs a scene file (the built-in demo has one camera)");
    if (o.output.empty()) throw UsageError("render: missing -o PATH (where to write the image)");
    o.write = parse_bits(o.bits, o.output);
    if (!o.error_map.empty() && o.settings.samples < 2)
        throw UsageError("--error-map: the estimate compares two halves of each pixel's samples; give --spp 2 or more");
    return o;
}

int run_render(const std::vector<std::string>& args) {
    const RenderOptions o = parse_render_options(args);
    // Check the size before the scene is built from its aspect ratio.
    validate_framebuffer_size(o.settings.width, o.settings.height, o.settings.samples, true);
    const double aspect = static_cast<double>(o.settings.width) / o.settings.height;
    RenderSettings settings = o.settings;
    Camera camera;
    std::vector<Draw> draws;
    DemoScene demo;
    LoadedScene loaded;
    if (o.scene.empty()) {
        demo = make_demo_scene(aspect);
        camera = demo.camera;
        if (!o.look_at.empty() || o.fov_degrees > 0.0) {
            const glm::dvec3 eye = o.look_at.empty() ? demo.eye : glm::dvec3(o.look_at[0], o.look_at[1], o.look_at[2]);
            const glm::dvec3 target = o.look_at.empty() ? demo.target : glm::dvec3(o.look_at[3], o.look_at[4], o.look_at[5]);
            const double fovy = o.fov_degrees > 0.0 ? o.fov_degrees * M_PI / 180.0 : demo.fovy;
            camera = Camera::look_at_perspective(eye, target, {0, 1, 0}, fovy, aspect, demo.near);
        }
        settings.clear_color = demo.clear_color;
        draws = demo.draws;
    } else {
        loaded = load_scene(o.scene);  // std::runtime_error naming the file → exit status 1
        if (!o.quiet)
            for (const std::string& w : loaded.warnings) std::fprintf(stderr, "mipraster: warning: %s\n", w.c_str());
        const double fovy = (o.fov_degrees > 0.0 ? o.fov_degrees : kDefaultFovDegrees) * M_PI / 180.0;
        if (o.camera >= 0) {
            if (static_cast<std::size_t>(o.camera) >= loaded.cameras.size())
                throw std::invalid_argument("--camera " + std::to_string(o.camera) + ": " + o.scene + " has " +
                                 std::to_string(loaded.cameras.size()) + " camera(s)" +
                                 (loaded.cameras.empty() ? "" : " (0.." + std::to_string(loaded.cameras.size() - 1) + ")"));
            camera = loaded.cameras[o.camera].build(aspect);
        } else if (!o.look_at.empty()) {
            const double near = 1e-3 * std::max(1.0, glm::length(glm::dvec3(o.look_at[3] - o.look_at[0],
                                                                            o.look_at[4] - o.look_at[1],
                                                                            o.look_at[5] - o.look_at[2])));
            camera = Camera::look_at_perspective({o.look_at[0], o.look_at[1], o.look_at[2]},
                                                 {o.look_at[3], o.look_at[4], o.look_at[5]}, {0, 1, 0}, fovy, aspect, near);
        } else if (o.fov_degrees > 0.0 || loaded.cameras.empty()) {
            camera = framing_camera(loaded.draws, fovy, aspect);
        } else {
            camera = loaded.cameras.front().build(aspect);
        }
        settings.clear_color = glm::vec4(kSceneFileClear, kSceneFileClear, kSceneFileClear, 1.0f);
        draws = loaded.draws;
    }
    override_samplers(o, draws);
    const bool sampler_flags = !o.filter.empty() || o.max_aniso > 0.0 || o.has_lod_bias || !o.wrap.empty() ||
                               o.settings.debug_view != DebugView::none;
    if (sampler_flags && !o.quiet && std::none_of(draws.begin(), draws.end(), [](const Draw& d) { return bool(d.texture); }))
        std::fprintf(stderr, "mipraster: warning: the scene has no textured draw; the texture options change nothing\n");
    if (!o.quiet && isatty(STDOUT_FILENO)) settings.progress = draw_progress;
    // The estimate (--stats, --error-map): the halves map (spp >= 2) says where, the probe how much.
    const bool estimate = o.print_stats || !o.error_map.empty();
    const int probe_pixels = !estimate ? 0
                             : o.probe_pixels >= 0 ? o.probe_pixels
                                                   : default_probe_pixels(settings.width, settings.height, settings.samples);
    settings.estimate_error = estimate && settings.samples >= 2;
    RenderResult result = render(draws, camera, settings);
    ErrorProbe probe;
    if (probe_pixels > 0) {
        probe = measure_error(draws, camera, settings, result.color, settings.estimate_error ? &result.error_map : nullptr,
                              probe_pixels, settings.pattern_seed);
        if (settings.estimate_error) {
            calibrate_error_map(result.error_map, probe);
            result.error_estimate = summarize_error_map(result.error_map);
        }
    }
    write_image(o.output, result.color, o.write);
    if (!o.quiet)
        std::printf("wrote %s (%dx%d, %d spp %s, %.1f ms on %d threads)\n", o.output.c_str(), settings.width,
                    settings.height, settings.samples, to_string(settings.anti_aliasing).c_str(), result.stats.total_ms,
                    result.stats.threads);
    if (!o.error_map.empty()) write_image(o.error_map, result.error_map);
    if (o.print_stats) {
        std::printf("%s\n%s\n", result.pattern.to_string().c_str(), result.stats.to_string().c_str());
        if (probe_pixels > 0) {
            std::printf("error estimate (linear RGB; %d pixels rendered again at %d spp, %.1f ms): rmse%s%.6g "
                        "+- %.2g, reference's own rmse=%.3g",
                        probe.pixels, probe.reference_spp, probe.ms, probe.upper_bound ? "<=" : "=", probe.rmse,
                        probe.standard_error, probe.reference_rmse);
            if (settings.estimate_error) std::printf(", worst pixel=%.6g", result.error_estimate.max_pixel);
            std::printf("%s\n", probe.upper_bound ? " (an upper bound: the error is too small for the probe to resolve)" : "");
        } else if (settings.estimate_error) {
            std::printf("error estimate (linear RGB, from two interleaved halves of the samples only; sampling "
                        "error, not filter blur): rmse=%.6g, worst pixel=%.6g\n",
                        result.error_estimate.rmse, result.error_estimate.max_pixel);
        } else {
            std::printf("error estimate: without a probe (--probe-pixels 0) it needs --spp 2 or more\n");
        }
    }
    if (o.stats_json == "-") {
        std::printf("%s\n", result.stats.to_json().c_str());
    } else if (!o.stats_json.empty()) {
        std::FILE* f = std::fopen(o.stats_json.c_str(), "w");
        if (!f) throw std::runtime_error("cannot write " + o.stats_json + ": " + std::strerror(errno));
        std::fprintf(f, "%s\n", result.stats.to_json().c_str());
        std::fclose(f);
    }
    return 0;
}

// "WxH" with both in 1…limit.
std::pair<int, int> parse_size(const std::string& text, int limit) {
    const auto [w, h] = split_size(text);
    if (w < 1 || h < 1 || w > limit || h > limit)
        throw UsageError("--size: " + text + " is out of range; expected 1 to " + std::to_string(limit) + " each");
    return {w, h};
}

// The options shared by resize and synthesize: one input, -o OUT, --size, --threads, --quiet;
// `extra` handles the command's own options (returns false for an unknown one).
struct ImageCommand {
    std::string input, output, bits = "8";  // (bits: --bits as given)
    ImageWriteOptions write;                 // from --bits
    int width = 0, height = 0, threads = 0;
    bool quiet = false;
};

template <class Extra>
ImageCommand parse_image_command(const char* command, const std::vector<std::string>& args, int size_limit,
                                 Extra extra) {
    ImageCommand o;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> const std::string& {
            if (i + 1 >= args.size()) throw UsageError(a + ": missing value");
            return args[++i];
        };
        if (a == "-o" || a == "--output") {
            o.output = value();
        } else if (a == "--size") {
            std::tie(o.width, o.height) = parse_size(value(), size_limit);
        } else if (a == "--threads") {
            o.threads = parse_int(a, value());
            resolve_thread_count(o.threads);  // throws naming threads
        } else if (a == "--quiet") {
            o.quiet = true;
        } else if (a == "--bits") {
            o.bits = value();
        } else if (extra(a, value)) {
        } else if (!a.empty() && a[0] != '-' && o.input.empty()) {
            o.input = a;
        } else if (!a.empty() && a[0] != '-') {
            throw UsageError(std::string(command) + ": more than one input image ('" + o.input + "', '" + a + "')");
        } else {
            throw UsageError(std::string(command) + ": unknown option '" + a + "'");
        }
    }
    if (o.input.empty()) throw UsageError(std::string(command) + ": missing the input image");
    if (o.output.empty()) throw UsageError(std::string(command) + ": missing -o PATH (where to write the image)");
    o.write = parse_bits(o.bits, o.output);
    if (o.width == 0) throw UsageError(std::string(command) + ": missing --size WxH");
    return o;
}

int run_resize(const std::vector<std::string>& args) {
    ReconstructionFilter filter = ReconstructionFilter::mitchell;
    const ImageCommand o = parse_image_command("resize", args, kMaxResampleDimension, [&](const std::string& a, auto value) {
        if (a != "--filter") return false;
        filter = parse_reconstruction_filter(value());
        return true;
    });
    const Image image = read_image(o.input);  // linear, premultiplied RGBA; std::runtime_error naming the file
    const auto start = std::chrono::steady_clock::now();
    const Image out = resample(image, o.width, o.height, filter, o.threads);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    write_image(o.output, out, o.write);
    if (!o.quiet)
        std::printf("wrote %s (%dx%d from %dx%d, %s, %.1f ms)\n", o.output.c_str(), o.width, o.height, image.width,
                    image.height, to_string(filter).c_str(), ms);
    return 0;
}

int run_synthesize(const std::vector<std::string>& args) {
    SynthesisSettings settings;
    const ImageCommand o = parse_image_command("synthesize", args, kMaxSynthesisDimension, [&](const std::string& a, auto value) {
        if (a == "--window") settings.window = parse_int(a, value());
        else if (a == "--seed") settings.seed = parse_seed(a, value());
        else if (a == "--epsilon") settings.epsilon = parse_number(a, value());
        else if (a == "--periodic") settings.periodic_sample = true;
        else if (a == "--tileable") settings.tileable = true;
        else return false;
        return true;
    });
    if (settings.window < 1 || settings.window % 2 == 0)
        throw UsageError("--window: expected an odd size >= 1, got " + std::to_string(settings.window));
    if (!(settings.epsilon >= 0.0)) throw UsageError("--epsilon: expected a number >= 0");
    settings.width = o.width;
    settings.height = o.height;
    settings.threads = o.threads;
    const Image sample = read_image(o.input);  // linear, premultiplied RGBA
    if (settings.window > std::min(sample.width, sample.height))
        throw std::invalid_argument("--window " + std::to_string(settings.window) + ": larger than the sample " +
                                    o.input + " (" + std::to_string(sample.width) + "x" + std::to_string(sample.height) + ")");
    const SynthesisResult r = synthesize_texture(sample, settings);
    write_image(o.output, r.image, o.write);
    if (!o.quiet)
        std::printf("wrote %s (%dx%d from %s, window %d, seed %llu, %.1f ms)\n", o.output.c_str(), o.width, o.height,
                    o.input.c_str(), settings.window, static_cast<unsigned long long>(settings.seed), r.milliseconds);
    return 0;
}

int run_compare(const std::vector<std::string>& args) {
    std::vector<std::string> paths;
    CompareSettings settings;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> const std::string& {
            if (i + 1 >= args.size()) throw UsageError(a + ": missing value");
            return args[++i];
        };
        if (a == "--fail") settings.fail_threshold = parse_threshold(a, value());
        else if (a == "--fail-fraction") {
            settings.fail_fraction = parse_number(a, value());
            if (!(settings.fail_fraction >= 0.0 && settings.fail_fraction <= 1.0))
                throw UsageError("--fail-fraction: expected a fraction in [0, 1], got '" + args[i] + "'");
        } else if (a == "--hard-fail") settings.hard_fail_threshold = parse_threshold(a, value());
        else if (!a.empty() && a[0] == '-') throw UsageError("compare: unknown option '" + a + "'");
        else paths.push_back(a);
    }
    if (paths.size() != 2)
        throw UsageError("compare: expected two image paths (actual, expected), got " + std::to_string(paths.size()));
    settings.validate();
    CompareReport report;
    try {
        report = compare_images(read_image(paths[0]), read_image(paths[1]), settings);
    } catch (const std::exception& e) {  // unreadable files, different sizes: no verdict
        std::fprintf(stderr, "mipraster: compare: %s\n", e.what());
        return 2;
    }
    std::printf("%s vs %s\n%s\n", paths[0].c_str(), paths[1].c_str(), report.to_string().c_str());
    return report.passed ? 0 : 1;
}

// Where `mipraster study` finds Python: the python3 beside this binary (a virtual environment's
// bin/), else $MIPRASTER_PYTHON, else python3 on PATH.
std::string python_executable() {
    char self[4096];
    const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n > 0) {
        std::string dir(self, static_cast<std::size_t>(n));
        dir = dir.substr(0, dir.find_last_of('/'));
        const std::string beside = dir + "/python3";
        if (access(beside.c_str(), X_OK) == 0) return beside;
    }
    if (const char* env = std::getenv("MIPRASTER_PYTHON"); env && *env) return env;
    return "python3";
}

// Hands a subcommand whose home is the Python package to `python3 -m MODULE ARGS...`.
int run_python_module(const std::string& module, const std::vector<std::string>& args) {
    const std::string python = python_executable();
    std::vector<std::string> words = {python, "-m", module};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    execvp(python.c_str(), argv.data());
    std::fprintf(stderr, "mipraster: error: this command runs in Python (%s -m %s) and %s could not be started: %s\n",
                 python.c_str(), module.c_str(), python.c_str(), std::strerror(errno));
    return 1;
}

int run_stress(const std::vector<std::string>& args) {
    StressSize size = StressSize::fast;
    std::string json;
    bool details = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--full") size = StressSize::full;
        else if (a == "--details") details = true;
        else if (a == "--json") {
            if (i + 1 >= args.size()) throw UsageError("--json: missing value");
            json = args[++i];
        } else throw UsageError("stress: unknown option '" + a + "'");
    }
    std::FILE* out = json == "-" ? stderr : stdout;  // keep stdout pure JSON with --json -
    std::FILE* json_file = nullptr;  // opened first: an unwritable path fails before minutes of work
    if (!json.empty() && json != "-") {
        json_file = std::fopen(json.c_str(), "w");
        if (!json_file) throw std::runtime_error("cannot write " + json + ": " + std::strerror(errno));
    }
    std::fprintf(out, "mipraster stress suite (%s sizes)\n", to_string(size).c_str());
    const std::vector<StressRow> rows = run_stress_suite(size, [&](const StressRow& r) {
        std::fputs(format_stress_report({r}, details).c_str(), out);
        std::fflush(out);
    });
    int failed = 0;
    for (const StressRow& r : rows) failed += !r.pass;
    std::fprintf(out, "%zu of %zu rows pass\n", rows.size() - failed, rows.size());
    if (json == "-") {
        std::fputs(stress_rows_to_json(rows).c_str(), stdout);
    } else if (json_file) {
        std::fputs(stress_rows_to_json(rows).c_str(), json_file);
        std::fclose(json_file);
    }
    return failed ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> args(argv + 1, argv + argc);
    try {
        if (args.empty()) throw UsageError("missing command");
        if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
            std::fputs(kUsage, stdout);
            return 0;
        }
        if (args[0] == "--version") {
            std::printf("mipraster %s\n", kVersion);
            return 0;
        }
        if (args[0] == "render") return run_render({args.begin() + 1, args.end()});
        if (args[0] == "compare") return run_compare({args.begin() + 1, args.end()});
        if (args[0] == "bench") return run_python_module("mipraster.bench", {args.begin() + 1, args.end()});
        if (args[0] == "stress") return run_stress({args.begin() + 1, args.end()});
        if (args[0] == "resize") return run_resize({args.begin() + 1, args.end()});
        if (args[0] == "synthesize") return run_synthesize({args.begin() + 1, args.end()});
        if (args[0] == "study") return run_python_module("mipraster.study", {args.begin() + 1, args.end()});
        throw UsageError("unknown command '" + args[0] + "'");
    } catch (const UsageError& e) {
        std::fprintf(stderr, "mipraster: %s\n\n%s", e.what(), kUsage);
        return 2;
    } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "mipraster: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mipraster: error: %s\n", e.what());
        return 1;
    }
}
