#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

using namespace terrain;
using Catch::Matchers::Contains;

namespace {

std::string write_off(const std::filesystem::path& path, const std::string& body) {
    std::ofstream(path) << "OFF\n" << body;
    return path.string();
}

// An octahedron: closed, genus 0, consistently oriented.
const char* kOctahedron =
    "6 8 0\n1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n"
    "3 0 2 4\n3 2 1 4\n3 1 3 4\n3 3 0 4\n3 2 0 5\n3 1 2 5\n3 3 1 5\n3 0 3 5\n";

std::string error_of(const std::string& path, bool repair = false) {
    try {
        io::ReadMeshOptions options;
        options.repair = repair;
        io::read_mesh(path, options);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST_CASE("read_mesh reads a closed OFF mesh", "[mesh_files]") {
    const auto dir = test::scratch_dir("mesh_files_ok");
    const auto mesh = io::read_mesh(write_off(dir / "octa.off", kOctahedron));
    const auto topo = mesh_topology(mesh);
    CHECK(topo.vertices == 6);
    CHECK(topo.faces == 8);
    CHECK(topo.boundary_edges == 0);
    CHECK(topo.euler_characteristic == 2);
    double area = 0;
    for (float a : mesh.vertex_areas) area += a;
    CHECK(area == Approx(8 * std::sqrt(3.0) / 2));  // eight equilateral faces of side sqrt 2
}

TEST_CASE("read_mesh refuses bad meshes naming the first bad element", "[mesh_files][bad_input]") {
    const auto dir = test::scratch_dir("mesh_files_bad");
    // Three triangles on one edge.
    const auto fin = write_off(dir / "fin.off",
                               "5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n"
                               "3 0 1 2\n3 1 0 3\n3 0 1 4\n");
    CHECK_THAT(error_of(fin), Contains("edge 0-1 is non-manifold"));
    const auto degenerate =
        write_off(dir / "degenerate.off", "4 2 0\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n3 0 1 3\n3 0 1 2\n");
    CHECK_THAT(error_of(degenerate), Contains("face 1") && Contains("area is zero"));
    const auto repeated = write_off(dir / "repeated.off", "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 0 1\n");
    CHECK_THAT(error_of(repeated), Contains("face 0") && Contains("repeats"));
    const auto flipped =
        write_off(dir / "flipped.off", "4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 2 3\n");
    CHECK_THAT(error_of(flipped), Contains("oriented inconsistently"));
    const auto bowtie = write_off(dir / "bowtie.off",
                                  "5 2 0\n0 0 0\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n3 0 1 2\n3 0 3 4\n");
    CHECK_THAT(error_of(bowtie), Contains("vertex 0 is non-manifold"));
    const auto range = write_off(dir / "range.off", "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    CHECK_THAT(error_of(range), Contains("range.off"));  // CGAL's reader or ours refuses it
    std::ofstream(dir / "garbage.ply") << "this is not a mesh\n";
    CHECK_THAT(error_of((dir / "garbage.ply").string()), Contains("cannot read a mesh"));
    CHECK_THAT(error_of((dir / "missing.obj").string()), Contains("does not exist"));
    CHECK_THAT(error_of(fin), Contains("--repair"));

    SECTION("--repair fixes what it can") {
        const auto bow = io::read_mesh(bowtie, {true});
        CHECK(bow.pinched_vertices + 1 >= 1);
        CHECK(mesh_topology(bow).components == 2);
        const auto flip = io::read_mesh(flipped, {true});
        CHECK(mesh_topology(flip).faces == 2);
        const auto deg = io::read_mesh(degenerate, {true});
        CHECK(mesh_topology(deg).faces == 1);
    }
}

TEST_CASE("write_ply: binary PLY read back by CGAL, with pixel and area properties",
          "[mesh_files]") {
    const auto dir = test::scratch_dir("mesh_files_ply");
    const Dem dem = io::read_dem(test::sample("moon_ldem4_copernicus.tif"));
    const auto mesh = mesh::dem_to_mesh(dem);
    const auto path = (dir / "moon.ply").string();
    io::write_ply(mesh, path, false);
    // The header names the properties a PLY reader in another tool will see.
    std::ifstream in(path, std::ios::binary);
    std::string header, line;
    while (std::getline(in, line) && line != "end_header") header += line + "\n";
    CHECK_THAT(header, Contains("format binary_little_endian 1.0"));
    CHECK_THAT(header, Contains("property double x") && Contains("property int col") &&
                           Contains("property int row") && Contains("property float area"));
    CHECK_THAT(header, Contains("element vertex " + std::to_string(mesh.vertex_count())));
    // CGAL's reader gives back the same mesh.
    const auto back = io::read_mesh(path);
    CHECK(back.vertex_count() == mesh.vertex_count());
    CHECK(back.triangles() == mesh.triangles());
    for (std::size_t v = 0; v < mesh.vertex_count(); v += 97) {
        const auto p = mesh.position(v), q = back.position(v);
        CHECK(std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]) < 0.5);
    }
    // Existing outputs are kept unless overwrite; an unwritable place is an error.
    CHECK_THROWS_WITH(io::write_ply(mesh, path, false), Contains("--overwrite"));
    CHECK_NOTHROW(io::write_ply(mesh, path, true));
    CHECK_THROWS_AS(io::write_ply(mesh, (dir / "no/such/dir/x.ply").string(), false), Error);
    // No temporary left behind.
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
    CHECK(files == 1);
}
