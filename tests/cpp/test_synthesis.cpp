// Texture synthesis (Efros & Leung): every output pixel is a sample pixel; a perfectly periodic
// sample comes out as a shift of itself (periodic or not, tileable output or not); the same seed
// gives the same output on any thread count; the accelerated search (padded planes, unrolled
// sweeps, threads) picks exactly what a direct search over every candidate window picks (a
// plain re-statement of the algorithm below); bad input throws naming it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mipraster/texture/synthesis.hpp"

namespace {

namespace mr = mipraster;

mr::Image random_image(int w, int h, int c, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    mr::Image im(w, h, c);
    for (float& v : im.pixels) v = u(rng);
    return im;
}

// A w×h tile of random colours repeated to cols × rows tiles.
mr::Image periodic_image(int w, int h, int cols, int rows, int channels, unsigned seed) {
    const mr::Image tile = random_image(w, h, channels, seed);
    mr::Image im(w * cols, h * rows, channels);
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x)
            for (int c = 0; c < channels; ++c) im.at(x, y, c) = tile.at(x % w, y % h, c);
    return im;
}

mr::SynthesisSettings settings(int w, int h, int window, std::uint64_t seed = 1) {
    mr::SynthesisSettings s;
    s.width = w;
    s.height = h;
    s.window = window;
    s.seed = seed;
    s.threads = 2;
    return s;
}

TEST(Synthesis, EveryOutputPixelIsASamplePixel) {
    const mr::Image sample = random_image(20, 16, 4, 1);
    std::set<std::vector<float>> values;
    for (int y = 0; y < sample.height; ++y)
        for (int x = 0; x < sample.width; ++x)
            values.insert({sample.at(x, y, 0), sample.at(x, y, 1), sample.at(x, y, 2), sample.at(x, y, 3)});
    for (bool periodic : {false, true}) {
        mr::SynthesisSettings s = settings(30, 24, 5);
        s.periodic_sample = periodic;
        const mr::SynthesisResult r = mr::synthesize_texture(sample, s);
        ASSERT_EQ(r.image.width, 30);
        ASSERT_EQ(r.image.height, 24);
        ASSERT_EQ(r.image.channels, 4);
        EXPECT_EQ(r.candidates, periodic ? 20u * 16u : 16u * 12u);
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 30; ++x) {
                const std::vector<float> v = {r.image.at(x, y, 0), r.image.at(x, y, 1), r.image.at(x, y, 2), r.image.at(x, y, 3)};
                EXPECT_TRUE(values.count(v)) << "pixel " << x << ", " << y;
                const int src = r.source[static_cast<std::size_t>(y) * 30 + x];
                ASSERT_GE(src, 0);
                ASSERT_LT(src, 20 * 16);
                for (int c = 0; c < 4; ++c) EXPECT_EQ(v[c], sample.at(src % 20, src / 20, c));
            }
    }
}

// Whether `out` is the periodic tile shifted: out(x, y) = tile((x + a) mod w, (y + b) mod h).
::testing::AssertionResult is_shift_of_tile(const mr::Image& out, const mr::Image& sample, int w, int h) {
    // The shift from pixel (0, 0): the tile's colours are distinct, so it is unique.
    int a = -1, b = -1;
    for (int y = 0; y < h && a < 0; ++y)
        for (int x = 0; x < w && a < 0; ++x)
            if (sample.at(x, y, 0) == out.at(0, 0, 0) && sample.at(x, y, 1) == out.at(0, 0, 1)) a = x, b = y;
    if (a < 0) return ::testing::AssertionFailure() << "pixel (0, 0) is not a sample colour";
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int c = 0; c < out.channels; ++c)
                if (out.at(x, y, c) != sample.at((x + a) % w, (y + b) % h, c))
                    return ::testing::AssertionFailure() << "pixel (" << x << ", " << y << ") breaks the shift (" << a << ", " << b << ")";
    return ::testing::AssertionSuccess() << "shift (" << a << ", " << b << ")";
}

TEST(Synthesis, APerfectlyPeriodicSampleIsReproducedAsAShiftOfItself) {
    const int w = 6, h = 5;
    const mr::Image sample = periodic_image(w, h, 5, 5, 3, 2);
    for (bool periodic : {false, true})
        for (bool tileable : {false, true})
            for (std::uint64_t seed : {1u, 2u, 3u}) {
                SCOPED_TRACE(std::string(periodic ? "periodic" : "bounded") + (tileable ? ", tileable" : "") +
                             ", seed " + std::to_string(seed));
                mr::SynthesisSettings s = settings(tileable ? 36 : 41, tileable ? 30 : 33, 5, seed);
                s.periodic_sample = periodic;
                s.tileable = tileable;
                EXPECT_TRUE(is_shift_of_tile(mr::synthesize_texture(sample, s).image, sample, w, h));
            }
}

TEST(Synthesis, TheSameSeedGivesTheSameOutputOnAnyThreadCountAndOtherSeedsDiffer) {
    // Large enough (48² candidates × up to 81 known pixels) that the search is split across threads.
    const mr::Image sample = random_image(48, 48, 3, 3);
    mr::SynthesisSettings s = settings(32, 28, 9, 42);
    s.periodic_sample = true;
    s.threads = 1;
    const mr::SynthesisResult one = mr::synthesize_texture(sample, s);
    for (int threads : {1, 2, 3, 8}) {
        s.threads = threads;
        EXPECT_EQ(mr::synthesize_texture(sample, s).source, one.source) << threads << " threads";
    }
    s.seed = 43;
    EXPECT_NE(mr::synthesize_texture(sample, s).source, one.source);
}

// --- a direct statement of the algorithm, for comparison ---------------------------------------

struct Splitmix {
    std::uint64_t state;
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    std::size_t below(std::size_t n) { return static_cast<std::size_t>((static_cast<unsigned __int128>(next()) * n) >> 64); }
};

// Efros–Leung with every candidate window read pixel by pixel from the sample (wrapping when it
// is periodic): the seed patch in the middle, onion-skin layers (shuffled, then stably sorted by
// known pixels in the window), the Gaussian-weighted SSD over the known pixels, a uniform pick
// among the candidates within (1 + ε) of the best.
std::vector<int> direct_synthesis(const mr::Image& sample, const mr::SynthesisSettings& s) {
    const int W = s.width, H = s.height, n = s.window, r = n / 2, C = sample.channels;
    const int sw = sample.width, sh = sample.height;
    const double sigma = n / mr::kSynthesisSigmaDivisor;
    Splitmix rng{s.seed};
    std::vector<int> source(static_cast<std::size_t>(W) * H, -1);
    auto at = [&](int x, int y) -> int& { return source[static_cast<std::size_t>(y) * W + x]; };
    auto out_of = [&](int x, int y, int dx, int dy, int& qx, int& qy) {
        qx = x + dx, qy = y + dy;
        if (s.tileable) {
            qx = (qx % W + W) % W;
            qy = (qy % H + H) % H;
            return true;
        }
        return qx >= 0 && qy >= 0 && qx < W && qy < H;
    };
    const int seed_w = std::min({3, W, sw}), seed_h = std::min({3, H, sh});
    const int sx0 = static_cast<int>(rng.below(s.periodic_sample ? sw : sw - seed_w + 1));
    const int sy0 = static_cast<int>(rng.below(s.periodic_sample ? sh : sh - seed_h + 1));
    for (int y = 0; y < seed_h; ++y)
        for (int x = 0; x < seed_w; ++x) at((W - seed_w) / 2 + x, (H - seed_h) / 2 + y) = (sy0 + y) % sh * sw + (sx0 + x) % sw;
    const int cand_w = s.periodic_sample ? sw : sw - n + 1, cand_h = s.periodic_sample ? sh : sh - n + 1;
    for (;;) {
        std::vector<std::pair<int, int>> layer;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                if (at(x, y) >= 0) continue;
                bool touches = false;
                int qx, qy, count = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx)
                        if (out_of(x, y, dx, dy, qx, qy) && at(qx, qy) >= 0) touches = true;
                if (!touches) continue;
                for (int dy = -r; dy <= r; ++dy)
                    for (int dx = -r; dx <= r; ++dx) count += out_of(x, y, dx, dy, qx, qy) && at(qx, qy) >= 0;
                layer.push_back({count, y * W + x});
            }
        if (layer.empty()) break;
        for (std::size_t i = layer.size(); i > 1; --i) std::swap(layer[i - 1], layer[rng.below(i)]);
        std::stable_sort(layer.begin(), layer.end(), [](auto& a, auto& b) { return a.first > b.first; });
        for (auto [count, p] : layer) {
            const int x = p % W, y = p / W;
            std::vector<float> ssd;
            for (int cy = 0; cy < cand_h; ++cy)
                for (int cx = 0; cx < cand_w; ++cx) {
                    float acc = 0.0f;
                    for (int dy = -r; dy <= r; ++dy)
                        for (int dx = -r; dx <= r; ++dx) {
                            int qx, qy;
                            if (!out_of(x, y, dx, dy, qx, qy) || at(qx, qy) < 0) continue;
                            const int q = at(qx, qy);
                            const int tx = (cx + dx + r) % sw, ty = (cy + dy + r) % sh;
                            float sum = 0.0f;
                            for (int c = 0; c < C; ++c) {
                                const float d = sample.at(tx, ty, c) - sample.at(q % sw, q / sw, c);
                                sum += d * d;
                            }
                            acc += static_cast<float>(std::exp(-(dx * dx + dy * dy) / (2.0 * sigma * sigma))) * sum;
                        }
                    ssd.push_back(acc);
                }
            const float best = *std::min_element(ssd.begin(), ssd.end());
            const float limit = static_cast<float>(best * (1.0 + s.epsilon));
            std::vector<int> matches;
            for (std::size_t i = 0; i < ssd.size(); ++i)
                if (ssd[i] <= limit) matches.push_back(static_cast<int>(i));
            const int pick = matches[rng.below(matches.size())];
            at(x, y) = (pick / cand_w + r) % sh * sw + (pick % cand_w + r) % sw;
        }
    }
    return source;
}

TEST(Synthesis, TheAcceleratedSearchPicksWhatADirectSearchPicks) {
    const mr::Image sample = random_image(13, 11, 3, 5);
    for (bool periodic : {false, true})
        for (bool tileable : {false, true})
            for (int window : {1, 3, 5, 9}) {
                SCOPED_TRACE(std::string(periodic ? "periodic" : "bounded") + (tileable ? ", tileable" : "") +
                             ", window " + std::to_string(window));
                mr::SynthesisSettings s = settings(17, 14, window, 9);
                s.periodic_sample = periodic;
                s.tileable = tileable;
                s.epsilon = 0.3;
                const std::vector<int> expected = direct_synthesis(sample, s);
                const mr::SynthesisResult r = mr::synthesize_texture(sample, s);
                EXPECT_EQ(std::vector<int>(r.source.begin(), r.source.end()), expected);
            }
    // A search large enough to be split across threads (40² candidates × up to 81 known pixels).
    const mr::Image large = random_image(40, 40, 4, 6);
    mr::SynthesisSettings s = settings(20, 16, 9, 10);
    s.periodic_sample = true;
    const std::vector<int> expected = direct_synthesis(large, s);
    for (int threads : {1, 2, 3}) {
        s.threads = threads;
        const mr::SynthesisResult r = mr::synthesize_texture(large, s);
        EXPECT_EQ(std::vector<int>(r.source.begin(), r.source.end()), expected) << threads << " threads";
    }
    // A binary sample and a 3×3 window: many exact ties, so a pick changes as soon as one known
    // pixel is missing, e.g. if pixels searched in parallel were not independent. 128² candidates
    // make the search worth batching over threads.
    mr::Image binary = random_image(128, 128, 1, 7);
    for (float& v : binary.pixels) v = v < 0.5f ? 0.0f : 1.0f;
    mr::SynthesisSettings b = settings(24, 20, 3, 11);
    b.periodic_sample = true;
    const std::vector<int> expected_binary = direct_synthesis(binary, b);
    for (int threads : {1, 2, 3}) {
        b.threads = threads;
        const mr::SynthesisResult r = mr::synthesize_texture(binary, b);
        EXPECT_EQ(std::vector<int>(r.source.begin(), r.source.end()), expected_binary) << threads << " threads";
    }
}

TEST(Synthesis, SmallAndDegenerateSizesWork) {
    const mr::Image sample = random_image(5, 4, 1, 6);
    for (auto [w, h, window] : {std::tuple{1, 1, 1}, {1, 9, 3}, {2, 2, 3}, {40, 3, 3}, {7, 7, 1}}) {
        const mr::SynthesisResult r = mr::synthesize_texture(sample, settings(w, h, window));
        EXPECT_EQ(r.image.width, w);
        for (int src : r.source) EXPECT_TRUE(src >= 0 && src < 20);
    }
    // A window as large as the sample: one candidate, so every pixel but the 3×3 seed patch
    // copies the sample's centre.
    const mr::SynthesisResult one = mr::synthesize_texture(random_image(5, 5, 2, 8), settings(9, 8, 5));
    EXPECT_EQ(one.candidates, 1u);
    EXPECT_LE(std::count_if(one.source.begin(), one.source.end(), [](int s) { return s != 2 * 5 + 2; }), 9);
}

TEST(Synthesis, BadInputThrowsNamingIt) {
    const mr::Image sample = random_image(8, 6, 3, 7);
    auto message = [&](const mr::Image& im, const mr::SynthesisSettings& s) {
        try {
            mr::synthesize_texture(im, s);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no exception");
    };
    auto contains = [](const std::string& text, const char* part) {
        return text.find(part) != std::string::npos ? ::testing::AssertionSuccess()
                                                    : ::testing::AssertionFailure() << text;
    };
    EXPECT_TRUE(contains(message(sample, settings(8, 8, 4)), "window: 4; expected an odd size"));
    EXPECT_TRUE(contains(message(sample, settings(8, 8, 0)), "window"));
    EXPECT_TRUE(contains(message(sample, settings(8, 8, 7)), "larger than the sample (8x6)"));
    EXPECT_TRUE(contains(message(sample, settings(0, 8, 3)), "width: 0"));
    EXPECT_TRUE(contains(message(sample, settings(8, 100000, 3)), "height: 100000"));
    mr::SynthesisSettings tile = settings(4, 4, 5);
    tile.tileable = true;
    EXPECT_TRUE(contains(message(random_image(9, 9, 1, 1), tile), "tileable output"));
    mr::SynthesisSettings eps = settings(8, 8, 3);
    eps.epsilon = -0.5;
    EXPECT_TRUE(contains(message(sample, eps), "epsilon"));
    eps.epsilon = std::nan("");
    EXPECT_TRUE(contains(message(sample, eps), "epsilon"));
    mr::SynthesisSettings threads = settings(8, 8, 3);
    threads.threads = -2;
    EXPECT_TRUE(contains(message(sample, threads), "threads"));
    mr::Image nan = sample;
    nan.at(3, 2, 1) = std::nanf("");
    EXPECT_TRUE(contains(message(nan, settings(8, 8, 3)), "sample[2, 3, 1]"));
    EXPECT_TRUE(contains(message(mr::Image(), settings(8, 8, 1)), "empty"));
    EXPECT_TRUE(contains(message(mr::Image(4, 4, 5), settings(8, 8, 1)), "channels"));
}

}  // namespace
