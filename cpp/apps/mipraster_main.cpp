// mipraster — the command-line renderer.
//
//   mipraster render -o OUT.png [--size WxH] [--spp N] [--aa ssaa|msaa] [--pattern NAME]
//                    [--threads N] [--stats]
//
// With no scene file (scene files arrive with the Python/scene issue) it renders the built-in
// demo. Usage errors exit with status 2, failures with 1; every message names the bad input.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "mipraster/io/image_io.hpp"
#include "mipraster/pipeline/renderer.hpp"
#include "mipraster/scene/demo_scene.hpp"

namespace {

using namespace mipraster;

constexpr const char* kVersion = "0.1.0";

constexpr const char* kUsage =
    "usage: mipraster <command> [options]\n"
    "\n"
    "commands:\n"
    "  render     render the built-in demo scene (a lit cube on a checkered plane)\n"
    "\n"
    "render options:\n"
    "  -o, --output PATH     output image: .png (sRGB 8-bit) or .exr (linear float)  [required]\n"
    "  --size WxH            image size in pixels                              [1280x720]\n"
    "  --spp N               samples per pixel, 1..64                          [4]\n"
    "  --aa ssaa|msaa        shade every sample, or once per pixel per triangle [msaa]\n"
    "  --pattern NAME        auto, center, grid, rotated, stratified           [auto]\n"
    "  --seed N              seed of the stratified pattern                    [0]\n"
    "  --threads N           worker threads, 0 = all cores                     [0]\n"
    "  --stats               print triangle, sample and per-stage time counts\n"
    "\n"
    "  mipraster --help | --version\n";

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

int parse_int(const std::string& option, const std::string& text) {
    std::size_t used = 0;
    long value = 0;
    try {
        value = std::stol(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != text.size() || text.empty() || value < -(1L << 30) || value > (1L << 30))
        throw UsageError(option + ": expected an integer, got '" + text + "'");
    return static_cast<int>(value);
}

struct RenderOptions {
    std::string output;
    RenderSettings settings;
    bool print_stats = false;
};

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
            const std::string& v = value();
            const auto x = v.find('x');
            if (x == std::string::npos) throw UsageError("--size: expected WxH (e.g. 1280x720), got '" + v + "'");
            o.settings.width = parse_int("--size width", v.substr(0, x));
            o.settings.height = parse_int("--size height", v.substr(x + 1));
        } else if (a == "--spp") {
            o.settings.samples = parse_int(a, value());
        } else if (a == "--aa") {
            o.settings.anti_aliasing = parse_anti_aliasing(value());
        } else if (a == "--pattern") {
            o.settings.pattern = parse_pattern_kind(value());
        } else if (a == "--seed") {
            o.settings.pattern_seed = static_cast<std::uint64_t>(parse_int(a, value()));
        } else if (a == "--threads") {
            o.settings.threads = parse_int(a, value());
        } else if (a == "--stats") {
            o.print_stats = true;
        } else {
            throw UsageError("render: unknown option '" + a + "'");
        }
    }
    if (o.output.empty()) throw UsageError("render: missing -o PATH (where to write the image)");
    return o;
}

int run_render(const std::vector<std::string>& args) {
    const RenderOptions o = parse_render_options(args);
    // Check the size before the scene is built from its aspect ratio.
    validate_framebuffer_size(o.settings.width, o.settings.height, o.settings.samples, true);
    const DemoScene scene = make_demo_scene(static_cast<double>(o.settings.width) / o.settings.height);
    RenderSettings settings = o.settings;
    settings.clear_color = scene.clear_color;
    const RenderResult result = render(scene.draws, scene.camera, settings);
    write_image(o.output, result.color);
    std::printf("wrote %s (%dx%d, %d spp %s, %.1f ms on %d threads)\n", o.output.c_str(), settings.width,
                settings.height, settings.samples, to_string(settings.anti_aliasing).c_str(), result.stats.total_ms,
                result.stats.threads);
    if (o.print_stats) std::printf("%s\n%s\n", result.pattern.to_string().c_str(), result.stats.to_string().c_str());
    return 0;
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
