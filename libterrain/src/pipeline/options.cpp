// The pipeline's options read from text, and written back (terrain/pipeline/options.hpp).
#include "terrain/pipeline/options.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <utility>

#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"

namespace terrain::pipeline {

const char* to_string(Absorbed absorbed) {
    return name_of(kAbsorbedNames, absorbed);
}

MinArea MinArea::area(double m2, std::string text) {
    return {Kind::area, m2, std::move(text)};
}

std::string to_string(const MinArea& min_area) {
    switch (min_area.kind) {
        case MinArea::Kind::automatic:
            return "auto";
        case MinArea::Kind::area:
            return min_area.text.empty() ? JsonWriter::number(min_area.m2) : min_area.text;
        default:
            return {};
    }
}

std::optional<segment::GrowCost> parse_cost(const std::string& name) {
    if (name == "auto") return std::nullopt;
    return segment::parse_grow_cost(name);
}

std::optional<Absorbed> parse_absorbed(const std::string& name) {
    if (name == "auto") return std::nullopt;
    if (const auto absorbed = value_named(kAbsorbedNames, name)) return *absorbed;
    throw Error("segment", "--absorbed is divide, whole or auto; '" + name + "' is none of them");
}

std::optional<MeshFrame> parse_frame(const std::string& name) {
    if (name == "auto") return std::nullopt;
    if (const auto frame = value_named(kFrameNames, name)) return *frame;
    throw Error("mesh", "the frame must be body, map or auto, not '" + name + "'");
}

field::ShapeIndexWindow parse_window(const std::string& name, const std::string& option) {
    if (const auto window = value_named(field::kShapeIndexWindowNames, name)) return *window;
    throw Error("options", option + " must be disk or ball, not '" + name + "'");
}

double parse_area(const std::string& text, const std::string& option) {
    std::size_t used = 0;
    double value = 0;
    try {
        value = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    std::string unit = used > 0 ? text.substr(used) : std::string();
    unit.erase(0, unit.find_first_not_of(' '));
    std::transform(unit.begin(), unit.end(), unit.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    double scale = 0;
    if (unit.empty() || unit == "m2" || unit == "m^2")
        scale = 1;
    else if (unit == "km2" || unit == "km^2")
        scale = 1e6;
    else if (unit == "ha")
        scale = 1e4;
    const double m2 = value * scale;
    if (used == 0 || scale == 0 || !std::isfinite(m2) || m2 <= 0)
        throw Error("segment", option +
                                   " takes an area above 0 in m^2 or with a unit (5km2, "
                                   "2000m2, 3ha); '" +
                                   text + "' is not one");
    return m2;
}

MinArea parse_min_area(const std::string& text, const std::string& option) {
    if (text.empty()) return {};
    if (text == "auto") return MinArea::automatic();
    return MinArea::area(parse_area(text, option), text);
}

std::vector<double> parse_area_ratios(const std::string& text) {
    std::vector<double> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        std::size_t used = 0;
        double v = 0;
        try {
            v = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != item.size() || !std::isfinite(v) || v <= 0 || v > 100)
            throw Error("sweep",
                        "--area-ratios takes percentages in (0, 100] separated by commas; '" +
                            item + "' is not one");
        out.push_back(v);
    }
    if (out.empty()) throw Error("sweep", "--area-ratios needs at least one value");
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::vector<AreaThreshold> parse_min_areas(const std::string& text) {
    std::vector<AreaThreshold> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        try {
            out.push_back({item, parse_area(item, "--min-areas")});
        } catch (const Error& e) {
            // The same message, from the sweep's stage.
            throw Error("sweep", std::string(e.what()).substr(e.stage().size() + 2));
        }
    }
    if (out.empty()) throw Error("sweep", "--min-areas needs at least one value");
    std::stable_sort(out.begin(), out.end(),
                     [](const AreaThreshold& a, const AreaThreshold& b) { return a.m2 < b.m2; });
    out.erase(
        std::unique(out.begin(), out.end(),
                    [](const AreaThreshold& a, const AreaThreshold& b) { return a.m2 == b.m2; }),
        out.end());
    return out;
}

}  // namespace terrain::pipeline
