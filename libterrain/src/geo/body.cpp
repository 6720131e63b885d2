#include "terrain/geo/body.hpp"

#include <ogr_spatialref.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <string_view>

#include "terrain/core/error.hpp"

namespace terrain::geo {
namespace {

struct KnownBody {
    std::string_view name;
    double mean_radius;                        // metres, used only when no name matches
    std::array<std::string_view, 4> keywords;  // upper case, matched inside datum/CRS names
};

// Solar-system bodies that planetary DEMs are made of. Radii are the IAU mean or reference
// radii; they only break ties when a CRS carries no recognisable name.
constexpr std::array<KnownBody, 14> kBodies{{
    {"Moon", 1737400, {"MOON", "LUNAR", "", ""}},
    {"Mars", 3389500, {"MARS", "", "", ""}},
    {"Mercury", 2439400, {"MERCURY", "", "", ""}},
    {"Venus", 6051800, {"VENUS", "", "", ""}},
    {"Vesta", 255000, {"VESTA", "", "", ""}},
    {"Ceres", 470000, {"CERES", "", "", ""}},
    {"Phobos", 11080, {"PHOBOS", "", "", ""}},
    {"Deimos", 6200, {"DEIMOS", "", "", ""}},
    {"Io", 1821490, {"_IO_", " IO ", "", ""}},
    {"Europa", 1560800, {"EUROPA", "", "", ""}},
    {"Ganymede", 2631200, {"GANYMEDE", "", "", ""}},
    {"Callisto", 2410300, {"CALLISTO", "", "", ""}},
    {"Titan", 2575000, {"TITAN", "", "", ""}},
    // Last, so that "MEAN EARTH/POLAR AXIS" style names of other bodies match them first.
    {"Earth", 6371008.8, {"WGS", "EARTH", "NAD", "GRS"}},
}};

std::string upper(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    return s;
}

}  // namespace

std::string identify_body_name(const std::string& names, double semi_major_axis) {
    const std::string text = " " + upper(names) + " ";
    for (const auto& body : kBodies)
        for (auto keyword : body.keywords)
            if (!keyword.empty() && text.find(keyword) != std::string::npos)
                return std::string(body.name);
    // Earth ellipsoids carry many names (Clarke, Bessel, Krassowsky, ...): their size alone
    // is unambiguous.
    if (semi_major_axis > 6.35e6 && semi_major_axis < 6.40e6) return "Earth";
    for (const auto& body : kBodies)
        if (std::abs(semi_major_axis - body.mean_radius) < 0.005 * body.mean_radius)
            return std::string(body.name);
    return "unknown";
}

double known_body_radius(const std::string& name) {
    for (const auto& body : kBodies)
        if (body.name == name) return body.mean_radius;
    return 0;
}

Body body_from_crs(const std::string& crs_definition) {
    Body body;
    if (crs_definition.empty()) {
        body.name = "none";
        return body;
    }
    OGRSpatialReference srs;
    if (srs.SetFromUserInput(crs_definition.c_str()) != OGRERR_NONE)
        throw Error("crs", "cannot read the CRS definition '" + crs_definition.substr(0, 60) +
                               "'; give WKT, PROJ or an AUTHORITY:CODE");
    OGRErr err = OGRERR_NONE;
    body.semi_major_axis = srs.GetSemiMajor(&err);
    const double inverse_flattening = srs.GetInvFlattening(&err);
    body.flattening = inverse_flattening > 0 ? 1.0 / inverse_flattening : 0.0;
    body.has_crs = true;
    std::string names;
    for (const char* key : {"GEOGCS", "GEOGCRS", "BASEGEOGCRS", "DATUM", "SPHEROID", "ELLIPSOID"})
        if (const char* value = srs.GetAttrValue(key)) names += std::string(value) + " ";
    if (const char* name = srs.GetName()) names += name;
    body.name = identify_body_name(names, body.semi_major_axis);
    return body;
}

}  // namespace terrain::geo
