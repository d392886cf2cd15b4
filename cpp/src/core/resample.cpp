#include "mipraster/core/resample.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "mipraster/core/memory_limit.hpp"
#include "mipraster/core/thread_pool.hpp"

namespace mipraster {

namespace {

// Rows per parallel task: enough work per task to hide the pool's hand-off.
constexpr int kRowsPerTask = 16;
static_assert(kRowsPerTask >= 1, "a task holds at least one row");

void check_size(int size, const char* name) {
    if (size < 1 || size > kMaxResampleDimension)
        throw std::invalid_argument(std::string(name) + ": " + std::to_string(size) + " is out of range; expected 1 to " +
                                    std::to_string(kMaxResampleDimension));
}

void check_image(const Image& image) {
    if (image.width < 1 || image.height < 1 || image.channels < 1)
        throw std::invalid_argument("image: empty (" + image.to_string() + "); expected at least 1x1 with a channel");
    if (image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * image.channels)
        throw std::invalid_argument("image: " + std::to_string(image.pixels.size()) + " values for " + image.to_string());
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        if (!std::isfinite(image.pixels[i])) {
            const std::size_t pixel = i / static_cast<std::size_t>(image.channels);
            throw std::invalid_argument("image[" + std::to_string(pixel / static_cast<std::size_t>(image.width)) + ", " +
                                        std::to_string(pixel % static_cast<std::size_t>(image.width)) + ", " +
                                        std::to_string(i % static_cast<std::size_t>(image.channels)) + "] is " +
                                        std::to_string(image.pixels[i]) + "; expected a finite number");
        }
}

// Runs body(row) for every row, kRowsPerTask rows per task.
template <class Body>
void for_rows(ThreadPool& pool, int rows, Body body) {
    const std::size_t tasks = static_cast<std::size_t>((rows + kRowsPerTask - 1) / kRowsPerTask);
    pool.parallel_for(tasks, [&](std::size_t t) {
        const int end = std::min(rows, static_cast<int>(t + 1) * kRowsPerTask);
        for (int row = static_cast<int>(t) * kRowsPerTask; row < end; ++row) body(row);
    });
}

}  // namespace

std::string ResampleWeights::to_string() const {
    return "ResampleWeights(" + std::to_string(source_size) + " -> " + std::to_string(target_size) + ", " +
           mipraster::to_string(filter) + ", scale=" + std::to_string(scale) + ", " + std::to_string(weights.size()) +
           " weights)";
}

ResampleWeights resample_weights(int source_size, int target_size, ReconstructionFilter filter) {
    check_size(source_size, "source_size");
    check_size(target_size, "target_size");
    ResampleWeights w;
    w.source_size = source_size;
    w.target_size = target_size;
    w.filter = filter;
    const double ratio = static_cast<double>(source_size) / target_size;
    w.scale = std::max(1.0, ratio);
    const double support = filter_radius(filter) * w.scale;
    w.first.resize(static_cast<std::size_t>(target_size));
    w.offset.resize(static_cast<std::size_t>(target_size) + 1);
    std::vector<double> raw;
    for (int i = 0; i < target_size; ++i) {
        const double c = (i + 0.5) * ratio;
        // Source pixels whose centre k + ½ lies within the support, clipped to the image.
        int lo = std::max(0, static_cast<int>(std::floor(c - support - 0.5)));
        int hi = std::min(source_size - 1, static_cast<int>(std::ceil(c + support - 0.5)));
        raw.clear();
        for (int k = lo; k <= hi; ++k) raw.push_back(filter_weight(filter, (k + 0.5 - c) / w.scale));
        // Trim zero taps at both ends (the support is open, or half-open for the box).
        std::size_t a = 0, b = raw.size();
        while (a < b && raw[a] == 0.0) ++a;
        while (b > a && raw[b - 1] == 0.0) --b;
        double sum = 0.0;
        for (std::size_t t = a; t < b; ++t) sum += raw[t];
        // The tap nearest c is within ½ pixel, where every kernel's central lobe is positive.
        if (!(sum > 0.0)) throw std::logic_error("resample_weights: no positive weight for pixel " + std::to_string(i));
        w.first[static_cast<std::size_t>(i)] = lo + static_cast<int>(a);
        w.offset[static_cast<std::size_t>(i)] = static_cast<int>(w.weights.size());
        for (std::size_t t = a; t < b; ++t) w.weights.push_back(static_cast<float>(raw[t] / sum));
    }
    w.offset[static_cast<std::size_t>(target_size)] = static_cast<int>(w.weights.size());
    return w;
}

Image resample(const Image& image, int width, int height, ReconstructionFilter filter, int threads) {
    check_image(image);
    check_size(width, "width");
    check_size(height, "height");
    const std::uint64_t C = static_cast<std::uint64_t>(image.channels);
    const std::uint64_t out_bytes = std::uint64_t{4} * C * static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
    const std::uint64_t mid_bytes = std::uint64_t{4} * C * static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(image.height);
    if (std::max(out_bytes, mid_bytes) > kMaxResampleBytes)
        throw std::invalid_argument("size: " + std::to_string(width) + "x" + std::to_string(height) + " needs " +
                                    std::to_string(std::max(out_bytes, mid_bytes) >> 20) + " MiB; the limit is " +
                                    std::to_string(kMaxResampleBytes >> 20) + " MiB");
    if (width == image.width && height == image.height) return image;
    // (The cap above is fixed; the process's memory limit can be lower.)
    check_memory(out_bytes + mid_bytes, "resampling to " + std::to_string(width) + "x" + std::to_string(height));

    const ResampleWeights wx = resample_weights(image.width, width, filter);
    const ResampleWeights wy = resample_weights(image.height, height, filter);
    ThreadPool pool(resolve_thread_count(threads));
    const int c_count = image.channels;

    // Pass 1: every source row to the new width.
    Image mid(width, image.height, c_count);
    for_rows(pool, image.height, [&](int y) {
        const float* src = &image.pixels[static_cast<std::size_t>(y) * image.width * c_count];
        float* dst = &mid.pixels[static_cast<std::size_t>(y) * width * c_count];
        for (int i = 0; i < width; ++i) {
            const float* w = &wx.weights[static_cast<std::size_t>(wx.offset[static_cast<std::size_t>(i)])];
            const float* s = src + static_cast<std::size_t>(wx.first[static_cast<std::size_t>(i)]) * c_count;
            float acc[4] = {0, 0, 0, 0};
            const int taps = wx.taps(i);
            for (int c0 = 0; c0 < c_count; c0 += 4) {
                const int cn = std::min(4, c_count - c0);
                for (int c = 0; c < cn; ++c) acc[c] = 0.0f;
                for (int t = 0; t < taps; ++t)
                    for (int c = 0; c < cn; ++c) acc[c] += w[t] * s[static_cast<std::size_t>(t) * c_count + c0 + c];
                for (int c = 0; c < cn; ++c) dst[static_cast<std::size_t>(i) * c_count + c0 + c] = acc[c];
            }
        }
    });

    // Pass 2: every output row from the intermediate rows under its taps.
    Image out(width, height, c_count);
    const std::size_t row_values = static_cast<std::size_t>(width) * c_count;
    for_rows(pool, height, [&](int j) {
        float* dst = &out.pixels[static_cast<std::size_t>(j) * row_values];
        const float* w = &wy.weights[static_cast<std::size_t>(wy.offset[static_cast<std::size_t>(j)])];
        const int first = wy.first[static_cast<std::size_t>(j)];
        for (int t = 0; t < wy.taps(j); ++t) {
            const float* src = &mid.pixels[static_cast<std::size_t>(first + t) * row_values];
            const float wt = w[t];
            for (std::size_t v = 0; v < row_values; ++v) dst[v] += wt * src[v];
        }
    });
    return out;
}

}  // namespace mipraster
