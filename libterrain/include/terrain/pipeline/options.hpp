#pragma once
// The values of the pipeline's options (SegmentOptions, InputOptions) and the text they are
// given as at the edges: the command line (tools/) and the Python module (python/) read each
// option's text once, with the one parser here or beside its enumeration
// (field::parse_field_kind, segment::parse_grow_cost), and the library's stages see values
// only. Each parser throws terrain::Error with the line the command line prints; each value
// has its name back (to_string), which run.json and the preview write.

#include <optional>
#include <string>
#include <vector>

#include "terrain/core/names.hpp"
#include "terrain/field/field_kind.hpp"
#include "terrain/field/shape_index.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/segment/grow_regions.hpp"

namespace terrain::pipeline {

// What the growing does with the vertices the simplification absorbed into surviving nodes
// (SegmentOptions::absorbed).
enum class Absorbed { divide, whole };

inline constexpr Named<Absorbed> kAbsorbedNames[] = {
    {"divide", Absorbed::divide},
    {"whole", Absorbed::whole},
};
const char* to_string(Absorbed absorbed);

// The frames a DEM may be meshed in by choice (InputOptions::frame); mesh files take `file`.
inline constexpr Named<MeshFrame> kFrameNames[] = {
    {"body", MeshFrame::body},
    {"map", MeshFrame::map},
};

// An area threshold on the body (SegmentOptions::min_area): none, auto (kAutoMinAreaPixels
// of the mesh's mean vertex area: the DEM's pixel, whatever the extent) or an area in m^2.
struct MinArea {
    enum class Kind { none, automatic, area };
    Kind kind = Kind::none;
    double m2 = 0;     // Kind::area: the threshold
    std::string text;  // Kind::area: as given ("5km2"), as run.json and the preview write it

    static MinArea automatic() { return {Kind::automatic, 0, {}}; }
    // `text`: the area as the user wrote it; empty: the number of m^2.
    static MinArea area(double m2, std::string text = {});
    bool is_set() const { return kind != Kind::none; }
    bool is_auto() const { return kind == Kind::automatic; }
};
// "" (none), "auto", or the area as given.
std::string to_string(const MinArea& min_area);

// "auto" for an option left to the input (unset), otherwise the name of its value.
template <class T>
std::string name_or_auto(const std::optional<T>& value) {
    return value ? std::string(to_string(*value)) : std::string("auto");
}

// The parsers. "auto" leaves an option unset: the job chooses by the input (a DEM or a mesh
// file).
// "graph", "standard" or "auto"; throws (stage "segment") otherwise.
std::optional<segment::GrowCost> parse_cost(const std::string& name);
// "divide", "whole" or "auto"; throws (stage "segment") otherwise.
std::optional<Absorbed> parse_absorbed(const std::string& name);
// "body", "map" or "auto"; throws (stage "mesh") otherwise.
std::optional<MeshFrame> parse_frame(const std::string& name);
// "disk" or "ball"; throws (stage "options") naming `option` as the caller spells it.
field::ShapeIndexWindow parse_window(const std::string& name,
                                     const std::string& option = "--window");
// An area with an optional unit, in m^2: "5km2" (or km^2), "2000m2" (or m^2), "3ha", or a
// plain number of m^2; above 0. Throws terrain::Error (stage "segment") naming `option`
// otherwise.
double parse_area(const std::string& text, const std::string& option = "--min-area");
// "" (none), "auto", or an area parse_area reads, kept as written.
MinArea parse_min_area(const std::string& text, const std::string& option = "--min-area");

// The sweep's scales (pipeline::sweep). "0.1,0.25,0.5" into sorted unique percentages in
// (0, 100]; throws terrain::Error (stage "sweep") otherwise.
std::vector<double> parse_area_ratios(const std::string& text);
// An area threshold as given ("5km2") and in m^2.
struct AreaThreshold {
    std::string text;
    double m2 = 0;
};
// "1km2,5km2,20km2" into thresholds sorted by area, equal areas once; throws terrain::Error
// (stage "sweep") for an empty list or a value parse_area refuses.
std::vector<AreaThreshold> parse_min_areas(const std::string& text);

}  // namespace terrain::pipeline
