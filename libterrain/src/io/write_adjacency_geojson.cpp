
#include "dataset_files.hpp"
#include "geojson_file.hpp"
#include "lonlat_frame.hpp"
#include "region_attributes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/geo/iau_crs.hpp"
#include "terrain/io/write_adjacency.hpp"

namespace terrain::io {
void write_adjacency_geojson(const segment::RegionGraph& graph, const std::string& path,
                             bool overwrite) {
    write_file_atomically(path, overwrite, [&](std::ostream& out) {
        const bool mesh = graph.point_frame == segment::PointFrame::mesh;
        const bool lonlat = graph.point_frame == segment::PointFrame::lonlat;
        // Earth in RFC 7946 lon/lat; other bodies name their geographic CRS, as regions.geojson.
        // A DEM without CRS: its local grid, named, so that no reader takes it for WGS 84.
        const std::string crs =
            lonlat ? geojson_crs_name(geo::output_crs_wkt(graph.point_crs_wkt))
                   : (graph.point_frame == segment::PointFrame::map ? local_grid_crs_wkt() : "");
        GeoJsonFile file(out, "adjacency", crs, lonlat ? 9 : 6);
        auto position = [&](JsonWriter& json, const segment::Region& r) {
            if (mesh)
                file.position(json, r.point[0], r.point[1], r.point[2]);
            else
                file.position(json, r.point[0], r.point[1]);
        };
        std::int64_t id = 0;
        for (const auto& region : graph.regions) {
            auto properties = region_attributes(graph, region);
            properties.insert(properties.begin(), {"kind", std::string("region")});
            file.feature(++id, properties, [&](JsonWriter& json) {
                json.begin_object().field("type", "Point").key("coordinates");
                position(json, region);
                json.end_object();
            });
        }
        for (const auto& edge : graph.edges) {
            auto properties = edge_attributes(edge);
            properties.insert(properties.begin(), {"kind", std::string("edge")});
            file.feature(++id, properties, [&](JsonWriter& json) {
                json.begin_object().field("type", "LineString").key("coordinates").begin_array();
                position(json, graph.regions[edge.a - 1]);
                position(json, graph.regions[edge.b - 1]);
                json.end_array().end_object();
            });
        }
        file.finish();
    });
}

}  // namespace terrain::io
