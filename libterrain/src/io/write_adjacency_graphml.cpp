#include <variant>

#include "dataset_files.hpp"
#include "region_attributes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/io/write_adjacency.hpp"

namespace terrain::io {
namespace {

std::string xml_escape(const std::string& text) {
    std::string s;
    for (char c : text) {
        switch (c) {
            case '&':
                s += "&amp;";
                break;
            case '<':
                s += "&lt;";
                break;
            case '>':
                s += "&gt;";
                break;
            case '"':
                s += "&quot;";
                break;
            default:
                s += c;
        }
    }
    return s;
}

const char* graphml_type(const AttributeValue& value) {
    if (std::holds_alternative<std::int64_t>(value)) return "long";
    return std::holds_alternative<double>(value) ? "double" : "string";
}

std::string text(const AttributeValue& value) {
    if (const auto* n = std::get_if<std::int64_t>(&value)) return std::to_string(*n);
    if (const auto* d = std::get_if<double>(&value)) return JsonWriter::number(*d);
    return xml_escape(std::get<std::string>(value));
}

// <key> declarations: ids "n_<name>" / "e_<name>" (the edge's source and target are the
// GraphML edge's own attributes, not data).
void write_keys(std::ostream& out, const std::vector<Attribute>& attributes, const char* kind) {
    for (const auto& [name, value] : attributes) {
        if (kind[0] == 'e' && (name == "source" || name == "target")) continue;
        out << "  <key id=\"" << kind[0] << "_" << name << "\" for=\"" << kind << "\" attr.name=\""
            << name << "\" attr.type=\"" << graphml_type(value) << "\"/>\n";
    }
}

void write_data(std::ostream& out, const std::vector<Attribute>& attributes, char kind) {
    for (const auto& [name, value] : attributes) {
        if (kind == 'e' && (name == "source" || name == "target")) continue;
        out << "      <data key=\"" << kind << "_" << name << "\">" << text(value) << "</data>\n";
    }
}

}  // namespace

void write_adjacency_graphml(const segment::RegionGraph& graph, const std::string& path,
                             bool overwrite) {
    write_file_atomically(path, overwrite, [&](std::ostream& out) {
        out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<graphml xmlns=\"http://graphml.graphdrawing.org/xmlns\"\n"
               "    xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"\n"
               "    xsi:schemaLocation=\"http://graphml.graphdrawing.org/xmlns "
               "http://graphml.graphdrawing.org/xmlns/1.0/graphml.xsd\">\n";
        out << "  <key id=\"g_point_frame\" for=\"graph\" attr.name=\"point_frame\" "
               "attr.type=\"string\"/>\n"
               "  <key id=\"g_point_crs\" for=\"graph\" attr.name=\"point_crs\" "
               "attr.type=\"string\"/>\n";
        if (!graph.regions.empty())
            write_keys(out, region_attributes(graph, graph.regions.front()), "node");
        write_keys(out, edge_attributes(segment::RegionEdge{}), "edge");
        out << "  <graph id=\"regions\" edgedefault=\"undirected\">\n"
            << "    <data key=\"g_point_frame\">" << to_string(graph.point_frame) << "</data>\n"
            << "    <data key=\"g_point_crs\">" << xml_escape(graph.point_crs_wkt) << "</data>\n";
        for (const auto& region : graph.regions) {
            out << "    <node id=\"" << region.id << "\">\n";
            write_data(out, region_attributes(graph, region), 'n');
            out << "    </node>\n";
        }
        for (const auto& edge : graph.edges) {
            out << "    <edge source=\"" << edge.a << "\" target=\"" << edge.b << "\">\n";
            write_data(out, edge_attributes(edge), 'e');
            out << "    </edge>\n";
        }
        out << "  </graph>\n</graphml>\n";
    });
}

}  // namespace terrain::io
