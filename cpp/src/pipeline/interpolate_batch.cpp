#include "interpolate_batch.hpp"

#include <cstring>

namespace mipraster {
namespace kernels {

namespace {

// Four doubles per vector: two SSE2 registers on the x86-64 baseline, one AVX2 register where the
// CPU has it; the same IEEE operations element by element either way (-ffp-contract=off: no
// fused multiply-add). Always inlined into the one function of each target.
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double Doubles __attribute__((vector_size(32)));
typedef float Floats __attribute__((vector_size(16)));
constexpr int kWidth = 4;

[[gnu::always_inline]] inline Doubles splat(double x) { return Doubles{x, x, x, x}; }  // (not 0 + x: keeps −0)
[[gnu::always_inline]] inline Doubles load(const double* p) {
    Doubles r;
    std::memcpy(&r, p, sizeof r);
    return r;
}
[[gnu::always_inline]] inline void store(float* p, const Doubles& x) {
    const Floats f = __builtin_convertvector(x, Floats);
    std::memcpy(p, &f, sizeof f);
}
// std::clamp(x, lo, hi) element by element: x < lo ? lo : hi < x ? hi : x.
[[gnu::always_inline]] inline Floats clamp(Floats x, float lo, float hi) {
    const Floats l = Floats{lo, lo, lo, lo}, h = Floats{hi, hi, hi, hi};
    return x < l ? l : (h < x ? h : x);
}

// What the quotient rule reads of a triangle, splatted: 1/w_i, the vertices' uvs, and the
// numerators' and denominator's steps (TriangleUvs).
struct QuotientTerms {
    Doubles inv_w[3], u[3], v[3];
    Doubles numerator_dx_u, numerator_dx_v, numerator_dy_u, numerator_dy_v, denominator_dx, denominator_dy;
    QuotientTerms(const SetupTriangle& t, const TriangleUvs& uvs)
        : numerator_dx_u(splat(uvs.numerator_dx.x)), numerator_dx_v(splat(uvs.numerator_dx.y)),
          numerator_dy_u(splat(uvs.numerator_dy.x)), numerator_dy_v(splat(uvs.numerator_dy.y)),
          denominator_dx(splat(uvs.denominator_dx)), denominator_dy(splat(uvs.denominator_dy)) {
        for (int i = 0; i < 3; ++i)
            inv_w[i] = splat(double(t.inv_w[i])), u[i] = splat(uvs.v[i].x), v[i] = splat(uvs.v[i].y);
    }
};
// Perspective-correct uv and its derivatives (interpolate_uv): q_i = λ_i / w_i, inv_sum = 1 / Σ q_i.
[[gnu::always_inline]] inline void quotient_rule(const QuotientTerms& k, Doubles q0, Doubles q1, Doubles q2,
                                                 Doubles inv_sum, Doubles& u, Doubles& v, Doubles& dudx,
                                                 Doubles& dvdx, Doubles& dudy, Doubles& dvdy) {
    u = (q0 * k.u[0] + q1 * k.u[1] + q2 * k.u[2]) * inv_sum;
    v = (q0 * k.v[0] + q1 * k.v[1] + q2 * k.v[2]) * inv_sum;
    dudx = (k.numerator_dx_u - u * k.denominator_dx) * inv_sum;
    dvdx = (k.numerator_dx_v - v * k.denominator_dx) * inv_sum;
    dudy = (k.numerator_dy_u - u * k.denominator_dy) * inv_sum;
    dvdy = (k.numerator_dy_v - v * k.denominator_dy) * inv_sum;
}
[[gnu::always_inline]] inline void store_lookups(LookupBatch* lookups, int first, Doubles u, Doubles v, Doubles dudx,
                                                 Doubles dvdx, Doubles dudy, Doubles dvdy) {
    store(lookups->u + first, u);
    store(lookups->v + first, v);
    store(lookups->dudx + first, dudx);
    store(lookups->dvdx + first, dvdx);
    store(lookups->dudy + first, dudy);
    store(lookups->dvdy + first, dvdy);
}

// Samples first … first + 3. Untextured (no uvs, no lookups): the colour alone.
[[gnu::always_inline]] inline void interpolate_group(const DrawInputs& draw, Shading shading, Texturing texturing,
                                                     const SetupTriangle& t, const VertexValues& colors,
                                                     const TriangleUvs* uvs, const BatchWeights& w, int first,
                                                     float (&channels)[4][kLookupBatch], LookupBatch* lookups) {
    const Doubles l0 = load(w.l0 + first), l1 = load(w.l1 + first), l2 = load(w.l2 + first);
    const bool perspective_uv = texturing != Texturing::none && draw.uv_interpolation == Interpolation::perspective;
    // perspective_weights and interpolate_uv: q_i = λ_i / w_i and 1 / Σ q_i.
    Doubles q0{}, q1{}, q2{}, inv_sum{};
    if (shading == Shading::perspective || perspective_uv) {
        q0 = l0 * double(t.inv_w[0]);
        q1 = l1 * double(t.inv_w[1]);
        q2 = l2 * double(t.inv_w[2]);
        inv_sum = splat(1.0) / (q0 + q1 + q2);
    }
    if (shading == Shading::screen || shading == Shading::perspective) {  // VertexValues::interpolate
        const bool screen = shading == Shading::screen;
        const Doubles w0 = screen ? l0 : q0 * inv_sum, w1 = screen ? l1 : q1 * inv_sum, w2 = screen ? l2 : q2 * inv_sum;
        for (int c = 0; c < 4; ++c) {
            const Doubles sum = w0 * double(colors.v[0][c]) + w1 * double(colors.v[1][c]) + w2 * double(colors.v[2][c]);
            const float k = draw.color[c];
            const Floats clamped = clamp(__builtin_convertvector(sum, Floats), colors.lo[c], colors.hi[c]);
            const Floats value = Floats{k, k, k, k} * clamped;
            std::memcpy(channels[c] + first, &value, sizeof value);
        }
    }

    if (texturing == Texturing::none) return;
    // interpolate_uv (and texture_lookup's footprint scale).
    const glm::dvec2* v = uvs->v;
    Doubles u, uv_v, dudx = splat(0.0), dvdx = splat(0.0), dudy = splat(0.0), dvdy = splat(0.0);
    if (draw.uv_interpolation == Interpolation::flat) {
        u = splat(uvs->flat.x);
        uv_v = splat(uvs->flat.y);
    } else if (texturing == Texturing::fixed) {  // uv only, from the normalized weights
        const bool screen = !perspective_uv;
        const Doubles w0 = screen ? l0 : q0 * inv_sum, w1 = screen ? l1 : q1 * inv_sum, w2 = screen ? l2 : q2 * inv_sum;
        u = w0 * v[0].x + w1 * v[1].x + w2 * v[2].x;
        uv_v = w0 * v[0].y + w1 * v[1].y + w2 * v[2].y;
    } else if (!perspective_uv) {  // screen space: derivatives constant over the triangle
        u = l0 * v[0].x + l1 * v[1].x + l2 * v[2].x;
        uv_v = l0 * v[0].y + l1 * v[1].y + l2 * v[2].y;
        const glm::dvec2 dx = uvs->lx.x * v[0] + uvs->lx.y * v[1] + uvs->lx.z * v[2];
        const glm::dvec2 dy = uvs->ly.x * v[0] + uvs->ly.y * v[1] + uvs->ly.z * v[2];
        dudx = splat(dx.x), dvdx = splat(dx.y), dudy = splat(dy.x), dvdy = splat(dy.y);
    } else {  // perspective-correct, derivatives by the quotient rule
        quotient_rule(QuotientTerms(t, *uvs), q0, q1, q2, inv_sum, u, uv_v, dudx, dvdx, dudy, dvdy);
    }
    if (texturing == Texturing::lod && draw.footprint_scale != glm::dvec2(1.0)) {
        dudx *= draw.footprint_scale.x;
        dvdx *= draw.footprint_scale.x;
        dudy *= draw.footprint_scale.y;
        dvdy *= draw.footprint_scale.y;
    }
    store_lookups(lookups, first, u, uv_v, dudx, dvdx, dudy, dvdy);
}

// The textured batches of most draws: constant or flat shading (no colour sums), uv
// perspective-correct with analytic derivatives, scaled to a sample's cell under SSAA. Its terms
// are splatted once per batch, not per group as in interpolate_group (which a textured plane's
// interpolation spent a third of its instructions on; SSAA 4x's samples there took 39
// instructions each, against 23 here).
[[gnu::always_inline]] inline bool quotient_rule_only(const DrawInputs& draw, Shading shading, Texturing texturing) {
    return (shading == Shading::constant || shading == Shading::flat) && texturing == Texturing::lod &&
           draw.uv_interpolation == Interpolation::perspective;
}
template <bool kScaled>  // the derivatives times footprint_scale (interpolate_group's products)
[[gnu::always_inline]] inline void quotient_rule_group(const QuotientTerms& k, glm::dvec2 scale, const BatchWeights& w,
                                                       int first, LookupBatch* lookups) {
    const Doubles q0 = load(w.l0 + first) * k.inv_w[0], q1 = load(w.l1 + first) * k.inv_w[1],
                  q2 = load(w.l2 + first) * k.inv_w[2];
    const Doubles inv_sum = splat(1.0) / (q0 + q1 + q2);
    Doubles u, v, dudx, dvdx, dudy, dvdy;
    quotient_rule(k, q0, q1, q2, inv_sum, u, v, dudx, dvdx, dudy, dvdy);
    if constexpr (kScaled) {
        dudx *= scale.x;
        dvdx *= scale.x;
        dudy *= scale.y;
        dvdy *= scale.y;
    }
    store_lookups(lookups, first, u, v, dudx, dvdx, dudy, dvdy);
}

[[gnu::always_inline]] inline void interpolate_all(const DrawInputs& draw, Shading shading, Texturing texturing,
                                                   const SetupTriangle& t, const VertexValues& colors,
                                                   const TriangleUvs* uvs, const BatchWeights& w, glm::vec4* colour,
                                                   LookupBatch* lookups) {
    float channels[4][kLookupBatch];
    if (quotient_rule_only(draw, shading, texturing)) {
        const QuotientTerms k(t, *uvs);
        const glm::dvec2 scale = draw.footprint_scale;
        if (scale == glm::dvec2(1.0)) {
            for (int first = 0; first < w.count; first += kWidth)
                quotient_rule_group<false>(k, scale, w, first, lookups);
        } else {
            for (int first = 0; first < w.count; first += kWidth)
                quotient_rule_group<true>(k, scale, w, first, lookups);
        }
    } else {
        for (int first = 0; first < w.count; first += kWidth)
            interpolate_group(draw, shading, texturing, t, colors, uvs, w, first, channels, lookups);
    }
    if (lookups) lookups->count = w.count;
    if (shading == Shading::constant || shading == Shading::flat) {  // (one colour, computed once)
        const glm::vec4 c = shading == Shading::constant ? draw.color : draw.color * colors.v[0];
        for (int i = 0; i < w.count; ++i) colour[i] = c;
    } else {
        for (int i = 0; i < w.count; ++i)
            colour[i] = glm::vec4(channels[0][i], channels[1][i], channels[2][i], channels[3][i]);
    }
}

void interpolate_baseline(const DrawInputs& draw, Shading shading, Texturing texturing, const SetupTriangle& t,
                          const VertexValues& colors, const TriangleUvs* uvs, const BatchWeights& w, glm::vec4* colour,
                          LookupBatch* lookups) {
    interpolate_all(draw, shading, texturing, t, colors, uvs, w, colour, lookups);
}
#if defined(__x86_64__)
[[gnu::target("avx2")]] void interpolate_avx2(const DrawInputs& draw, Shading shading, Texturing texturing,
                                              const SetupTriangle& t, const VertexValues& colors, const TriangleUvs* uvs,
                                              const BatchWeights& w, glm::vec4* colour, LookupBatch* lookups) {
    interpolate_all(draw, shading, texturing, t, colors, uvs, w, colour, lookups);
}
#else
const auto interpolate_avx2 = interpolate_baseline;  // (never chosen: widest_vector() is 4)
#endif

// interpolate_batch and interpolate_colours: uvs and lookups null without texturing.
void interpolate(const DrawInputs& draw, Shading shading, Texturing texturing, const SetupTriangle& t,
                 const VertexValues& colors, const TriangleUvs* uvs, const BatchWeights& w, glm::vec4* colour,
                 LookupBatch* lookups) {
    (BatchSampler::widest_vector() == 8 ? interpolate_avx2 : interpolate_baseline)(draw, shading, texturing, t, colors,
                                                                                 uvs, w, colour, lookups);
}

}  // namespace

Shading batch_shading(Shading shading, const VertexValues& colors) {
    return (shading == Shading::screen || shading == Shading::perspective) && colors.one ? Shading::flat : shading;
}

bool interpolates_in_batches(const DrawInputs& draw, Shading shading, Texturing texturing, const SetupTriangle& t) {
    return shading != Shading::visibility && texturing != Texturing::none && t.clip_index < 0 &&
           !(texturing == Texturing::lod && draw.derivatives == DerivativeMode::quad);
}

void interpolate_batch(const DrawInputs& draw, Shading shading, Texturing texturing, const SetupTriangle& t,
                       const VertexValues& colors, const TriangleUvs& uvs, const BatchWeights& w, glm::vec4* colour,
                       LookupBatch& lookups) {
    interpolate(draw, shading, texturing, t, colors, &uvs, w, colour, &lookups);
}

void interpolate_colours(const DrawInputs& draw, Shading shading, const SetupTriangle& t, const VertexValues& colors,
                         const BatchWeights& w, glm::vec4* colour) {
    interpolate(draw, shading, Texturing::none, t, colors, nullptr, w, colour, nullptr);
}

}  // namespace kernels
}  // namespace mipraster
