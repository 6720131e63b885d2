#include <cpl_json.h>
#include <catch2/catch.hpp>

#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "support/test_meshes.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/write_reeb_graph.hpp"
#include "terrain/reeb/reeb_graph.hpp"

using namespace terrain;

namespace {

// A torus standing on its rim, height as the field: minimum, two saddles, maximum, one loop.
struct Torus {
    TriangleMesh mesh = test::torus_mesh(3, 1, 48, 24, true);
    std::vector<float> field;
    reeb::ReebGraph graph;
    Torus() {
        field.resize(mesh.vertex_count());
        for (std::size_t v = 0; v < field.size(); ++v) {
            const auto p = mesh.position(v);
            field[v] = static_cast<float>(1e-3 * p[0] + 2e-4 * p[1] + p[2]);
        }
        graph = reeb::build_reeb_graph(mesh, field);
    }
};

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto i = text.find(what); i != std::string::npos; i = text.find(what, i + 1)) ++n;
    return n;
}

}  // namespace

TEST_CASE("the Reeb graph JSON reads back with its nodes, arcs, mesh and summary",
          "[write_reeb_graph]") {
    const Torus t;
    const auto dir = test::scratch_dir("write_reeb_json");
    const auto path = (dir / "reeb.json").string();
    io::write_reeb_json(t.graph, t.mesh, path, false, {{"persistence", "10"}, {"tag", "\"x\""}});

    CPLJSONDocument doc;
    REQUIRE(doc.Load(path));
    const auto root = doc.GetRoot();
    const auto nodes = root.GetArray("nodes");
    const auto arcs = root.GetArray("arcs");
    REQUIRE(nodes.Size() == 4);
    REQUIRE(arcs.Size() == 4);

    std::map<std::string, int> types;
    std::map<int, double> value;
    std::map<int, int> degree;
    int node_vertices = 0;
    for (int i = 0; i < nodes.Size(); ++i) {
        const auto n = nodes[i];
        CHECK(n.GetInteger("id") == i);  // critical nodes numbered 0.. in order
        ++types[n.GetString("type")];
        value[i] = n.GetDouble("value");
        degree[i] = n.GetInteger("degree");
        node_vertices += n.GetInteger("vertex_count");
        const int vertex = n.GetInteger("vertex");
        REQUIRE(vertex >= 0);
        REQUIRE(vertex < static_cast<int>(t.mesh.vertex_count()));
        CHECK(n.GetDouble("value") == Approx(t.field[static_cast<std::size_t>(vertex)]));
    }
    CHECK(types == std::map<std::string, int>{{"max", 1}, {"min", 1}, {"saddle", 2}});

    std::map<int, int> ends;
    int regular = 0;
    for (int a = 0; a < arcs.Size(); ++a) {
        const auto arc = arcs[a];
        CHECK(arc.GetInteger("id") == a);
        const int from = arc.GetInteger("from"), to = arc.GetInteger("to");
        REQUIRE(value.count(from) == 1);
        REQUIRE(value.count(to) == 1);
        CHECK(value[from] < value[to]);  // from the lower node to the upper
        CHECK(arc.GetDouble("persistence") == Approx(value[to] - value[from]).epsilon(1e-6));
        CHECK(arc.GetDouble("area_ratio") > 0);
        CHECK(arc.GetDouble("area_ratio") <= 100);
        ++ends[from];
        ++ends[to];
        regular += arc.GetInteger("regular_vertex_count");
    }
    CHECK(ends == degree);  // each node's degree counts the arcs that end on it
    // Every vertex is in one critical node or on one arc.
    CHECK(node_vertices + regular == static_cast<int>(t.mesh.vertex_count()));

    const auto mesh = root.GetObj("mesh");
    CHECK(mesh.GetInteger("vertices") == static_cast<int>(t.mesh.vertex_count()));
    CHECK(mesh.GetInteger("faces") == static_cast<int>(t.mesh.triangle_count()));
    CHECK(mesh.GetInteger("boundary_edges") == 0);
    CHECK(mesh.GetInteger("euler_characteristic") == 0);  // a torus
    const auto summary = root.GetObj("summary");
    CHECK(summary.GetInteger("critical_nodes") == 4);
    CHECK(summary.GetInteger("arcs") == 4);
    CHECK(summary.GetInteger("loops") == 1);
    const auto parameters = root.GetObj("parameters");
    CHECK(parameters.GetInteger("persistence") == 10);
    CHECK(parameters.GetString("tag") == "x");

    // Atomic and careful: an existing file is kept unless overwrite.
    const auto before = test::file_bytes(path);
    CHECK_THROWS_AS(io::write_reeb_json(t.graph, t.mesh, path, false), Error);
    CHECK(test::file_bytes(path) == before);
    io::write_reeb_json(t.graph, t.mesh, path, true, {{"persistence", "10"}, {"tag", "\"x\""}});
    CHECK(test::file_bytes(path) == before);  // the same bytes for the same graph
}

TEST_CASE("the Reeb graph DOT: one coloured node per critical node, one edge per arc",
          "[write_reeb_graph]") {
    const Torus t;
    const auto dir = test::scratch_dir("write_reeb_dot");
    const auto path = (dir / "reeb.dot").string();
    io::write_reeb_dot(t.graph, path, false);
    const auto text = test::file_bytes(path);
    CHECK(text.rfind("graph reeb {\n", 0) == 0);
    CHECK(text.substr(text.size() - 2) == "}\n");
    CHECK(count(text, "fillcolor=lightblue") == 1);  // minimum
    CHECK(count(text, "fillcolor=salmon") == 1);     // maximum
    CHECK(count(text, "fillcolor=palegreen") == 2);  // saddles

    // Edges join declared nodes; each node's edge count is its degree (1, 3, 3, 1).
    const std::regex edge(R"re(  n(\d+) -- n(\d+) \[label="(\d+)"\];)re");
    std::set<std::string> declared;
    for (int n = 0; n < 4; ++n) {
        CHECK(count(text, "  n" + std::to_string(n) + " [label=") == 1);
        declared.insert(std::to_string(n));
    }
    std::map<std::string, int> degree;
    int edges = 0;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
        std::smatch m;
        if (!std::regex_match(line, m, edge)) continue;
        ++edges;
        CHECK(declared.count(m[1]) == 1);
        CHECK(declared.count(m[2]) == 1);
        ++degree[m[1]];
        ++degree[m[2]];
    }
    CHECK(edges == 4);
    std::multiset<int> degrees;
    for (const auto& [node, d] : degree) degrees.insert(d);
    CHECK(degrees == std::multiset<int>{1, 1, 3, 3});

    CHECK_THROWS_AS(io::write_reeb_dot(t.graph, path, false), Error);
    io::write_reeb_dot(t.graph, path, true);
    CHECK(test::file_bytes(path) == text);
}
