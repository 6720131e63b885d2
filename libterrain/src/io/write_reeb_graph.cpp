#include "terrain/io/write_reeb_graph.hpp"

#include <fstream>

#include "terrain/core/error.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/reeb/simplify.hpp"

namespace terrain::io {

using reeb::NodeKind;
using reeb::ReebGraph;

namespace {

// Critical node n -> its id in the files (0..), -1 for regular nodes.
std::vector<std::int32_t> critical_ids(const ReebGraph& g) {
    std::vector<std::int32_t> id(g.node_count(), -1);
    std::int32_t next = 0;
    for (std::size_t n = 0; n < g.node_count(); ++n)
        if (g.is_critical(static_cast<std::int32_t>(n))) id[n] = next++;
    return id;
}

std::size_t node_size(const ReebGraph& g, std::size_t n) {
    return static_cast<std::size_t>(g.node_vertex_offsets[n + 1] - g.node_vertex_offsets[n]);
}

template <class Write>
void write_atomically(const std::string& path, bool overwrite, Write&& write) {
    AtomicOutput out(path, overwrite);
    {
        std::ofstream file(out.temp_path(), std::ios::binary);
        if (!file) throw Error("write", "cannot write " + path);
        write(file);
        file.flush();
        if (!file) throw Error("write", "writing " + path + " failed (disk full?)");
    }
    out.commit();
}

}  // namespace

void write_reeb_json(const ReebGraph& g, const TriangleMesh& mesh, const std::string& path,
                     bool overwrite, const JsonParameters& parameters) {
    const auto ids = critical_ids(g);
    const auto inc = reeb::node_arcs(g);
    const auto metrics = reeb::arc_metrics(mesh, g);
    const auto topo = mesh_topology(mesh);
    const auto summary = reeb::summarize(g);
    write_atomically(path, overwrite, [&](std::ostream& os) {
        JsonWriter j(os);
        j.begin_object();
        j.key("nodes").begin_array();
        for (std::size_t n = 0; n < g.node_count(); ++n) {
            if (ids[n] < 0) continue;
            const auto nn = static_cast<std::int32_t>(n);
            j.begin_object()
                .field("id", ids[n])
                .field("type", to_string(g.node_kinds[n]))
                .field("class",
                       to_string(reeb::classify_link(g.node_lower_links[n], g.node_upper_links[n])))
                .field("value", static_cast<double>(g.node_values[n]))
                .field("vertex_count", node_size(g, n))
                .field("lower_links", int{g.node_lower_links[n]})
                .field("upper_links", int{g.node_upper_links[n]})
                .field("degree", inc.degree(nn))
                .field("vertex",
                       g.node_vertices[static_cast<std::size_t>(g.node_vertex_offsets[n])])
                .end_object();
        }
        j.end_array();
        j.key("arcs").begin_array();
        for (std::size_t a = 0; a < g.arc_count(); ++a) {
            j.begin_object()
                .field("id", a)
                .field("from", ids[static_cast<std::size_t>(g.arcs[a][0])])
                .field("to", ids[static_cast<std::size_t>(g.arcs[a][1])])
                .field("regular_node_count",
                       static_cast<std::size_t>(g.arc_offsets[a + 1] - g.arc_offsets[a]));
            std::size_t regular_vertices = 0;
            for (auto i = g.arc_offsets[a]; i < g.arc_offsets[a + 1]; ++i)
                regular_vertices += node_size(
                    g, static_cast<std::size_t>(g.arc_nodes[static_cast<std::size_t>(i)]));
            j.field("regular_vertex_count", regular_vertices)
                .field("persistence", static_cast<double>(metrics.persistence[a]))
                .field("area_ratio", 100.0 * metrics.area_ratio[a])
                .end_object();
        }
        j.end_array();
        j.key("mesh")
            .begin_object()
            .field("vertices", topo.vertices)
            .field("faces", topo.faces)
            .field("boundary_edges", topo.boundary_edges)
            .field("boundary_loops", topo.boundary_loops)
            .field("components", topo.components)
            .field("euler_characteristic", topo.euler_characteristic)
            .end_object();
        j.key("summary")
            .begin_object()
            .field("nodes", summary.nodes)
            .field("critical_nodes", summary.critical)
            .field("minima", summary.minima)
            .field("maxima", summary.maxima)
            .field("saddles", summary.saddles)
            .field("arcs", summary.arcs)
            .field("components", summary.components)
            .field("loops", summary.loops)
            .end_object();
        j.key("parameters").begin_object();
        for (const auto& [k, v] : parameters) j.key(k).raw(v);
        j.end_object();
        j.end_object();
    });
}

void write_reeb_dot(const ReebGraph& g, const std::string& path, bool overwrite) {
    const auto ids = critical_ids(g);
    write_atomically(path, overwrite, [&](std::ostream& os) {
        os << "graph reeb {\n  node [style=filled, fontname=\"Helvetica\"];\n";
        for (std::size_t n = 0; n < g.node_count(); ++n) {
            if (ids[n] < 0) continue;
            const NodeKind k = g.node_kinds[n];
            const char* colour = k == NodeKind::minimum   ? "lightblue"
                                 : k == NodeKind::maximum ? "salmon"
                                                          : "palegreen";
            os << "  n" << ids[n] << " [label=\"" << to_string(k) << " "
               << JsonWriter::number(g.node_values[n]) << "\", fillcolor=" << colour << "];\n";
        }
        for (std::size_t a = 0; a < g.arc_count(); ++a)
            os << "  n" << ids[static_cast<std::size_t>(g.arcs[a][0])] << " -- n"
               << ids[static_cast<std::size_t>(g.arcs[a][1])] << " [label=\""
               << (g.arc_offsets[a + 1] - g.arc_offsets[a]) << "\"];\n";
        os << "}\n";
    });
}

}  // namespace terrain::io
