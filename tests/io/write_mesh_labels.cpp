#include <catch2/catch.hpp>

#include <cstring>
#include <fstream>
#include <sstream>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_mesh_labels.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;

TEST_CASE("faces.seg: one label per face, majority of its vertices, ties to the lowest",
          "[write_mesh_labels]") {
    TriangleMesh mesh;
    set_positions(mesh, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}});
    mesh.edit_triangles() = {{0, 1, 2}, {1, 3, 2}, {1, 4, 3}, {4, 5, 3}};
    finish_mesh(mesh);
    const std::vector<std::uint32_t> labels = {1, 1, 2, 3, 2, 2};
    // {1,1,2} -> 1; {1,3,2} -> 1 (all differ); {1,2,3} -> 1; {2,2,3} -> 2.
    CHECK(io::face_labels(mesh, labels) == std::vector<std::uint32_t>{1, 1, 1, 2});
    const std::vector<std::uint32_t> others = {3, 2, 2, 1, 1, 3};
    // {3,2,2} -> 2; {2,1,2} -> 2; {2,1,1} -> 1; {1,3,1} -> 1.
    CHECK(io::face_labels(mesh, others) == std::vector<std::uint32_t>{2, 2, 1, 1});
    const auto dir = test::scratch_dir("write_faces_seg");
    const auto path = (dir / "faces.seg").string();
    io::write_faces_seg(mesh, labels, path, false);
    CHECK(test::file_bytes(path) == "1\n1\n1\n2\n");
    CHECK_THROWS_AS(io::write_faces_seg(mesh, labels, path, false), Error);
}

TEST_CASE("labels.ply: the mesh with uint label and float field per vertex",
          "[write_mesh_labels]") {
    const Dem mars = io::read_dem(test::sample("mars_hirise_crop.tif"));
    const auto t = test::segment_tile(mars, test::voronoi_cells(mars, 2, 3));
    const auto dir = test::scratch_dir("write_labels_ply");
    const auto path = (dir / "labels.ply").string();
    io::write_labels_ply(t.mesh, t.field, t.labels, path, false, "shape_index");
    const std::string text = test::file_bytes(path);
    const auto end = text.find("end_header\n");
    REQUIRE(end != std::string::npos);
    const std::string header = text.substr(0, end);
    CHECK(header.find("property uint label\nproperty float shape_index\n") != std::string::npos);
    // Vertex records: double x y z, int col row, float area, uint label, float field.
    const std::size_t record = 3 * 8 + 2 * 4 + 4 + 4 + 4;
    const char* data = text.data() + end + 11;
    for (std::size_t v = 0; v < t.mesh.vertex_count(); v += 97) {
        std::uint32_t label = 0;
        float field = 0;
        std::memcpy(&label, data + v * record + 36, 4);
        std::memcpy(&field, data + v * record + 40, 4);
        CHECK(label == t.labels[v]);
        CHECK(field == t.field[v]);
    }
    CHECK(text.size() == end + 11 + t.mesh.vertex_count() * record + t.mesh.triangle_count() * 13);
    CHECK_THROWS_AS(io::write_labels_ply(t.mesh, t.field, t.labels, path, true, "label"), Error);
}
