#include "mipraster/stress/stress_row.hpp"

#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace mipraster {

namespace {

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", c);
                    out += buf;
                } else {
                    out += c;
                }
        }
    }
    return out + "\"";
}

}  // namespace

std::string to_string(StressSize size) { return size == StressSize::fast ? "fast" : "full"; }

StressSize parse_stress_size(const std::string& name) {
    if (name == "fast") return StressSize::fast;
    if (name == "full") return StressSize::full;
    throw std::invalid_argument("stress size: expected 'fast' or 'full', got '" + name + "'");
}

std::string StressRow::to_string() const {
    std::ostringstream o;
    o << "StressRow(" << number << " " << name << ": " << figure << " [bound " << bound << "] "
      << (pass ? "PASS" : "FAIL") << ")";
    return o.str();
}

std::string StressRow::to_json() const {
    std::ostringstream o;
    o << "{\"number\": " << number << ", \"name\": " << json_string(name) << ", \"tried\": " << json_string(tried)
      << ", \"figure\": " << json_string(figure) << ", \"bound\": " << json_string(bound)
      << ", \"pass\": " << (pass ? "true" : "false") << ", \"details\": [";
    for (std::size_t i = 0; i < details.size(); ++i) o << (i ? ", " : "") << json_string(details[i]);
    o << "]}";
    return o.str();
}

std::string format_stress_report(const std::vector<StressRow>& rows, bool with_details) {
    std::ostringstream o;
    for (const StressRow& r : rows) {
        o << (r.pass ? "PASS " : "FAIL ") << r.number << ". " << r.name << "\n"
          << "     tried:  " << r.tried << "\n"
          << "     figure: " << r.figure << "\n"
          << "     bound:  " << r.bound << "\n";
        if (with_details)
            for (const std::string& d : r.details) o << "       " << d << "\n";
    }
    return o.str();
}

std::string stress_rows_to_json(const std::vector<StressRow>& rows) {
    std::string out = "[\n";
    for (std::size_t i = 0; i < rows.size(); ++i) out += "  " + rows[i].to_json() + (i + 1 < rows.size() ? ",\n" : "\n");
    return out + "]\n";
}

}  // namespace mipraster
