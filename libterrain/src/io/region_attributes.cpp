#include "region_attributes.hpp"

#include <cmath>
#include <cstdio>

#include "terrain/io/region_colour.hpp"
#include "terrain/io/write_preview.hpp"

namespace terrain::io {
namespace {

std::int64_t as_int(std::size_t n) {
    return static_cast<std::int64_t>(n);
}

}  // namespace

std::array<std::uint8_t, 4> region_colour(std::uint32_t id) {
    if (id == 0) return {0, 0, 0, 0};
    // Hue steps by the golden ratio (consecutive ids far apart on the colour wheel);
    // saturation and value cycle so that ids with close hues still differ.
    const double hue = std::fmod(0.13 + id * 0.6180339887498949, 1.0) * 6.0;
    const double saturation = id % 3 == 0 ? 0.45 : (id % 3 == 1 ? 0.7 : 0.9);
    const double value = (id / 3) % 2 == 0 ? 0.95 : 0.78;
    const int sector = static_cast<int>(hue);
    const double f = hue - sector;
    const double p = value * (1 - saturation), q = value * (1 - saturation * f),
                 t = value * (1 - saturation * (1 - f));
    double rgb[3];
    switch (sector % 6) {
        case 0:
            rgb[0] = value, rgb[1] = t, rgb[2] = p;
            break;
        case 1:
            rgb[0] = q, rgb[1] = value, rgb[2] = p;
            break;
        case 2:
            rgb[0] = p, rgb[1] = value, rgb[2] = t;
            break;
        case 3:
            rgb[0] = p, rgb[1] = q, rgb[2] = value;
            break;
        case 4:
            rgb[0] = t, rgb[1] = p, rgb[2] = value;
            break;
        default:
            rgb[0] = value, rgb[1] = p, rgb[2] = q;
    }
    std::array<std::uint8_t, 4> out{0, 0, 0, 255};
    for (int k = 0; k < 3; ++k)
        out[std::size_t(k)] = static_cast<std::uint8_t>(std::lround(rgb[k] * 255));
    return out;
}

std::array<std::uint8_t, 3> landform_colour(segment::Landform landform) {
    if (landform == segment::Landform::unknown) return {160, 160, 160};
    return preview_field_colour(segment::landform_centre(landform));
}

const char* to_string(segment::PointFrame frame) {
    switch (frame) {
        case segment::PointFrame::lonlat:
            return "lonlat";
        case segment::PointFrame::map:
            return "map";
        default:
            return "mesh";
    }
}

std::vector<Attribute> region_attributes(const segment::RegionGraph& graph,
                                         const segment::Region& r) {
    std::vector<Attribute> a;
    a.push_back({"id", std::int64_t{r.id}});
    a.push_back({"vertex_count", as_int(r.vertex_count)});
    if (graph.point_frame != segment::PointFrame::mesh)
        a.push_back({"pixel_count", as_int(r.pixel_count)});
    a.push_back({"area_m2", r.area_m2});
    a.push_back({"surface_area_m2", r.surface_area_m2});
    a.push_back({"field_mean", r.field_mean});
    a.push_back({"field_min", r.field_min});
    a.push_back({"field_max", r.field_max});
    a.push_back({"landform", std::string(segment::to_string(r.landform))});
    a.push_back({"neighbor_count", as_int(r.neighbor_count)});
    if (graph.has_field_scale) a.push_back({"field_scale_m", r.field_scale_m});
    if (graph.has_area_range) {
        a.push_back({"min_area_from_m2", r.min_area_from_m2});
        a.push_back({"min_area_to_m2", r.min_area_to_m2});
    }
    a.push_back({"representative_vertex", std::int64_t{r.representative_vertex}});
    const bool lonlat = graph.point_frame == segment::PointFrame::lonlat;
    const bool mesh = graph.point_frame == segment::PointFrame::mesh;
    a.push_back({lonlat ? "lon" : "x", r.point[0]});
    a.push_back({lonlat ? "lat" : "y", r.point[1]});
    a.push_back({mesh ? "z" : "height_m", r.point[2]});
    const auto c = region_colour(r.id);
    char hex[8];
    std::snprintf(hex, sizeof hex, "#%02x%02x%02x", c[0], c[1], c[2]);
    a.push_back({"fill", std::string(hex)});
    return a;
}

std::vector<Attribute> edge_attributes(const segment::RegionEdge& e) {
    return {{"source", std::int64_t{e.a}},
            {"target", std::int64_t{e.b}},
            {"boundary_length_m", e.boundary_length_m},
            {"contrast", e.contrast},
            {"mesh_edges", as_int(e.mesh_edges)}};
}

void write_attributes(JsonWriter& json, const std::vector<Attribute>& attributes) {
    for (const auto& [name, value] : attributes) {
        json.key(name);
        std::visit([&](const auto& v) { json.value(v); }, value);
    }
}

}  // namespace terrain::io
