#include "mipraster/stress/texture_reference.hpp"

#include <cmath>

namespace mipraster::stress {

namespace {

glm::dvec4 texel(const TextureLevel& level, long long i, long long j, const Sampler& s) {
    i = reference_wrap(i, level.width, s.wrap_u);
    j = reference_wrap(j, level.height, s.wrap_v);
    if (i < 0 || j < 0) return glm::dvec4(s.border_color);
    return glm::dvec4(level.at(static_cast<int>(i), static_cast<int>(j)));
}

}  // namespace

long long reference_wrap(long long i, long long n, WrapMode mode) {
    switch (mode) {
        case WrapMode::repeat: return ((i % n) + n) % n;
        case WrapMode::mirror: {
            const long long k = ((i % (2 * n)) + 2 * n) % (2 * n);  // position in a mirrored pair of copies
            return k < n ? k : 2 * n - 1 - k;
        }
        case WrapMode::clamp: return i < 0 ? 0 : (i >= n ? n - 1 : i);
        case WrapMode::border: return i < 0 || i >= n ? -1 : i;
    }
    return -1;
}

glm::dvec4 reference_lookup(const TextureLevel& level, double u, double v, TexelFilter filter, const Sampler& s) {
    const double U = u * level.width, V = v * level.height;
    if (filter == TexelFilter::nearest)
        return texel(level, static_cast<long long>(std::floor(U)), static_cast<long long>(std::floor(V)), s);
    const double fi = std::floor(U - 0.5), fj = std::floor(V - 0.5);
    const double a = U - 0.5 - fi, b = V - 0.5 - fj;
    const long long i = static_cast<long long>(fi), j = static_cast<long long>(fj);
    return (1 - b) * ((1 - a) * texel(level, i, j, s) + a * texel(level, i + 1, j, s)) +
           b * ((1 - a) * texel(level, i, j + 1, s) + a * texel(level, i + 1, j + 1, s));
}

}  // namespace mipraster::stress
