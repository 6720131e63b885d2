#pragma once
// Private: the properties of regions and edges as every output file names them (one list,
// so labels.tif's attribute table, the polygons and the graphs agree). Not installed.

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "terrain/core/json_writer.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

using AttributeValue = std::variant<std::int64_t, double, std::string>;

struct Attribute {
    std::string name;
    AttributeValue value;
};

// id, vertex_count, pixel_count (DEM only), area_m2, surface_area_m2, field_mean, field_min,
// field_max, landform, neighbor_count, representative_vertex, the point (lon, lat, height_m;
// x, y, height_m; or x, y, z) and fill ("#rrggbb", the region colour).
std::vector<Attribute> region_attributes(const segment::RegionGraph& graph,
                                         const segment::Region& region);
// source, target, boundary_length_m, contrast, mesh_edges.
std::vector<Attribute> edge_attributes(const segment::RegionEdge& edge);

// Writes each attribute as a key and value of the open JSON object.
void write_attributes(JsonWriter& json, const std::vector<Attribute>& attributes);

// "lonlat", "map" or "mesh".
const char* to_string(segment::PointFrame frame);

}  // namespace terrain::io
