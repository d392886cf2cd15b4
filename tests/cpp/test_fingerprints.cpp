// The bits of a few renders of the demo scene, recorded in tests/golden/fingerprints.txt: every
// build reproduces them, whatever instruction set it was compiled for (DESIGN.md §2.8). The
// CTest build of .ci/dev compiles for the x86-64 baseline and the Python package for the machine
// (x86-64-v3 where it has AVX2); tests/python/test_fingerprints.py checks the same file there, so
// the two builds agree bit for bit. After a change that is meant to move bits, the file is
// rewritten by `python3 -m pytest tests/python/test_fingerprints.py --update-goldens`.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "mipraster/pipeline/renderer.hpp"
#include "mipraster/scene/demo_scene.hpp"

namespace {

namespace mr = mipraster;

/// Σ word_i · (2i + 1) mod 2⁶⁴ over the image's 32-bit words: an odd factor per position, so a
/// change of any one word changes the sum (tests/python/test_fingerprints.py computes the same).
std::uint64_t fingerprint(const mr::Image& image) {
    std::uint64_t sum = 0;
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        std::uint32_t word;
        std::memcpy(&word, &image.pixels[i], sizeof word);
        sum += std::uint64_t{word} * (2 * std::uint64_t{i} + 1);
    }
    return sum;
}

std::map<std::string, std::string> recorded() {
    std::ifstream in(std::string(MIPRASTER_SOURCE_DIR) + "/tests/golden/fingerprints.txt");
    std::map<std::string, std::string> out;
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream fields(line);
        std::string name, hex;
        fields >> name >> hex;
        out[name] = hex;
    }
    return out;
}

TEST(Fingerprints, DemoRendersReproduceTheRecordedBits) {
    const std::map<std::string, std::string> expected = recorded();
    ASSERT_FALSE(expected.empty()) << "tests/golden/fingerprints.txt is missing or empty";
    const int W = 128, H = 96;
    const mr::DemoScene demo = mr::make_demo_scene(double(W) / H);
    struct Mode {
        const char* name;
        int samples;
        mr::AntiAliasing aa;
    };
    for (const Mode mode : {Mode{"1x", 1, mr::AntiAliasing::ssaa}, Mode{"msaa4", 4, mr::AntiAliasing::msaa},
                            Mode{"ssaa4", 4, mr::AntiAliasing::ssaa}}) {
        mr::RenderSettings settings;
        settings.width = W;
        settings.height = H;
        settings.samples = mode.samples;
        settings.anti_aliasing = mode.aa;
        settings.threads = 2;
        settings.clear_color = demo.clear_color;
        const mr::RenderResult result = mr::render(demo.draws, demo.camera, settings);
        char hex[17];
        std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fingerprint(result.color)));
        const std::string name = std::string("demo_") + mode.name;
        ASSERT_TRUE(expected.count(name)) << name << " is not in tests/golden/fingerprints.txt";
        EXPECT_EQ(hex, expected.at(name)) << name;
    }
}

}  // namespace
