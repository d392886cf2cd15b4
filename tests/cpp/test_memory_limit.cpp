// The process-wide memory limit: estimates are checked before anything large is allocated, and
// the refusal gives the estimate and the limit.
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "helpers.hpp"
#include "mipraster/core/memory_limit.hpp"
#include "mipraster/texture/texture.hpp"

namespace {

namespace mr = mipraster;
using namespace helpers;

// Restores the default limit however a test ends.
struct LimitGuard {
    explicit LimitGuard(std::uint64_t bytes) { mr::set_memory_limit(bytes); }
    ~LimitGuard() { mr::set_memory_limit(0); }
};

mr::Mesh one_triangle() {
    mr::Mesh m;
    m.positions = {glm::vec3(-0.5f, -0.5f, 0.0f), glm::vec3(0.5f, -0.5f, 0.0f), glm::vec3(0.0f, 0.5f, 0.0f)};
    m.triangles = {glm::uvec3(0, 1, 2)};
    return m;
}

mr::RenderSettings sized(int w, int h, int samples, int threads = 1) {
    mr::RenderSettings s;
    s.width = w;
    s.height = h;
    s.samples = samples;
    s.threads = threads;
    return s;
}

std::string refusal(const std::vector<mr::Draw>& draws, const mr::RenderSettings& s) {
    try {
        mr::render(draws, identity_camera(), s);
    } catch (const mr::MemoryLimitError& e) {
        return e.what();
    }
    ADD_FAILURE() << "not refused";
    return "";
}

// The bytes the message reports, from its "(N bytes)".
std::uint64_t reported_bytes(const std::string& message) {
    const std::size_t close = message.find(" bytes)");
    const std::size_t open = message.rfind('(', close);
    return std::stoull(message.substr(open + 1, close - open - 1));
}

TEST(MemoryLimit, FormatsBinaryUnits) {
    EXPECT_EQ(mr::format_bytes(0), "0 bytes");
    EXPECT_EQ(mr::format_bytes(1), "1 byte");
    EXPECT_EQ(mr::format_bytes(1023), "1023 bytes");
    EXPECT_EQ(mr::format_bytes(1024), "1.00 KiB");
    EXPECT_EQ(mr::format_bytes(1536), "1.50 KiB");
    EXPECT_EQ(mr::format_bytes(std::uint64_t{100} << 20), "100 MiB");
    EXPECT_EQ(mr::format_bytes(std::uint64_t{16} << 30), "16.0 GiB");
    EXPECT_EQ(mr::format_bytes(std::uint64_t{3} << 40), "3.00 TiB");
}

TEST(MemoryLimit, SetAndRestoreDefault) {
    EXPECT_EQ(mr::memory_limit(), mr::kDefaultMemoryLimit);
    {
        LimitGuard guard(12345);
        EXPECT_EQ(mr::memory_limit(), 12345u);
    }
    EXPECT_EQ(mr::memory_limit(), mr::kDefaultMemoryLimit);
}

TEST(MemoryLimit, RenderIsRefusedWithItsEstimateAndTheLimit) {
    const mr::Mesh m = one_triangle();
    const std::vector<mr::Draw> draws = {make_draw(m, glm::dmat4(1.0), mr::DrawState{})};
    LimitGuard guard(1 << 20);
    const std::string msg = refusal(draws, sized(1000, 1000, 4));
    EXPECT_NE(msg.find("a render of 1000x1000 pixels at 4 samples per pixel"), std::string::npos) << msg;
    EXPECT_NE(msg.find("the memory limit is 1.00 MiB"), std::string::npos) << msg;
    // The estimate holds at least the resolved colour (16 bytes a pixel) and one thread's tile
    // buffers (32² pixels × 4 samples × 20 bytes of colour and depth).
    EXPECT_GE(reported_bytes(msg), 1000u * 1000u * 16u + 32u * 32u * 4u * 20u);
    // Just under the limit it renders.
    mr::set_memory_limit(reported_bytes(msg));
    EXPECT_NO_THROW(mr::render(draws, identity_camera(), sized(1000, 1000, 4)));
}

TEST(MemoryLimit, EstimateGrowsWithWhatTheRenderKeeps) {
    const mr::Mesh m = one_triangle();
    const std::vector<mr::Draw> draws = {make_draw(m, glm::dmat4(1.0), mr::DrawState{})};
    LimitGuard guard(1);
    const mr::RenderSettings plain = sized(200, 100, 16);
    mr::RenderSettings kept = plain;
    kept.keep_samples = true;
    mr::RenderSettings wide = plain;
    wide.resolve_filter = mr::ResolveFilter::mitchell;
    mr::RenderSettings estimated = plain;
    estimated.estimate_error = true;
    mr::RenderSettings more_threads = plain;
    more_threads.threads = 4;
    const std::uint64_t base = reported_bytes(refusal(draws, plain));
    // Keeping the samples adds the whole sample framebuffer: 200·100·16 samples × 20 bytes.
    EXPECT_EQ(reported_bytes(refusal(draws, kept)) - base, 200u * 100u * 16u * 20u);
    // So does a resolve filter wider than a pixel, with its row sums (four doubles a sample); the
    // error estimate adds its map (4 bytes a pixel).
    EXPECT_EQ(reported_bytes(refusal(draws, wide)) - base, 200u * 100u * 16u * (20u + 32u));
    EXPECT_EQ(reported_bytes(refusal(draws, estimated)) - base, 200u * 100u * 4u);
    // Each further worker adds its tile buffers: 32² pixels × 16 samples × 24 bytes (colour,
    // depth and deferred shading's owner), or 20 without deferred shading.
    EXPECT_EQ(reported_bytes(refusal(draws, more_threads)) - base, 3u * 32u * 32u * 16u * 24u);
    mr::RenderSettings forward = plain, forward_threads = more_threads;
    forward.deferred_shading = forward_threads.deferred_shading = false;
    EXPECT_EQ(reported_bytes(refusal(draws, forward_threads)) - reported_bytes(refusal(draws, forward)),
              3u * 32u * 32u * 16u * 20u);
}

TEST(MemoryLimit, RasterizeIsRefusedBeforeAllocating) {
    LimitGuard guard(1 << 20);
    mr::RasterizeSettings s;
    s.width = 1000;
    s.height = 1000;
    s.samples = 4;
    const std::vector<glm::dvec4> clip = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {0, 1, 0, 1}};
    try {
        mr::rasterize(clip, {glm::uvec3(0, 1, 2)}, s);
        ADD_FAILURE() << "not refused";
    } catch (const mr::MemoryLimitError& e) {
        // 4·10⁶ samples × 16 bytes (id, two barycentrics, depth).
        EXPECT_GE(reported_bytes(e.what()), 64000000u);
    }
}

TEST(MemoryLimit, TextureIsRefusedBeforeAllocating) {
    LimitGuard guard(1 << 20);
    const std::vector<float> texels(256 * 256 * 4, 0.5f);
    try {
        mr::Texture::from_float(texels.data(), 256, 256, 4, true, "big");
        ADD_FAILURE() << "not refused";
    } catch (const mr::MemoryLimitError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("texture 'big' (256x256"), std::string::npos) << msg;
        // Level 0 (256² × 16 bytes) and a third more for the mip chain.
        EXPECT_EQ(reported_bytes(msg), 256u * 256u * 16u * 4u / 3u);
    }
    mr::set_memory_limit(2 << 20);
    EXPECT_NO_THROW(mr::Texture::from_float(texels.data(), 256, 256, 4, true, "fits"));
}

TEST(MemoryLimit, IsAnInvalidArgumentForCallersThatReportBadInput) {
    const mr::Mesh m = one_triangle();
    const std::vector<mr::Draw> draws = {make_draw(m, glm::dmat4(1.0), mr::DrawState{})};
    LimitGuard guard(1);
    EXPECT_THROW(mr::render(draws, identity_camera(), sized(8, 8, 1)), std::invalid_argument);
}

}  // namespace
