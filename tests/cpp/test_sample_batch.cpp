// BatchSampler (texture/sample_batch.hpp) against its reference, sample_texture: covered lanes
// (anisotropic footprints of several probes included) within batch_sampling_tolerance, every other
// lane (a sampler outside covers(), a non-finite uv or derivative) bit for bit; constant textures
// exact (DESIGN.md §2.6); a lane independent of the rest of its batch; λ reading the levels it
// names (oracle bilinear on view.level(k)); levels built only when a lookup needs them (and never
// for a prefetch); the prefetched texel area holding every texel a lookup in its box reads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "mipraster/texture/sample.hpp"
#include "mipraster/texture/sample_batch.hpp"
#include "mipraster/texture/sampler.hpp"
#include "mipraster/texture/texture.hpp"
#include "texture_oracle.hpp"

namespace {

namespace mr = mipraster;
namespace to = tex_oracle;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kMaxF = std::numeric_limits<float>::max();

// ---- helpers ------------------------------------------------------------------------------------

/// A w×h level of random premultiplied RGBA: alpha uniform in [0, scale), colour ≤ alpha.
mr::TextureLevel premultiplied_level(int w, int h, float scale, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> d(0.0f, 1.0f);
    return to::make_level(w, h, [&](int, int) {
        const float a = scale * d(rng);
        return glm::vec4(a * d(rng), a * d(rng), a * d(rng), a);
    });
}

float largest_texel(const mr::TextureLevel& level) {
    float m = 0.0f;
    for (const glm::vec4& t : level.texels)
        for (int c = 0; c < 4; ++c) m = std::max(m, std::abs(t[c]));
    return m;
}

bool same_bits(glm::vec4 a, glm::vec4 b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::string str(glm::vec2 v) {
    std::ostringstream o;
    o.precision(9);
    o << "(" << v.x << ", " << v.y << ")";
    return o.str();
}
std::string str(glm::vec4 v) {
    std::ostringstream o;
    o.precision(9);
    o << "(" << v.x << ", " << v.y << ", " << v.z << ", " << v.w << ")";
    return o.str();
}
// Sampler::to_string leaves out the LOD clamps and the border colour.
std::string str(const mr::Sampler& s) {
    std::ostringstream o;
    o.precision(9);
    o << s.to_string() << " min_lod " << s.min_lod << " max_lod " << s.max_lod << " border " << str(s.border_color);
    return o.str();
}

struct Lookup {
    glm::vec2 uv, dx, dy;
    const char* uv_kind = "";
    const char* footprint_kind = "";
    bool finite() const {
        for (float x : {uv.x, uv.y, dx.x, dx.y, dy.x, dy.y})
            if (!std::isfinite(x)) return false;
        return true;
    }
    std::string describe() const {
        return "uv " + str(uv) + " [" + uv_kind + "] dx " + str(dx) + " dy " + str(dy) + " [" + footprint_kind + "]";
    }
};

void put(mr::LookupBatch& b, int lane, const Lookup& l) { b.set(lane, l.uv, l.dx, l.dy); }

glm::vec4 reference(const mr::TextureView& view, const mr::Sampler& s, const Lookup& l) {
    return mr::sample_texture(view, s, l.uv, l.dx, l.dy);
}

/// Random lookups of every kind the batch path must handle, for a w×h texture. Footprints are made
/// in texels of level 0 and divided by the size, so "2^k texels" and "isotropic" mean what they say.
class LookupGen {
public:
    LookupGen(int w, int h, std::uint64_t seed) : w_(w), h_(h), rng_(seed) {}

    Lookup next() {
        Lookup l;
        l.uv = uv(l.uv_kind);
        footprint(l);
        return l;
    }

    double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
    int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

private:
    float sign() { return integer(0, 1) ? 1.0f : -1.0f; }
    // A length log-uniform in [lo, hi] texels.
    double length(double lo, double hi) { return std::exp2(uniform(std::log2(lo), std::log2(hi))); }
    glm::dvec2 direction() {
        const double a = uniform(0.0, 6.283185307179586);
        return {std::cos(a), std::sin(a)};
    }
    glm::vec2 to_uv(glm::dvec2 texels) const { return {float(texels.x / w_), float(texels.y / h_)}; }

    glm::vec2 uv(const char*& kind) {
        const int r = integer(0, 99);
        if (r < 30) return kind = "unit", glm::vec2(float(uniform(-0.5, 1.5)), float(uniform(-0.5, 1.5)));
        if (r < 45) return kind = "wide", glm::vec2(float(uniform(-40, 40)), float(uniform(-40, 40)));
        if (r < 60) return kind = "far", glm::vec2(float(uniform(-1e4, 1e4)), float(uniform(-1e4, 1e4)));
        if (r < 75) {  // exact texel centres, some periods away
            kind = "centre";
            return {float((integer(0, w_ - 1) + 0.5) / w_ + integer(-3, 3)), float((integer(0, h_ - 1) + 0.5) / h_ + integer(-3, 3))};
        }
        if (r < 92) {  // exact texel edges (where bilinear's i = ⌊u·w − ½⌋ has fraction ½, ⌊u·w⌋ steps)
            kind = "edge";
            return {float(double(integer(0, w_)) / w_ + integer(-3, 3)), float(double(integer(0, h_)) / h_ + integer(-3, 3))};
        }
        if (r < 96) {
            kind = "huge";
            const float big[] = {1e8f, -3e9f, 1e30f, -kMaxF, kMaxF};
            return {big[integer(0, 4)], integer(0, 1) ? big[integer(0, 4)] : float(uniform(0, 1))};
        }
        kind = "nonfinite";
        const float bad[] = {kNaN, kInf, -kInf};
        glm::vec2 p(float(uniform(0, 1)), float(uniform(0, 1)));
        p[integer(0, 1)] = bad[integer(0, 2)];
        return p;
    }

    void footprint(Lookup& l) {
        const int r = integer(0, 99);
        glm::dvec2 a, b;  // texels
        if (r < 4) {
            l.footprint_kind = "zero";
            l.dx = l.dy = glm::vec2(0.0f);
            return;
        }
        if (r < 8) {
            l.footprint_kind = "tiny";
            l.dx = {sign() * 1e-30f, 0.0f};
            l.dy = {0.0f, sign() * 1e-30f};
            return;
        }
        if (r < 16) {
            l.footprint_kind = "magnify";
            a = length(0.05, 1.0) * direction();
            b = length(0.05, 1.0) * direction();
        } else if (r < 36) {
            l.footprint_kind = "typical";
            a = length(0.1, 64.0) * direction();
            b = length(0.1, 64.0) * direction();
        } else if (r < 50) {  // dx ⟂ dy, equal length in texels: one anisotropic probe
            l.footprint_kind = "isotropic";
            a = length(0.1, 64.0) * direction();
            b = {-a.y, a.x};
        } else if (r < 60) {  // exactly 2^k texels along the axes: λ an integer (exact in float for 2^n sizes)
            l.footprint_kind = "pow2";
            const double t = std::exp2(integer(-1, 11));
            a = {sign() * t, 0.0};
            b = {0.0, integer(0, 2) ? sign() * t : sign() * t / std::exp2(integer(1, 3))};
            if (integer(0, 1)) std::swap(a, b);
        } else if (r < 64) {  // a 3-4-5 vector of 2^k texels: λ a few ulps off an integer (the snap)
            l.footprint_kind = "pow2_345";
            const double t = std::exp2(integer(0, 11));
            a = {0.6 * t, 0.8 * t};
            b = {-0.8 * t, 0.6 * t};
        } else if (r < 68) {
            l.footprint_kind = "pow2_half";
            const double t = std::exp2(integer(0, 10) + 0.5);
            a = {t, 0.0};
            b = {0.0, t};
        } else if (r < 73) {
            l.footprint_kind = "huge";
            const float big = integer(0, 2) ? 1e30f : kMaxF;
            l.dx = {sign() * big, integer(0, 1) ? 0.0f : sign() * big};
            l.dy = {integer(0, 1) ? 0.0f : sign() * big, sign() * big};
            return;
        } else if (r < 80) {  // parallel, antiparallel or one zero derivative
            l.footprint_kind = "parallel";
            a = length(0.1, 64.0) * direction();
            const double scales[] = {1.0, -1.0, 0.5, 0.0};
            b = scales[integer(0, 3)] * a;
            if (integer(0, 1)) std::swap(a, b);
        } else if (r < 88) {  // ratio 2 to 10⁴: many probes, or max_anisotropy of them
            l.footprint_kind = "anisotropic";
            const glm::dvec2 d = direction();
            const double major = length(1.0, 256.0);
            a = major * d;
            b = major / length(2.0, 1e4) * glm::dvec2(-d.y, d.x);
        } else if (r < 94) {  // nearly isotropic (ratio 1 to 1.1): the one-or-two probes boundary
            l.footprint_kind = "near_isotropic";
            a = length(0.5, 64.0) * direction();
            b = glm::dvec2(-a.y, a.x) * uniform(1.0, 1.1);
        } else {
            l.footprint_kind = "nonfinite";
            l.dx = to_uv(length(0.1, 64.0) * direction());
            l.dy = to_uv(length(0.1, 64.0) * direction());
            const float bad[] = {kNaN, kInf, -kInf};
            float* c[] = {&l.dx.x, &l.dx.y, &l.dy.x, &l.dy.y};
            *c[integer(0, 3)] = bad[integer(0, 2)];
            return;
        }
        l.dx = to_uv(a);
        l.dy = to_uv(b);
    }

    int w_, h_;
    std::mt19937_64 rng_;
};

/// A random sampler that covers() takes: linear filters, mip none or linear, isotropic or
/// anisotropic (max 1, 4, 16 or 40: lines longer than the 16 probes the AVX2 path places at a
/// time), repeat or clamp per axis, bias in [−2, 2], LOD clamps varied.
mr::Sampler covered_sampler(LookupGen& g) {
    mr::Sampler s;
    s.mip_filter = g.integer(0, 3) ? mr::MipFilter::linear : mr::MipFilter::none;
    s.footprint = g.integer(0, 1) ? mr::FootprintFilter::anisotropic : mr::FootprintFilter::isotropic;
    const float anisotropy[] = {1.0f, 4.0f, 16.0f, 40.0f};
    s.max_anisotropy = anisotropy[g.integer(0, 3)];
    s.wrap_u = g.integer(0, 1) ? mr::WrapMode::repeat : mr::WrapMode::clamp;
    s.wrap_v = g.integer(0, 1) ? mr::WrapMode::repeat : mr::WrapMode::clamp;
    if (g.integer(0, 1)) s.lod_bias = float(g.uniform(-2.0, 2.0));  // else 0: the plain-magnification shortcut
    switch (g.integer(0, 4)) {
        case 0: s.min_lod = float(g.uniform(-1.0, 3.0)); break;
        case 1: s.max_lod = float(g.uniform(0.0, 4.0)); break;
        case 2:
            s.min_lod = float(g.uniform(0.0, 2.0));
            s.max_lod = s.min_lod + float(g.uniform(0.0, 2.0));
            break;
        default: break;  // the defaults, most of the time
    }
    s.border_color = glm::vec4(0.25f, 0.5f, 0.125f, 0.75f);
    s.validate();
    return s;
}

/// A sampler outside covers(): a covered one with one or two fields changed to what the float
/// path does not take.
mr::Sampler uncovered_sampler(LookupGen& g) {
    mr::Sampler s = covered_sampler(g);
    const int changes = g.integer(1, 2);
    for (int i = 0; i < changes; ++i) switch (g.integer(0, 6)) {
            case 0: s.mag_filter = mr::TexelFilter::nearest; break;
            case 1: s.min_filter = mr::TexelFilter::nearest; break;
            case 2: s.mip_filter = mr::MipFilter::nearest; break;
            case 3: s.wrap_u = mr::WrapMode::mirror; break;
            case 4: s.wrap_v = mr::WrapMode::border; break;
            case 5: s.footprint = mr::FootprintFilter::ewa; break;
            default: s.footprint = mr::FootprintFilter::sat; break;
        }
    return s;
}

/// True when sample_texture takes more than one anisotropic probe for this lookup, with margins
/// (ratio² ≥ 1.01, isotropic λ ≥ 0.01) that float rounding of the inputs cannot cross (counted, so
/// that the test is known to cover such lanes).
bool surely_several_probes(const mr::TextureView& view, const mr::Sampler& s, const Lookup& l) {
    if (s.footprint != mr::FootprintFilter::anisotropic || s.max_anisotropy < 2.0f || !l.finite()) return false;
    const to::Jacobian j = to::jacobian(view.width(), view.height(), l.dx, l.dy);
    const double px2 = j.ux * j.ux + j.vx * j.vx, py2 = j.uy * j.uy + j.vy * j.vy;
    const double pmax2 = std::max(px2, py2), pmin2 = std::min(px2, py2);
    if (!(pmin2 == 0.0 || pmax2 >= 1.01 * pmin2)) return false;
    mr::Sampler iso = s;
    iso.footprint = mr::FootprintFilter::isotropic;
    return mr::texture_lod(view, iso, l.dx, l.dy) >= 0.01;  // minifies (else one magnification lookup)
}

struct TextureCase {
    int w, h;
    float scale;  // 1: uniform [0, 1) per channel; else premultiplied with alpha up to scale
};

const TextureCase kTextures[] = {{1, 1, 1.0f},      {3, 5, 100.0f},     {7, 1, 1.0f},     {64, 64, 100.0f},
                                 {256, 128, 1.0f}, {1000, 600, 100.0f}, {1024, 1024, 1.0f}};

mr::Texture make_texture(const TextureCase& c, std::uint64_t seed) {
    return mr::Texture(c.scale == 1.0f ? to::random_level(c.w, c.h, seed) : premultiplied_level(c.w, c.h, c.scale, seed),
                       "random");
}

// ---- tests --------------------------------------------------------------------------------------

// covers() is the condition its comment states: linear mag and min filters, mip none or linear,
// isotropic or anisotropic, repeat or clamp on both axes; nothing else.
TEST(BatchSampler, CoversExactlyTheDocumentedSamplers) {
    const mr::TexelFilter texel[] = {mr::TexelFilter::nearest, mr::TexelFilter::linear};
    const mr::MipFilter mip[] = {mr::MipFilter::none, mr::MipFilter::nearest, mr::MipFilter::linear};
    const mr::FootprintFilter footprint[] = {mr::FootprintFilter::isotropic, mr::FootprintFilter::anisotropic,
                                             mr::FootprintFilter::ewa, mr::FootprintFilter::sat};
    const auto plain = [](mr::WrapMode m) { return m == mr::WrapMode::repeat || m == mr::WrapMode::clamp; };
    for (auto mag : texel)
        for (auto min : texel)
            for (auto mf : mip)
                for (auto fp : footprint)
                    for (auto wu : to::kAllWraps)
                        for (auto wv : to::kAllWraps) {
                            mr::Sampler s;
                            s.mag_filter = mag, s.min_filter = min, s.mip_filter = mf, s.footprint = fp;
                            s.wrap_u = wu, s.wrap_v = wv;
                            const bool expected = mag == mr::TexelFilter::linear && min == mr::TexelFilter::linear &&
                                                  mf != mr::MipFilter::nearest &&
                                                  (fp == mr::FootprintFilter::isotropic ||
                                                   fp == mr::FootprintFilter::anisotropic) &&
                                                  plain(wu) && plain(wv);
                            EXPECT_EQ(mr::BatchSampler::covers(s), expected) << str(s);
                        }
}

// The stated bound, on random lookups of every kind, batches of 1 to 8 with mixed kinds: per
// channel |batch − sample_texture| ≤ batch_sampling_tolerance(w, h) × max |texel| for covered
// lanes (several anisotropic probes included); bit for bit for lanes sample_texture computes
// (uncovered sampler, non-finite input).
TEST(BatchSampler, RandomLookupsMatchSampleTextureWithinTheStatedTolerance) {
    constexpr int kSamplersPerTexture = 42, kBatchesPerSampler = 40;
    long lanes = 0, covered_minifying = 0, covered_magnifying = 0, several_probes = 0, nonfinite = 0, uncovered = 0,
         failures = 0;
    std::uint64_t seed = 1000;
    for (const TextureCase& tc : kTextures) {
        const mr::Texture tex = make_texture(tc, ++seed);
        mr::TextureView view(tex);
        const float largest = largest_texel(tex.base_level());
        const double tolerance = mr::batch_sampling_tolerance(tc.w, tc.h) * largest;
        LookupGen gen(tc.w, tc.h, ++seed);
        for (int si = 0; si < kSamplersPerTexture; ++si) {
            const bool covered = si % 3 != 2;
            const mr::Sampler s = covered ? covered_sampler(gen) : uncovered_sampler(gen);
            ASSERT_EQ(mr::BatchSampler::covers(s), covered) << str(s);
            mr::BatchSampler batch_sampler(view, s);
            for (int bi = 0; bi < kBatchesPerSampler; ++bi) {
                mr::LookupBatch batch;
                batch.count = gen.integer(1, mr::kLookupBatch);
                Lookup lookups[mr::kLookupBatch];
                for (int lane = 0; lane < batch.count; ++lane) put(batch, lane, lookups[lane] = gen.next());
                glm::vec4 out[mr::kLookupBatch];
                batch_sampler.sample(batch, out);
                for (int lane = 0; lane < batch.count; ++lane) {
                    const Lookup& l = lookups[lane];
                    const glm::vec4 expected = reference(view, s, l);
                    const bool several = covered && surely_several_probes(view, s, l);
                    const bool exact = !covered || !l.finite();
                    ++lanes;
                    if (!covered) ++uncovered;
                    else if (!l.finite()) ++nonfinite;
                    else if (several) ++several_probes;
                    else if (mr::texture_lod(view, s, l.dx, l.dy) > 0.0) ++covered_minifying;
                    else ++covered_magnifying;
                    bool ok = exact ? same_bits(out[lane], expected) : true;
                    for (int c = 0; c < 4 && !exact; ++c) ok = ok && std::abs(double(out[lane][c]) - expected[c]) <= tolerance;
                    if (!ok && ++failures <= 12)
                        ADD_FAILURE() << tc.w << "x" << tc.h << " " << str(s) << "\n  lane " << lane << " of "
                                      << batch.count << ": " << l.describe() << "\n  batch " << str(out[lane])
                                      << ", sample_texture " << str(expected)
                                      << (exact ? " (must be bit-identical)" : "") << ", tolerance " << tolerance;
                }
            }
        }
    }
    std::cout << "lanes " << lanes << ": covered minifying " << covered_minifying << ", covered magnifying "
              << covered_magnifying << ", several anisotropic probes " << several_probes << ", non-finite "
              << nonfinite << ", uncovered sampler " << uncovered << "; failures " << failures << "\n";
    EXPECT_EQ(failures, 0);
    // Not vacuous: the float path's own work (covered, finite, minifying) is most of the lanes.
    EXPECT_GE(covered_minifying, 15000);
    EXPECT_GE(covered_magnifying, 2000);
    EXPECT_GE(several_probes, 1000);
    EXPECT_GE(nonfinite, 1000);
    EXPECT_GE(uncovered, 8000);
}

// §2.6 on the batch path: a constant texture comes back bit for bit for every covered sampler and
// every footprint kind (zero, tiny, huge, infinite, NaN, degenerate, 2^k, random) and size.
TEST(BatchSampler, ConstantTexturesAreReturnedExactly) {
    const glm::vec4 constants[] = {glm::vec4(0.3f, 0.7f, 1.0f / 3.0f, 0.9f), glm::vec4(123.456f, 1e-3f, 0.0f, 7e30f)};
    const std::pair<float, float> lod_variants[] = {{0.0f, 0.0f}, {-1.5f, 0.0f}, {1.7f, 0.0f}};
    long checked = 0, failures = 0;
    std::uint64_t seed = 2000;
    for (const glm::vec4& c : constants)
        for (const TextureCase& tc : kTextures) {
            mr::Texture tex(to::make_level(tc.w, tc.h, [&](int, int) { return c; }), "constant");
            mr::TextureView view(tex);
            LookupGen gen(tc.w, tc.h, ++seed);
            for (mr::MipFilter mip : {mr::MipFilter::none, mr::MipFilter::linear})
                for (float aniso : {0.0f, 1.0f, 4.0f, 16.0f})  // 0: isotropic
                    for (auto wu : {mr::WrapMode::repeat, mr::WrapMode::clamp})
                        for (auto wv : {mr::WrapMode::repeat, mr::WrapMode::clamp})
                            for (int lod = 0; lod < 5; ++lod) {
                                mr::Sampler s;
                                s.mip_filter = mip;
                                s.footprint = aniso > 0 ? mr::FootprintFilter::anisotropic : mr::FootprintFilter::isotropic;
                                s.max_anisotropy = std::max(aniso, 1.0f);
                                s.wrap_u = wu, s.wrap_v = wv;
                                if (lod < 3) s.lod_bias = lod_variants[lod].first;
                                if (lod == 3) s.min_lod = 1.5f;
                                if (lod == 4) s.min_lod = -1.0f, s.max_lod = 0.5f;
                                mr::BatchSampler batch_sampler(view, s);
                                for (int bi = 0; bi < 6; ++bi) {
                                    mr::LookupBatch batch;
                                    batch.count = mr::kLookupBatch;
                                    Lookup lookups[mr::kLookupBatch];
                                    for (Lookup& l : lookups) {
                                        do l = gen.next();  // a non-finite uv returns the border colour instead
                                        while (!std::isfinite(l.uv.x) || !std::isfinite(l.uv.y));
                                    }
                                    for (int lane = 0; lane < batch.count; ++lane) put(batch, lane, lookups[lane]);
                                    glm::vec4 out[mr::kLookupBatch];
                                    batch_sampler.sample(batch, out);
                                    for (int lane = 0; lane < batch.count; ++lane) {
                                        ++checked;
                                        if (!same_bits(out[lane], c) && ++failures <= 12)
                                            ADD_FAILURE() << tc.w << "x" << tc.h << " " << str(s) << " lane " << lane
                                                          << ": " << lookups[lane].describe() << ": got "
                                                          << str(out[lane]) << ", expected " << str(c);
                                    }
                                }
                            }
        }
    std::cout << "constant-texture lanes checked: " << checked << ", failures: " << failures << "\n";
    EXPECT_EQ(failures, 0);
}

// DESIGN.md §2.8 on the batch path: the four-lane (SSE2) and eight-lane (AVX2) float paths give the
// same bits for every lookup kind, sampler and size, lines of anisotropic probes included (the
// reference's line against anisotropic_line_avx2). On a CPU without AVX2 the eight-lane path is
// refused by name instead.
/// `batches` batches of 1 … kLookupBatch lookups from next(), sampled at vector widths 4 and 8:
/// the same bits lane by lane (a failure names the sampler and the lookup). Counts the lanes and
/// those surely of several probes.
template <typename Next>
void expect_vector_widths_agree(const mr::TextureView& view, const mr::Sampler& s, LookupGen& gen, int batches,
                                Next next, long& lanes, long& several_probes) {
    mr::BatchSampler four(view, s, 4), eight(view, s, 8);
    for (int bi = 0; bi < batches; ++bi) {
        mr::LookupBatch batch;
        batch.count = gen.integer(1, mr::kLookupBatch);
        std::vector<Lookup> lookups;
        for (int lane = 0; lane < batch.count; ++lane) {
            lookups.push_back(next());
            put(batch, lane, lookups.back());
        }
        glm::vec4 a[mr::kLookupBatch], b[mr::kLookupBatch];
        four.sample(batch, a);
        eight.sample(batch, b);
        for (int lane = 0; lane < batch.count; ++lane, ++lanes) {
            several_probes += surely_several_probes(view, s, lookups[lane]);
            ASSERT_TRUE(same_bits(a[lane], b[lane]))
                << view.width() << "x" << view.height() << " " << str(s) << "\n  " << lookups[lane].describe()
                << "\n  four lanes " << str(a[lane]) << ", eight lanes " << str(b[lane]);
        }
    }
}

TEST(BatchSampler, EveryVectorWidthGivesTheSameBits) {
    EXPECT_THROW(mr::BatchSampler(mr::TextureView(make_texture(kTextures[0], 1)), mr::Sampler{}, 5), std::invalid_argument);
    {  // (and a batch count out of range is refused, not read past the arrays)
        const mr::Texture tex = make_texture(kTextures[0], 1);
        mr::TextureView view(tex);
        mr::BatchSampler sampler(view, mr::Sampler{});
        mr::LookupBatch batch;
        glm::vec4 out[mr::kLookupBatch];
        for (int bad : {-1, mr::kLookupBatch + 1}) {
            batch.count = bad;
            EXPECT_THROW(sampler.sample(batch, out), std::invalid_argument);
        }
    }
    if (mr::BatchSampler::widest_vector() < 8) {
        const mr::Texture tex = make_texture(kTextures[0], 1);
        mr::TextureView view(tex);
        EXPECT_THROW(mr::BatchSampler(view, mr::Sampler{}, 8), std::invalid_argument);
        GTEST_SKIP() << "this CPU has no AVX2: only the four-lane path runs here";
    }
    long checked = 0, several_probes = 0;
    for (std::size_t ti = 0; ti < std::size(kTextures); ++ti) {
        const TextureCase& tc = kTextures[ti];
        const mr::Texture tex = make_texture(tc, 4000 + ti);
        mr::TextureView view(tex);
        LookupGen gen(tc.w, tc.h, 4100 + ti);
        for (int si = 0; si < 12; ++si) {
            const mr::Sampler s = covered_sampler(gen);
            expect_vector_widths_agree(view, s, gen, 120, [&] { return gen.next(); }, checked, several_probes);
            if (HasFatalFailure()) return;
        }
    }
    std::cout << "lanes " << checked << ", several anisotropic probes " << several_probes << "\n";
    EXPECT_GE(checked, 20000);
    EXPECT_GE(several_probes, 1000);  // (the eight-lane path's own line of probes: anisotropic_line_avx2)
}

// The eight-lane path decides each lane's line of probes four lanes per AVX2 vector
// (probe_lines_avx2), the four-lane path one lane at a time: the same bits for caps that are not
// integers or are huge, for ratios exactly on an integer (axis-aligned power-of-two footprints,
// where ⌈√ratio²⌉ is decided exactly) or near the cap, and for samplers whose λ is not plain (a
// bias, a min_lod, a max_lod of 0: the lanes that ask anisotropic_magnifies).
TEST(BatchSampler, VectorLineDecisionsGiveTheScalarLanesBits) {
    if (mr::BatchSampler::widest_vector() < 8)
        GTEST_SKIP() << "this CPU has no AVX2: only the four-lane path runs here";
    const TextureCase tc{256, 128, 1.0f};
    const mr::Texture tex = make_texture(tc, 4200);
    mr::TextureView view(tex);
    LookupGen gen(tc.w, tc.h, 4201);
    long checked = 0, several_probes = 0, on_integers = 0, magnifying_asked = 0;
    for (float cap : {1.5f, 2.5f, 7.9f, 16.0f, 1e4f}) {
        for (int variant = 0; variant < 4; ++variant) {
            mr::Sampler s;
            s.footprint = mr::FootprintFilter::anisotropic;
            s.max_anisotropy = cap;
            if (variant == 1) s.lod_bias = 0.75f;
            if (variant == 2) s.min_lod = 0.5f;
            if (variant == 3) s.max_lod = 0.0f;
            s.validate();
            const auto next = [&] {
                Lookup l;
                l.uv = glm::vec2(float(gen.uniform(-2.0, 3.0)), float(gen.uniform(-2.0, 3.0)));
                const bool exact = gen.integer(0, 1);  // power-of-two lengths along the axes
                const double major = exact ? std::exp2(gen.integer(-2, 7)) : std::exp2(gen.uniform(-2.0, 7.0));
                const double ratio = exact ? std::exp2(gen.integer(0, 5))
                                           : (gen.integer(0, 1) ? cap * (1.0 + gen.uniform(-1e-6, 1e-6))
                                                                : gen.uniform(1.0, 2.0 * cap));
                const double a = exact ? 0.0 : gen.uniform(0.0, 6.283185307179586);
                const glm::dvec2 along(std::cos(a), std::sin(a)), across(-along.y, along.x);
                const glm::dvec2 dx = along * major, dy = across * (major / ratio);
                l.dx = glm::vec2(float(dx.x / tc.w), float(dx.y / tc.h));
                l.dy = glm::vec2(float(dy.x / tc.w), float(dy.y / tc.h));
                if (gen.integer(0, 1)) std::swap(l.dx, l.dy);
                on_integers += exact && ratio > 1.0;
                magnifying_asked += variant != 0 && major <= 2.0 && ratio > 1.0;
                return l;
            };
            expect_vector_widths_agree(view, s, gen, 150, next, checked, several_probes);
            if (HasFatalFailure()) return;
        }
    }
    std::cout << "lanes " << checked << ", several anisotropic probes " << several_probes << ", ratios on integers "
              << on_integers << ", short lines of non-plain samplers " << magnifying_asked << "\n";
    EXPECT_GE(several_probes, 10000);
    EXPECT_GE(on_integers, 5000);
    EXPECT_GE(magnifying_asked, 1000);
}

// A lane's value does not depend on the batch around it: the same lookup alone in lane 0 and in any
// lane of a batch of random other lookups (unused lanes holding garbage) gives the same bits, and
// out[i] for i ≥ count is left untouched.
TEST(BatchSampler, LaneResultDoesNotDependOnOtherLanes) {
    const TextureCase tc{256, 128, 1.0f};
    const mr::Texture tex = make_texture(tc, 3000);
    mr::TextureView view(tex);
    LookupGen gen(tc.w, tc.h, 3001);
    const glm::vec4 sentinel(-7.0f, kNaN, 1e30f, -0.0f);
    long checked = 0;
    for (int si = 0; si < 6; ++si) {
        const mr::Sampler s = si < 5 ? covered_sampler(gen) : uncovered_sampler(gen);
        mr::BatchSampler batch_sampler(view, s);
        for (int li = 0; li < 150; ++li) {
            const Lookup l = gen.next();
            mr::LookupBatch alone;
            for (int lane = 0; lane < mr::kLookupBatch; ++lane)
                alone.set(lane, glm::vec2(kNaN), glm::vec2(kInf), glm::vec2(-kMaxF));  // garbage beyond count
            alone.count = 1;
            put(alone, 0, l);
            glm::vec4 solo[mr::kLookupBatch];
            std::fill(std::begin(solo), std::end(solo), sentinel);
            batch_sampler.sample(alone, solo);
            for (int lane = 1; lane < mr::kLookupBatch; ++lane)
                ASSERT_TRUE(same_bits(solo[lane], sentinel)) << "out[" << lane << "] written for a batch of 1";
            for (int lane = 0; lane < mr::kLookupBatch; ++lane) {
                mr::LookupBatch batch;
                batch.count = gen.integer(lane + 1, mr::kLookupBatch);
                for (int other = 0; other < mr::kLookupBatch; ++other)
                    put(batch, other, other == lane ? l : gen.next());  // lanes ≥ count: unused lookups
                glm::vec4 out[mr::kLookupBatch];
                std::fill(std::begin(out), std::end(out), sentinel);
                batch_sampler.sample(batch, out);
                ++checked;
                ASSERT_TRUE(same_bits(out[lane], solo[0]))
                    << str(s) << "\n  " << l.describe() << "\n  alone " << str(solo[0]) << ", lane " << lane << " of "
                    << batch.count << " " << str(out[lane]);
                for (int unused = batch.count; unused < mr::kLookupBatch; ++unused)
                    ASSERT_TRUE(same_bits(out[unused], sentinel)) << "out[" << unused << "] written, count " << batch.count;
            }
        }
    }
    EXPECT_GE(checked, 7000);
}

// The sampler's levels as λ says, against bilinear by hand on view.level(k) (texture_oracle.hpp):
// a footprint of exactly 2^k texels reads level k alone, one of 2^(k+½) texels the 50/50 blend
// of levels k and k+1 — both within the stated tolerance.
TEST(BatchSampler, PowerOfTwoFootprintsReadTheirLevels) {
    for (const TextureCase tc : {TextureCase{64, 64, 1.0f}, TextureCase{256, 128, 100.0f}, TextureCase{32, 4, 1.0f}}) {
        const mr::Texture tex = make_texture(tc, 4000 + tc.w);
        mr::TextureView view(tex);
        const double tolerance = mr::batch_sampling_tolerance(tc.w, tc.h) * largest_texel(tex.base_level());
        LookupGen gen(tc.w, tc.h, 4100 + tc.w);
        for (auto fp : {mr::FootprintFilter::isotropic, mr::FootprintFilter::anisotropic})
            for (auto wrap : {mr::WrapMode::repeat, mr::WrapMode::clamp}) {
                mr::Sampler s;
                s.footprint = fp;
                s.wrap_u = s.wrap_v = wrap;
                mr::BatchSampler batch_sampler(view, s);
                for (int k = 0; k < view.level_count(); ++k)
                    for (const double half : {0.0, 0.5}) {
                        if (half > 0 && k + 1 >= view.level_count()) continue;
                        const float t = float(std::exp2(k + half));
                        // Both axes 2^(k+half) texels (one anisotropic probe), in either order and sign.
                        const glm::vec2 ax(t / tc.w, 0.0f), ay(0.0f, t / tc.h);
                        for (int rep = 0; rep < 6; ++rep) {
                            mr::LookupBatch batch;
                            batch.count = mr::kLookupBatch;
                            for (int lane = 0; lane < batch.count; ++lane) {
                                const glm::vec2 uv(float(gen.uniform(-1.0, 2.0)), float(gen.uniform(-1.0, 2.0)));
                                if (lane % 2) batch.set(lane, uv, ax, -ay);
                                else batch.set(lane, uv, ay, ax);
                            }
                            glm::vec4 out[mr::kLookupBatch];
                            batch_sampler.sample(batch, out);
                            for (int lane = 0; lane < batch.count; ++lane) {
                                const double u = batch.u[lane], v = batch.v[lane];
                                glm::dvec4 expected = to::bilinear(view.level(k), u, v, s);
                                if (half > 0) expected = 0.5 * (expected + to::bilinear(view.level(k + 1), u, v, s));
                                for (int c = 0; c < 4; ++c)
                                    ASSERT_LE(std::abs(out[lane][c] - expected[c]), tolerance)
                                        << tc.w << "x" << tc.h << " " << str(s) << " λ " << k + half << " uv ("
                                        << u << ", " << v << ") channel " << c << ": batch " << str(out[lane])
                                        << ", levels by hand " << expected[c];
                            }
                        }
                    }
            }
    }
}

// Beyond the stated bound: at an exact 2^k footprint on a power-of-two texture and uv in [0, 1)
// (no wrapping: outside it, moving a coordinate by a period rounds in float), u·w, the bilinear
// fractions and λ = k are exact in float and no two levels are blended, so a float path that
// blends like sample_texture (a + t·(b − a), along u first) gives its bits.
TEST(BatchSampler, ExactLevelFootprintGivesSampleTextureBits) {
    for (const TextureCase tc : {TextureCase{64, 64, 1.0f}, TextureCase{256, 128, 100.0f}}) {
        const mr::Texture tex = make_texture(tc, 5000 + tc.w);
        mr::TextureView view(tex);
        LookupGen gen(tc.w, tc.h, 5100 + tc.w);
        for (auto fp : {mr::FootprintFilter::isotropic, mr::FootprintFilter::anisotropic})
            for (auto wrap : {mr::WrapMode::repeat, mr::WrapMode::clamp}) {
                mr::Sampler s;
                s.footprint = fp;
                s.wrap_u = s.wrap_v = wrap;
                mr::BatchSampler batch_sampler(view, s);
                for (int k = 0; k < view.level_count(); ++k) {
                    const float t = std::ldexp(1.0f, k);
                    const glm::vec2 dx(t / tc.w, 0.0f), dy(0.0f, t / tc.h);
                    mr::LookupBatch batch;
                    batch.count = mr::kLookupBatch;
                    for (int lane = 0; lane < batch.count; ++lane)
                        batch.set(lane, {float(gen.uniform(0.0, 1.0)), float(gen.uniform(0.0, 1.0))}, dx, dy);
                    glm::vec4 out[mr::kLookupBatch];
                    batch_sampler.sample(batch, out);
                    for (int lane = 0; lane < batch.count; ++lane) {
                        const glm::vec2 uv(batch.u[lane], batch.v[lane]);
                        const glm::vec4 expected = mr::sample_texture(view, s, uv, dx, dy);
                        EXPECT_TRUE(same_bits(out[lane], expected)) << tc.w << "x" << tc.h << " " << str(s) << " k "
                                                                    << k << " uv " << str(uv) << ": batch "
                                                                    << str(out[lane]) << ", sample_texture "
                                                                    << str(expected);
                    }
                }
            }
    }
}

// DESIGN.md §3, levels no lookup needs are never built: a BatchSampler on a fresh texture doing
// only magnifying lookups builds no level, and lookups at exactly λ = 1 build level 1 alone.
TEST(BatchSampler, BuildsOnlyTheLevelsItsLookupsNeed) {
    for (auto fp : {mr::FootprintFilter::isotropic, mr::FootprintFilter::anisotropic}) {
        mr::Texture tex(to::random_level(256, 256, 6000), "fresh");
        mr::TextureView view(tex);
        mr::Sampler s;
        s.footprint = fp;
        mr::BatchSampler batch_sampler(view, s);
        EXPECT_EQ(tex.built_levels(), 0) << "after construction, " << str(s);
        LookupGen gen(256, 256, 6001);
        const auto run = [&](glm::vec2 dx, glm::vec2 dy) {
            mr::LookupBatch batch;
            batch.count = mr::kLookupBatch;
            for (int lane = 0; lane < batch.count; ++lane) {
                glm::vec2 uv(float(gen.uniform(-1e3, 1e3)), float(gen.uniform(-0.5, 1.5)));
                if (lane == 7) uv.x = kNaN;  // the border colour: no level either
                batch.set(lane, uv, dx * float(gen.uniform(0.0, 1.0)), dy);
            }
            glm::vec4 out[mr::kLookupBatch];
            batch_sampler.sample(batch, out);
        };
        const float texel = 1.0f / 256;
        for (int i = 0; i < 50; ++i) {  // ρ ≤ 1 texel: λ ≤ 0
            run({0.0f, 0.0f}, {0.0f, 0.0f});
            run({1e-30f, 0.0f}, {0.0f, 1e-30f});
            run({0.25f * texel, 0.0f}, {0.0f, 0.5f * texel});
            run({0.6f * texel, 0.8f * texel}, {-0.8f * texel, 0.6f * texel});
            run({texel, 0.0f}, {0.0f, texel});
        }
        EXPECT_EQ(tex.built_levels(), 0) << "after magnifying lookups, " << str(s);
        for (int i = 0; i < 50; ++i) {
            mr::LookupBatch batch;
            batch.count = mr::kLookupBatch;
            for (int lane = 0; lane < batch.count; ++lane)
                batch.set(lane, {float(gen.uniform(-2, 2)), float(gen.uniform(-2, 2))}, {2 * texel, 0.0f},
                          {0.0f, -2 * texel});
            glm::vec4 out[mr::kLookupBatch];
            batch_sampler.sample(batch, out);
        }
        EXPECT_EQ(tex.built_levels(), 1) << "after lookups at exactly λ = 1, " << str(s);
    }
}

// A prefetch is a hint: it builds no level, whatever it is asked for.
TEST(BatchSampler, PrefetchBuildsNoLevel) {
    mr::Texture tex(to::random_level(256, 128, 6100), "fresh");
    mr::TextureView view(tex);
    mr::Sampler s;
    mr::BatchSampler batch_sampler(view, s);
    for (double lambda : {0.0, 0.5, 1.0, 2.5, 7.0, 8.0, 1e30, -1e30, double(kInf), double(kNaN)})
        for (glm::dvec2 lo : {glm::dvec2(0.1, 0.2), glm::dvec2(-5.0, 0.9), glm::dvec2(kNaN, 0.0)})
            batch_sampler.prefetch(lo, lo + glm::dvec2(0.3, 2.0), lambda);
    EXPECT_EQ(tex.built_levels(), 0);
}

// texel_area against the texels a bilinear lookup reads, worked out here in double: x = u·w − ½
// (u's fraction under repeat, u·w bounded to [−2, w + 2] under clamp), texels ⌊x⌋ and ⌊x⌋ + 1,
// wrapped or clamped. Every lookup in a random box reads texels inside the area, and the area
// is no longer along an axis than the box's span plus five texels (or the whole axis).
TEST(TexelArea, HoldsEveryTexelALookupInItsBoxReads) {
    std::mt19937_64 rng(6200);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto read = [](double u, int n, mr::WrapMode mode, int& first, int& second) {
        const double x = mode == mr::WrapMode::repeat ? (u - std::floor(u)) * n - 0.5
                                                      : std::clamp(u * n, -2.0, n + 2.0) - 0.5;
        const long i = static_cast<long>(std::floor(x));
        const auto fix = [&](long k) {
            return static_cast<int>(mode == mr::WrapMode::repeat ? (k % n + n) % n : std::clamp<long>(k, 0, n - 1));
        };
        first = fix(i), second = fix(i + 1);
    };
    const auto inside = [](int k, int ranges, const int (&from)[2], const int (&to)[2]) {
        for (int r = 0; r < ranges; ++r)
            if (k >= from[r] && k <= to[r]) return true;
        return false;
    };
    const auto length = [](int ranges, const int (&from)[2], const int (&to)[2]) {
        long n = 0;
        for (int r = 0; r < ranges; ++r) n += to[r] - from[r] + 1;
        return n;
    };
    const int sizes[] = {1, 2, 3, 7, 64, 100, 1024};
    const double spans[] = {0.0, 1e-4, 0.01, 0.3, 0.99, 1.0, 2.5};
    for (int trial = 0; trial < 20000; ++trial) {
        const int w = sizes[rng() % 7], h = sizes[rng() % 7];
        const mr::WrapMode wu = rng() % 2 ? mr::WrapMode::repeat : mr::WrapMode::clamp;
        const mr::WrapMode wv = rng() % 2 ? mr::WrapMode::repeat : mr::WrapMode::clamp;
        const glm::dvec2 lo(6 * unit(rng) - 3, 6 * unit(rng) - 3);
        const glm::dvec2 hi = lo + glm::dvec2(spans[rng() % 7], spans[rng() % 7]);
        const mr::TexelArea a = mr::texel_area(w, h, lo, hi, wu, wv);
        ASSERT_TRUE(a.columns >= 1 && a.rows >= 1);
        const long columns = length(a.columns, a.x_from, a.x_to), rows = length(a.rows, a.y_from, a.y_to);
        EXPECT_LE(columns, std::min<double>(w, (hi.x - lo.x) * w + 5)) << w << " wide, " << lo.x << " … " << hi.x;
        EXPECT_LE(rows, std::min<double>(h, (hi.y - lo.y) * h + 5)) << h << " high, " << lo.y << " … " << hi.y;
        for (int k = 0; k < 20; ++k) {
            // The box's corners, then points inside it.
            const glm::dvec2 t = k < 4 ? glm::dvec2(k & 1, k >> 1) : glm::dvec2(unit(rng), unit(rng));
            const glm::dvec2 uv = lo + t * (hi - lo);
            int x[2], y[2];
            read(uv.x, w, wu, x[0], x[1]);
            read(uv.y, h, wv, y[0], y[1]);
            for (int i = 0; i < 2; ++i) {
                ASSERT_TRUE(inside(x[i], a.columns, a.x_from, a.x_to))
                    << "column " << x[i] << " of " << w << " at u " << uv.x << ", box " << lo.x << " … " << hi.x;
                ASSERT_TRUE(inside(y[i], a.rows, a.y_from, a.y_to))
                    << "row " << y[i] << " of " << h << " at v " << uv.y << ", box " << lo.y << " … " << hi.y;
            }
        }
    }
    for (glm::dvec2 lo : {glm::dvec2(kNaN, 0.0), glm::dvec2(0.0, -double(kInf)), glm::dvec2(-0x1p21, 0.0)}) {
        const mr::TexelArea a = mr::texel_area(64, 64, lo, glm::dvec2(0.5), mr::WrapMode::repeat, mr::WrapMode::repeat);
        EXPECT_EQ(a.columns + a.rows, 0) << lo.x << ", " << lo.y;
    }
    EXPECT_EQ(mr::texel_area(64, 64, {0.6, 0.0}, {0.5, 1.0}, mr::WrapMode::clamp, mr::WrapMode::clamp).rows, 0)
        << "an inverted box";
}

}  // namespace
