#include <cpl_json.h>
#include <cpl_minixml.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>
#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_adjacency.hpp"

using namespace terrain;

namespace {

test::SegmentedTile vesta_tile() {
    const Dem vesta = test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 64, 96, 48, 40);
    return test::segment_tile(vesta, test::voronoi_cells(vesta, 4, 4));
}

using Pair = std::pair<std::int64_t, std::int64_t>;

// An XML attribute by name (CPLGetXMLValue reads "attr.name" as a path).
std::string attribute(const CPLXMLNode* node, const char* name) {
    for (const CPLXMLNode* a = node->psChild; a; a = a->psNext)
        if (a->eType == CXT_Attribute && std::string(a->pszValue) == name && a->psChild)
            return a->psChild->pszValue;
    return "";
}

}  // namespace

TEST_CASE("adjacency.json agrees with the label raster and the mesh", "[write_adjacency]") {
    const auto t = vesta_tile();
    const auto dir = test::scratch_dir("write_adjacency_json");
    const auto path = (dir / "adjacency.json").string();
    io::write_adjacency_json(t.graph, path, false);

    CPLJSONDocument doc;
    REQUIRE(doc.Load(path));
    const auto root = doc.GetRoot();
    CHECK_FALSE(root.GetBool("directed", true));
    CHECK(root.GetObj("graph").GetString("point_frame") == "lonlat");
    const auto nodes = root.GetArray("nodes");
    const auto edges = root.GetArray("edges");
    REQUIRE(nodes.Size() == int(t.region_count));
    REQUIRE(edges.Size() == int(t.graph.edges.size()));
    for (int i = 0; i < nodes.Size(); ++i) {
        const auto& r = t.graph.regions[std::size_t(i)];
        CHECK(nodes[i].GetLong("id") == r.id);
        CHECK(nodes[i].GetDouble("area_m2") == r.area_m2);  // shortest round-trip text
        CHECK(nodes[i].GetDouble("field_mean") == r.field_mean);
        CHECK(nodes[i].GetString("landform") == segment::to_string(r.landform));
        CHECK(nodes[i].GetDouble("lon") == r.point[0]);
        CHECK(nodes[i].GetLong("neighbor_count") == GIntBig(r.neighbor_count));
    }
    std::set<Pair> graph_edges;
    for (int i = 0; i < edges.Size(); ++i) {
        const auto& e = t.graph.edges[std::size_t(i)];
        CHECK(edges[i].GetLong("source") == e.a);
        CHECK(edges[i].GetLong("target") == e.b);
        CHECK(edges[i].GetDouble("boundary_length_m") == e.boundary_length_m);
        CHECK(edges[i].GetDouble("contrast") == e.contrast);
        CHECK(edges[i].GetLong("mesh_edges") >= 1);
        graph_edges.insert({edges[i].GetLong("source"), edges[i].GetLong("target")});
    }
    // Every pair of 4-neighbour pixels with different labels is an edge.
    std::set<Pair> touching;
    for (int r = 0; r < t.dem.height; ++r)
        for (int c = 0; c < t.dem.width; ++c) {
            const std::int64_t a = t.pixels[t.dem.index(c, r)];
            for (const auto& [dc, dr] : {std::pair{1, 0}, std::pair{0, 1}}) {
                if (c + dc >= t.dem.width || r + dr >= t.dem.height) continue;
                const std::int64_t b = t.pixels[t.dem.index(c + dc, r + dr)];
                if (a != 0 && b != 0 && a != b) touching.insert({std::min(a, b), std::max(a, b)});
            }
        }
    for (const auto& p : touching) CHECK(graph_edges.count(p) == 1);
    // Every edge has a mesh edge between its labels (the graph may also join regions that
    // touch only diagonally, through a triangle's diagonal).
    std::set<Pair> mesh_pairs;
    for (std::size_t v = 0; v < t.mesh.vertex_count(); ++v)
        for (const auto nb : t.mesh.neighbors_of(v)) {
            const std::int64_t a = t.labels[v], b = t.labels[std::size_t(nb)];
            if (a != b) mesh_pairs.insert({std::min(a, b), std::max(a, b)});
        }
    for (const auto& p : graph_edges) CHECK(mesh_pairs.count(p) == 1);
    CHECK(mesh_pairs.size() == graph_edges.size());

    const auto first = test::file_bytes(path);
    CHECK_THROWS_AS(io::write_adjacency_json(t.graph, path, false), Error);
    io::write_adjacency_json(t.graph, path, true);
    CHECK(test::file_bytes(path) == first);
}

TEST_CASE("adjacency.graphml is GraphML with typed keys", "[write_adjacency]") {
    const auto t = vesta_tile();
    const auto dir = test::scratch_dir("write_adjacency_graphml");
    const auto path = (dir / "adjacency.graphml").string();
    io::write_adjacency_graphml(t.graph, path, false);
    const std::string text = test::file_bytes(path);
    CPLXMLNode* root = CPLParseXMLString(text.c_str());
    REQUIRE(root);
    const CPLXMLNode* graphml = CPLGetXMLNode(root, "=graphml");
    REQUIRE(graphml);
    CHECK(std::string(CPLGetXMLValue(graphml, "xmlns", "")) ==
          "http://graphml.graphdrawing.org/xmlns");
    std::map<std::string, std::string> key_type;  // id -> attr.type
    std::map<std::string, std::string> key_for;
    const CPLXMLNode* graph = nullptr;
    for (const CPLXMLNode* n = graphml->psChild; n; n = n->psNext) {
        if (n->eType != CXT_Element) continue;
        const std::string name = n->pszValue;
        if (name == "key") {
            const std::string id = CPLGetXMLValue(n, "id", "");
            key_type[id] = attribute(n, "attr.type");
            key_for[id] = CPLGetXMLValue(n, "for", "");
            CHECK(id.substr(2) == attribute(n, "attr.name"));
        } else if (name == "graph") {
            graph = n;
        }
    }
    CHECK(key_type.at("n_area_m2") == "double");
    CHECK(key_type.at("n_pixel_count") == "long");
    CHECK(key_type.at("n_landform") == "string");
    CHECK(key_type.at("e_boundary_length_m") == "double");
    CHECK(key_for.at("e_contrast") == "edge");
    REQUIRE(graph);
    CHECK(std::string(CPLGetXMLValue(graph, "edgedefault", "")) == "undirected");
    std::size_t nodes = 0, edges = 0;
    std::set<std::string> ids;
    for (const CPLXMLNode* n = graph->psChild; n; n = n->psNext) {
        if (n->eType != CXT_Element) continue;
        const std::string name = n->pszValue;
        if (name == "node") {
            ids.insert(CPLGetXMLValue(n, "id", ""));
            const auto& r = t.graph.regions[nodes++];
            CHECK(std::string(CPLGetXMLValue(n, "id", "")) == std::to_string(r.id));
        } else if (name == "edge") {
            const auto& e = t.graph.edges[edges++];
            CHECK(std::string(CPLGetXMLValue(n, "source", "")) == std::to_string(e.a));
            CHECK(std::string(CPLGetXMLValue(n, "target", "")) == std::to_string(e.b));
            CHECK(ids.count(CPLGetXMLValue(n, "source", "")) == 1);
        }
        // Every data element names a declared key of the right domain.
        if (name == "data") CHECK(key_for[CPLGetXMLValue(n, "key", "")] == "graph");
        for (const CPLXMLNode* d = n->psChild; d; d = d->psNext)
            if (d->eType == CXT_Element && std::string(d->pszValue) == "data") {
                const std::string key = CPLGetXMLValue(d, "key", "");
                REQUIRE(key_for.count(key) == 1);
                CHECK(key_for[key] == name);
            }
    }
    CHECK(nodes == t.region_count);
    CHECK(edges == t.graph.edges.size());
    CPLDestroyXMLNode(root);
    io::write_adjacency_graphml(t.graph, path, true);
    CHECK(test::file_bytes(path) == text);
}

TEST_CASE("adjacency.geojson: a point per region, a line per edge, readable by OGR",
          "[write_adjacency]") {
    const auto t = vesta_tile();
    const auto dir = test::scratch_dir("write_adjacency_geojson");
    const auto path = (dir / "adjacency.geojson").string();
    io::write_adjacency_geojson(t.graph, path, false);
    GDALAllRegister();
    std::unique_ptr<GDALDataset> ds(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
    REQUIRE(ds);
    OGRLayer* layer = ds->GetLayer(0);
    REQUIRE(layer->GetSpatialRef());
    CHECK(layer->GetSpatialRef()->GetSemiMajor() == Approx(255000));
    std::size_t points = 0, lines = 0;
    for (std::unique_ptr<OGRFeature> f(layer->GetNextFeature()); f;
         f.reset(layer->GetNextFeature())) {
        const OGRGeometry* g = f->GetGeometryRef();
        REQUIRE(g);
        if (std::string(f->GetFieldAsString("kind")) == "region") {
            const auto& r = t.graph.regions[points++];
            REQUIRE(wkbFlatten(g->getGeometryType()) == wkbPoint);
            CHECK(g->toPoint()->getX() == Approx(r.point[0]).margin(1e-8));
            CHECK(g->toPoint()->getY() == Approx(r.point[1]).margin(1e-8));
            CHECK(f->GetFieldAsInteger64("id") == r.id);
        } else {
            const auto& e = t.graph.edges[lines++];
            REQUIRE(wkbFlatten(g->getGeometryType()) == wkbLineString);
            CHECK(g->toLineString()->getNumPoints() == 2);
            CHECK(g->toLineString()->getX(1) ==
                  Approx(t.graph.regions[e.b - 1].point[0]).margin(1e-8));
            CHECK(f->GetFieldAsDouble("boundary_length_m") == Approx(e.boundary_length_m));
        }
    }
    CHECK(points == t.region_count);
    CHECK(lines == t.graph.edges.size());
}
