
#include "dataset_files.hpp"
#include "region_attributes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/io/write_adjacency.hpp"

namespace terrain::io {

void write_adjacency_json(const segment::RegionGraph& graph, const std::string& path,
                          bool overwrite) {
    write_file_atomically(path, overwrite, [&](std::ostream& out) {
        // networkx's node-link layout; one node or edge per line.
        out << "{\n\"directed\": false,\n\"multigraph\": false,\n\"graph\": ";
        JsonWriter(out, false)
            .begin_object()
            .field("name", "region adjacency")
            .field("point_frame", to_string(graph.point_frame))
            .field("point_crs", graph.point_crs_wkt)
            .field("region_count", graph.regions.size())
            .field("edge_count", graph.edges.size())
            .end_object();
        const char* separator = "\n";
        out << ",\n\"nodes\": [";
        for (const auto& region : graph.regions) {
            out << separator;
            separator = ",\n";
            JsonWriter json(out, false);
            json.begin_object();
            write_attributes(json, region_attributes(graph, region));
            json.end_object();
        }
        out << "\n],\n\"edges\": [";
        separator = "\n";
        for (const auto& edge : graph.edges) {
            out << separator;
            separator = ",\n";
            JsonWriter json(out, false);
            json.begin_object();
            write_attributes(json, edge_attributes(edge));
            json.end_object();
        }
        out << "\n]\n}\n";
    });
}

}  // namespace terrain::io
