#pragma once
// One row of the stability report: which case, what was tried, the figure measured, the bound
// it must meet and whether it did.
#include <string>
#include <vector>

namespace mipraster {

/// How hard the suite pushes: `fast` sizes run in CI (tens of seconds in all), `full` sizes are
/// the (10⁷ samples and more, 16384² textures; minutes).
enum class StressSize { fast, full };

std::string to_string(StressSize size);
/// "fast" or "full"; throws std::invalid_argument naming the value otherwise.
StressSize parse_stress_size(const std::string& name);

struct StressRow {
    int number = 0;            ///< the issue's case number, 1…12
    std::string name;          ///< short name, e.g. "watertight"
    std::string tried;         ///< what was rendered or looked up
    std::string figure;        ///< the measured figure(s)
    std::string bound;         ///< what the figure must meet
    bool pass = false;
    std::vector<std::string> details;  ///< per-setting measurements behind the figure (tables)

    std::string to_string() const;
    std::string to_json() const;
};

/// A plain-text report: one block per row (PASS/FAIL, case, tried, figure, bound), details indented.
std::string format_stress_report(const std::vector<StressRow>& rows, bool with_details);

/// The rows as a JSON array of objects {number, name, tried, figure, bound, pass, details}.
std::string stress_rows_to_json(const std::vector<StressRow>& rows);

}  // namespace mipraster
