// Reconstruction filters and image resampling (the notes' chapters 17 and 19): the kernels
// integrate to 1 and the cardinal splines are partitions of unity (numerical quadrature and sums
// over integer shifts); per-pixel weights sum to 1; the same size returns the input and the
// interpolating filters reproduce the input at scale 1; tent reproduces a linear ramp exactly and
// equals the notes' bilinear formula; box reduction by an integer factor is the block mean (brute
// force); results do not depend on the thread count; bad input throws naming it. The renderer's
// resolve with a wide filter equals resampling the image of a grid pattern's samples.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "helpers.hpp"
#include "mipraster/core/reconstruction_filter.hpp"
#include "mipraster/core/resample.hpp"
#include "mipraster/pipeline/renderer.hpp"

namespace {

namespace mr = mipraster;
using mr::ReconstructionFilter;

const ReconstructionFilter kFilters[] = {ReconstructionFilter::box, ReconstructionFilter::tent,
                                         ReconstructionFilter::mitchell, ReconstructionFilter::catmull_rom,
                                         ReconstructionFilter::lanczos3};

mr::Image random_image(int w, int h, int c, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    mr::Image im(w, h, c);
    for (float& v : im.pixels) v = u(rng);
    return im;
}

TEST(ReconstructionFilter, NamesRoundTripAndUnknownNamesAreRefused) {
    for (ReconstructionFilter f : kFilters) EXPECT_EQ(mr::parse_reconstruction_filter(mr::to_string(f)), f);
    try {
        mr::parse_reconstruction_filter("bicubic");
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("'bicubic'"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("lanczos3"), std::string::npos) << e.what();
    }
}

TEST(ReconstructionFilter, KernelsIntegrateToOneAndVanishOutsideTheirRadius) {
    for (ReconstructionFilter f : kFilters) {
        SCOPED_TRACE(mr::to_string(f));
        const double r = mr::filter_radius(f);
        // Midpoint rule on a fine grid (the kernels are piecewise smooth with breaks at integers
        // and half-integers, which the grid's cell edges hit).
        const int steps = 200000;
        double integral = 0.0;
        for (int i = 0; i < steps; ++i) integral += mr::filter_weight(f, -r + (i + 0.5) * (2.0 * r / steps));
        integral *= 2.0 * r / steps;
        // Lanczos is a windowed sinc: its integral is 0.99706, 1 only to within its truncation
        // (the resampler normalizes the weights anyway).
        EXPECT_NEAR(integral, f == ReconstructionFilter::lanczos3 ? 0.99706 : 1.0, f == ReconstructionFilter::lanczos3 ? 1e-5 : 1e-9);
        for (double x : {r, r + 0.25, 2 * r + 7, -r - 1e-9, -r - 3}) EXPECT_EQ(mr::filter_weight(f, x), 0.0) << x;
        EXPECT_GT(mr::filter_weight(f, 0.0), 0.0);
    }
}

TEST(ReconstructionFilter, CardinalSplinesArePartitionsOfUnity) {
    // Sum over integer shifts f(x − k) = 1 for every x: what makes a constant image stay constant
    // without normalization. (Lanczos is not one; the resampler normalizes its weights.)
    for (ReconstructionFilter f : {ReconstructionFilter::box, ReconstructionFilter::tent, ReconstructionFilter::mitchell,
                                   ReconstructionFilter::catmull_rom}) {
        SCOPED_TRACE(mr::to_string(f));
        for (int i = 0; i < 100; ++i) {
            const double x = i / 100.0;
            double sum = 0.0;
            for (int k = -5; k <= 5; ++k) sum += mr::filter_weight(f, x - k);
            EXPECT_NEAR(sum, 1.0, 1e-12) << "x = " << x;
        }
    }
}

TEST(ResampleWeights, EveryPixelsWeightsSumToOneAndStayInsideTheSource) {
    for (ReconstructionFilter f : kFilters)
        for (int src : {1, 2, 3, 7, 16, 33, 100})
            for (int dst : {1, 2, 5, 7, 16, 31, 64, 250}) {
                const mr::ResampleWeights w = mr::resample_weights(src, dst, f);
                ASSERT_EQ(static_cast<int>(w.first.size()), dst);
                for (int i = 0; i < dst; ++i) {
                    double sum = 0.0;
                    for (int t = 0; t < w.taps(i); ++t) sum += w.weights[static_cast<std::size_t>(w.offset[i] + t)];
                    EXPECT_NEAR(sum, 1.0, 1e-6) << mr::to_string(f) << " " << src << " -> " << dst << " pixel " << i;
                    EXPECT_GE(w.first[i], 0);
                    EXPECT_LE(w.first[i] + w.taps(i), src);
                    EXPECT_GE(w.taps(i), 1);
                }
            }
}

TEST(ResampleWeights, MinifyingWidensTheKernelByTheReductionFactor) {
    // 64 → 8: a tent reaches 8 source pixels either side, so an interior pixel reads 16 taps.
    const mr::ResampleWeights w = mr::resample_weights(64, 8, ReconstructionFilter::tent);
    EXPECT_EQ(w.scale, 8.0);
    EXPECT_EQ(w.taps(4), 16);
    // Magnifying does not narrow it: 8 → 64 reads at most 2 taps per pixel.
    const mr::ResampleWeights m = mr::resample_weights(8, 64, ReconstructionFilter::tent);
    EXPECT_EQ(m.scale, 1.0);
    for (int i = 0; i < 64; ++i) EXPECT_LE(m.taps(i), 2);
}

TEST(Resample, TheSameSizeReturnsTheInputAndInterpolatingFiltersHaveUnitWeightsAtScaleOne) {
    const mr::Image im = random_image(13, 9, 4, 1);
    for (ReconstructionFilter f : kFilters) EXPECT_EQ(mr::resample(im, 13, 9, f).pixels, im.pixels) << mr::to_string(f);
    // Without the shortcut: at scale 1 every target centre lands on a source centre, where the
    // interpolating kernels are 1 and 0 at the other integers.
    for (ReconstructionFilter f : {ReconstructionFilter::box, ReconstructionFilter::tent, ReconstructionFilter::catmull_rom,
                                   ReconstructionFilter::lanczos3}) {
        const mr::ResampleWeights w = mr::resample_weights(13, 13, f);
        for (int i = 0; i < 13; ++i) {
            ASSERT_EQ(w.taps(i), 1) << mr::to_string(f) << " pixel " << i;
            EXPECT_EQ(w.first[i], i);
            EXPECT_EQ(w.weights[static_cast<std::size_t>(w.offset[i])], 1.0f);
        }
    }
}

TEST(Resample, TentReproducesALinearRampExactlyWhenMagnifyingAndForIntegerReductions) {
    // A ramp v = a·x + b·y + c (x, y at pixel centres) in every channel with its own slopes.
    const int W = 24, H = 20;
    mr::Image ramp(W, H, 3);
    const double a[3] = {0.03, -0.02, 0.011}, b[3] = {0.017, 0.025, -0.04}, c0[3] = {0.1, 0.7, 0.9};
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int c = 0; c < 3; ++c) ramp.at(x, y, c) = static_cast<float>(a[c] * (x + 0.5) + b[c] * (y + 0.5) + c0[c]);
    struct Case {
        int w, h;
    };
    for (const Case& s : {Case{37, 31}, Case{48, 40}, Case{100, 23}, Case{12, 10}, Case{8, 5}, Case{6, 4}}) {
        SCOPED_TRACE(std::to_string(s.w) + "x" + std::to_string(s.h));
        const mr::Image out = mr::resample(ramp, s.w, s.h, ReconstructionFilter::tent, 1);
        const double sx = double(W) / s.w, sy = double(H) / s.h;
        for (int j = 0; j < s.h; ++j)
            for (int i = 0; i < s.w; ++i) {
                const double x = (i + 0.5) * sx, y = (j + 0.5) * sy;  // source position of the target centre
                // Exact where the (widened) tent lies inside the source: no edge renormalization.
                const double reach_x = std::max(1.0, sx), reach_y = std::max(1.0, sy);
                if (x - reach_x < 0.5 || x + reach_x > W - 0.5 || y - reach_y < 0.5 || y + reach_y > H - 0.5) continue;
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(out.at(i, j, c), a[c] * x + b[c] * y + c0[c], 2e-6) << "pixel " << i << ", " << j;
            }
    }
}

TEST(Resample, TentMagnificationIsTheNotesBilinearInterpolation) {
    const mr::Image im = random_image(9, 7, 3, 2);
    const int W = 31, H = 26;
    const mr::Image out = mr::resample(im, W, H, ReconstructionFilter::tent, 1);
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            // The notes' bilinearReconstruction at the source position, pixel centres at integers.
            const double x = (i + 0.5) * 9.0 / W - 0.5, y = (j + 0.5) * 7.0 / H - 0.5;
            if (x < 0 || y < 0 || x > 8 || y > 6) continue;  // the edge renormalizes instead
            const int ix = std::min(7, static_cast<int>(x)), iy = std::min(5, static_cast<int>(y));
            const double fx = x - ix, fy = y - iy;
            for (int c = 0; c < 3; ++c) {
                const double top = (1 - fx) * im.at(ix, iy, c) + fx * im.at(ix + 1, iy, c);
                const double bottom = (1 - fx) * im.at(ix, iy + 1, c) + fx * im.at(ix + 1, iy + 1, c);
                EXPECT_NEAR(out.at(i, j, c), (1 - fy) * top + fy * bottom, 2e-6) << "pixel " << i << ", " << j;
            }
        }
}

TEST(Resample, BoxReductionByAnIntegerFactorIsTheBlockMean) {
    const mr::Image im = random_image(24, 18, 4, 3);
    for (int k : {2, 3, 6}) {
        const mr::Image out = mr::resample(im, 24 / k, 18 / k, ReconstructionFilter::box, 1);
        for (int j = 0; j < 18 / k; ++j)
            for (int i = 0; i < 24 / k; ++i)
                for (int c = 0; c < 4; ++c) {
                    double sum = 0.0;
                    for (int y = j * k; y < (j + 1) * k; ++y)
                        for (int x = i * k; x < (i + 1) * k; ++x) sum += im.at(x, y, c);
                    EXPECT_NEAR(out.at(i, j, c), sum / (k * k), 1e-6);
                }
    }
}

TEST(Resample, AConstantImageStaysConstantForEveryFilterAndSize) {
    mr::Image im(17, 11, 2);
    for (std::size_t i = 0; i < im.pixels.size(); ++i) im.pixels[i] = i % 2 ? 0.25f : 0.8f;
    for (ReconstructionFilter f : kFilters)
        for (auto [w, h] : {std::pair<int, int>{1, 1}, {5, 3}, {40, 29}, {17, 2}, {300, 7}}) {
            const mr::Image out = mr::resample(im, w, h, f, 1);
            for (std::size_t i = 0; i < out.pixels.size(); ++i)
                ASSERT_NEAR(out.pixels[i], i % 2 ? 0.25f : 0.8f, 1e-6) << mr::to_string(f) << " " << w << "x" << h;
        }
}

TEST(Resample, TheResultDoesNotDependOnTheThreadCount) {
    const mr::Image im = random_image(123, 77, 4, 4);
    for (ReconstructionFilter f : {ReconstructionFilter::mitchell, ReconstructionFilter::lanczos3}) {
        const mr::Image one = mr::resample(im, 50, 190, f, 1);
        EXPECT_EQ(mr::resample(im, 50, 190, f, 2).pixels, one.pixels);
        EXPECT_EQ(mr::resample(im, 50, 190, f, 5).pixels, one.pixels);
    }
}

TEST(Resample, BadInputThrowsNamingIt) {
    const mr::Image im = random_image(4, 4, 3, 5);
    auto message = [&](auto call) {
        try {
            call();
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no exception");
    };
    EXPECT_NE(message([&] { mr::resample(im, 0, 4, ReconstructionFilter::tent); }).find("width"), std::string::npos);
    EXPECT_NE(message([&] { mr::resample(im, 4, -3, ReconstructionFilter::tent); }).find("height"), std::string::npos);
    EXPECT_NE(message([&] { mr::resample(im, 1 << 20, 4, ReconstructionFilter::tent); }).find("width"), std::string::npos);
    EXPECT_NE(message([&] { mr::resample(im, 60000, 60000, ReconstructionFilter::tent); }).find("MiB"), std::string::npos);
    EXPECT_NE(message([&] { mr::resample(mr::Image(), 4, 4, ReconstructionFilter::tent); }).find("empty"), std::string::npos);
    mr::Image nan = im;
    nan.at(2, 1, 1) = std::nanf("");
    EXPECT_NE(message([&] { mr::resample(nan, 8, 8, ReconstructionFilter::tent); }).find("image[1, 2, 1]"), std::string::npos);
    EXPECT_NE(message([&] { mr::resample(im, 8, 8, ReconstructionFilter::tent, -1); }).find("threads"), std::string::npos);
}

// --- the renderer's resolve ----------------------------------------------------------------------

// Vertex-coloured triangles with edges at many slopes, in NDC (identity camera).
mr::Mesh colourful_mesh() {
    mr::Mesh m;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> pos(-1.2f, 1.2f), col(0.0f, 1.0f);
    for (int t = 0; t < 12; ++t) {
        for (int v = 0; v < 3; ++v) {
            m.positions.push_back({pos(rng), pos(rng), 0.0f});
            m.colors.push_back({col(rng), col(rng), col(rng), 1.0f});
        }
        helpers::add_triangle(m, 3 * t, 3 * t + 1, 3 * t + 2);
    }
    return m;
}

// The samples of a C×R grid pattern as a (C·W)×(R·H) image: sample (a, b) of pixel (x, y) is
// image pixel (C·x + a, R·y + b).
mr::Image sample_image(const mr::RenderResult& r, int cols, int rows) {
    const mr::Framebuffer& fb = r.framebuffer;
    mr::Image im(fb.width * cols, fb.height * rows, 4);
    for (int s = 0; s < fb.samples; ++s) {
        const int a = static_cast<int>(r.pattern.x[s] * cols / mr::kSubpixelOne);  // column of the sample in the grid
        const int b = static_cast<int>(r.pattern.y[s] * rows / mr::kSubpixelOne);
        for (int y = 0; y < fb.height; ++y)
            for (int x = 0; x < fb.width; ++x)
                for (int c = 0; c < 4; ++c) im.at(cols * x + a, rows * y + b, c) = fb.color[fb.sample_index(x, y, s) * 4 + c];
    }
    return im;
}

TEST(ResolveFilter, ResolvingWithAFilterEqualsResamplingTheSampleImageWithIt) {
    const mr::Mesh mesh = colourful_mesh();
    const int W = 24, H = 18;
    for (int spp : {4, 16}) {
        const int n = spp == 4 ? 2 : 4;
        for (ReconstructionFilter f : kFilters) {
            SCOPED_TRACE(std::to_string(spp) + " spp, " + mr::to_string(f));
            mr::RenderSettings s = helpers::settings(W, H, spp, mr::PatternKind::grid);  // keeps the samples
            s.resolve_filter = f;
            s.clear_color = glm::vec4(0.1f, 0.2f, 0.3f, 1.0f);
            const mr::RenderResult r = mr::render({helpers::make_draw(mesh, glm::dmat4(1.0), helpers::no_depth())},
                                                  helpers::identity_camera(), s);
            const mr::Image expected = mr::resample(sample_image(r, n, n), W, H, f, 1);
            double worst = 0.0;
            for (std::size_t i = 0; i < expected.pixels.size(); ++i)
                worst = std::max(worst, double(std::fabs(r.color.pixels[i] - expected.pixels[i])));
            EXPECT_LT(worst, 2e-6);
            // The same without keeping the samples, and on one thread.
            s.keep_samples = false;
            s.threads = 1;
            const mr::RenderResult r1 = mr::render({helpers::make_draw(mesh, glm::dmat4(1.0), helpers::no_depth())},
                                                   helpers::identity_camera(), s);
            EXPECT_EQ(r1.color.pixels, r.color.pixels);
            EXPECT_TRUE(r1.framebuffer.color.empty());
        }
    }
}

TEST(ResolveFilter, WideFiltersSmoothAcrossPixelsAndTheBoxStaysPixelLocal) {
    // A half-plane edge: the box resolve reaches the edge pixel only, tent and wider filters also
    // the next pixel over, and all keep a flat region flat.
    mr::Mesh half;
    half.positions = {{-2, -2, 0}, {0.0625f, -2, 0}, {0.0625f, 2, 0}, {-2, 2, 0}};
    helpers::add_triangle(half, 0, 1, 2);
    helpers::add_triangle(half, 0, 2, 3);
    const int W = 32, H = 8;
    for (ReconstructionFilter f : kFilters) {
        mr::RenderSettings s = helpers::settings(W, H, 16, mr::PatternKind::grid);
        s.resolve_filter = f;
        s.clear_color = glm::vec4(0, 0, 0, 1);
        const mr::RenderResult r = mr::render({helpers::make_draw(half, glm::dmat4(1.0), helpers::no_depth())},
                                              helpers::identity_camera(), s);
        // The edge is at x = 17 px: pixels 0..16 white, 17.. black under the box filter.
        EXPECT_NEAR(r.color.at(2, 4, 0), 1.0f, 1e-6) << mr::to_string(f);
        EXPECT_NEAR(r.color.at(28, 4, 0), 0.0f, 1e-6) << mr::to_string(f);
        if (f == ReconstructionFilter::box) {
            EXPECT_EQ(r.color.at(16, 4, 0), 1.0f);
            EXPECT_EQ(r.color.at(17, 4, 0), 0.0f);
        } else {
            EXPECT_LT(r.color.at(16, 4, 0), 1.0f) << mr::to_string(f);
            EXPECT_GT(r.color.at(17, 4, 0), 0.0f) << mr::to_string(f);
        }
    }
}

TEST(ResolveFilter, NamesParseAndTheTileResolveRefusesWideFilters) {
    EXPECT_EQ(mr::parse_resolve_filter("mitchell"), ReconstructionFilter::mitchell);
    EXPECT_THROW(mr::parse_resolve_filter("gauss"), std::invalid_argument);
    mr::Image out(2, 2, 4);
    std::vector<float> data(2 * 2 * 4, 0.5f);
    const mr::SampleWindow window{data.data(), 4, 0, 0, 2, 1};
    EXPECT_THROW(mr::resolve_tile(window, 0, 0, 2, 2, ReconstructionFilter::tent, out), std::invalid_argument);
}

}  // namespace
