#include "mipraster/pipeline/sample_pattern.hpp"

#include <cmath>
#include <stdexcept>

#include "mipraster/core/constants.hpp"
#include "mipraster/core/splitmix.hpp"

namespace mipraster {

namespace {

// The most square factorization samples = columns × rows with columns ≥ rows.
int grid_rows(int samples) {
    int rows = 1;
    for (int r = 1; r * r <= samples; ++r)
        if (samples % r == 0) rows = r;
    return rows;
}

}  // namespace

std::string to_string(PatternKind kind) {
    switch (kind) {
        case PatternKind::automatic: return "auto";
        case PatternKind::center: return "center";
        case PatternKind::grid: return "grid";
        case PatternKind::rotated: return "rotated";
        case PatternKind::stratified: return "stratified";
    }
    return "?";
}

PatternKind parse_pattern_kind(const std::string& name) {
    for (PatternKind k : {PatternKind::automatic, PatternKind::center, PatternKind::grid, PatternKind::rotated,
                          PatternKind::stratified})
        if (name == to_string(k)) return k;
    throw std::invalid_argument("pattern: unknown name '" + name +
                                "'; expected one of auto, center, grid, rotated, stratified");
}

SamplePattern make_sample_pattern(PatternKind kind, int samples, std::uint64_t seed) {
    if (samples < 1 || samples > kMaxSamples)
        throw std::invalid_argument("samples per pixel: expected 1 to " + std::to_string(kMaxSamples) + ", got " +
                                    std::to_string(samples));
    if (kind == PatternKind::automatic)
        kind = samples == 1 ? PatternKind::center : samples == 4 ? PatternKind::rotated : PatternKind::grid;
    SamplePattern p;
    p.kind = kind;
    auto add = [&](std::int32_t ox, std::int32_t oy) {
        p.x.push_back(ox);
        p.y.push_back(oy);
    };
    switch (kind) {
        case PatternKind::center:
            if (samples != 1)
                throw std::invalid_argument("pattern 'center' has 1 sample; got samples=" + std::to_string(samples));
            add(128, 128);
            break;
        case PatternKind::rotated:
            if (samples != 4)
                throw std::invalid_argument("pattern 'rotated' has 4 samples; got samples=" + std::to_string(samples));
            // (0.375,0.125) (0.875,0.375) (0.125,0.625) (0.625,0.875) in 1/256 px.
            add(96, 32);
            add(224, 96);
            add(32, 160);
            add(160, 224);
            p.columns = p.rows = 2;
            break;
        case PatternKind::grid:
        case PatternKind::stratified: {
            const int rows = grid_rows(samples), cols = samples / rows;
            p.columns = cols;
            p.rows = rows;
            std::uint64_t state = seed;
            for (int b = 0; b < rows; ++b)
                for (int a = 0; a < cols; ++a) {
                    if (kind == PatternKind::grid) {
                        // ((a+½)/cols, (b+½)/rows)·256 rounded to nearest, ties up; exact when the
                        // count divides 128.
                        add(static_cast<std::int32_t>((256 * (2 * a + 1) + cols) / (2 * cols)),
                            static_cast<std::int32_t>((256 * (2 * b + 1) + rows) / (2 * rows)));
                    } else {
                        // Stratum [a/cols, (a+1)/cols) × [b/rows, (b+1)/rows) on the 1/256 grid.
                        const int lo_x = 256 * a / cols, hi_x = 256 * (a + 1) / cols;
                        const int lo_y = 256 * b / rows, hi_y = 256 * (b + 1) / rows;
                        add(lo_x + static_cast<std::int32_t>(splitmix64(state) % static_cast<std::uint64_t>(hi_x - lo_x)),
                            lo_y + static_cast<std::int32_t>(splitmix64(state) % static_cast<std::uint64_t>(hi_y - lo_y)));
                    }
                }
            break;
        }
        case PatternKind::automatic: break;
    }
    return p;
}

std::string SamplePattern::to_string() const {
    std::string s = "SamplePattern(" + mipraster::to_string(kind) + ", [";
    for (int i = 0; i < count(); ++i)
        s += (i ? ", (" : "(") + std::to_string(x[i]) + "/256, " + std::to_string(y[i]) + "/256)";
    return s + "])";
}

}  // namespace mipraster
