// Mesh files in. CGAL's polygon-soup readers and repair live in this one translation unit
// (CGAL headers are slow to compile).
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>

#include "mesh_header_check.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/io/mesh_files.hpp"

namespace terrain::io {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Polygon = std::vector<std::size_t>;
namespace PMP = CGAL::Polygon_mesh_processing;

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

double twice_area(const std::vector<Point>& p, std::size_t a, std::size_t b, std::size_t c) {
    const auto n = CGAL::cross_product(p[b] - p[a], p[c] - p[a]);
    return std::sqrt(n.squared_length());
}

std::string face_text(std::size_t f, const Polygon& poly) {
    std::string s = "face " + std::to_string(f) + " (vertices";
    for (auto v : poly) s += " " + std::to_string(v);
    return s + ")";
}

// Fan-triangulates polygons, drops degenerate triangles (repeated vertex or zero area).
void triangulate_and_clean(const std::vector<Point>& points, std::vector<Polygon>& polygons) {
    std::vector<Polygon> out;
    out.reserve(polygons.size());
    for (const auto& poly : polygons)
        for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
            const std::size_t a = poly[0], b = poly[k], c = poly[k + 1];
            if (a == b || b == c || a == c || twice_area(points, a, b, c) == 0) continue;
            out.push_back({a, b, c});
        }
    polygons = std::move(out);
}

// The first problem of a triangle soup, or an empty string.
std::string first_problem(const std::vector<Point>& points, const std::vector<Polygon>& polygons) {
    for (std::size_t f = 0; f < polygons.size(); ++f) {
        const auto& poly = polygons[f];
        if (poly.size() != 3)
            return face_text(f, poly) + " has " + std::to_string(poly.size()) +
                   " vertices; only triangles are read";
        for (auto v : poly)
            if (v >= points.size())
                return face_text(f, poly) + " refers to a vertex that does not exist";
        if (poly[0] == poly[1] || poly[1] == poly[2] || poly[0] == poly[2])
            return face_text(f, poly) + " is degenerate: a vertex repeats";
        if (twice_area(points, poly[0], poly[1], poly[2]) == 0)
            return face_text(f, poly) + " is degenerate: its area is zero";
    }
    // Directed edges: the same direction twice means two faces disagree on orientation or
    // more than two faces share the edge.
    std::vector<std::array<std::size_t, 3>> directed;  // (from, to, face)
    directed.reserve(3 * polygons.size());
    for (std::size_t f = 0; f < polygons.size(); ++f)
        for (int k = 0; k < 3; ++k)
            directed.push_back({polygons[f][k], polygons[f][(k + 1) % 3], f});
    std::vector<std::array<std::size_t, 3>> undirected = directed;
    for (auto& e : undirected)
        if (e[0] > e[1]) std::swap(e[0], e[1]);
    std::sort(undirected.begin(), undirected.end());
    for (std::size_t i = 0; i + 2 < undirected.size(); ++i)
        if (undirected[i][0] == undirected[i + 2][0] && undirected[i][1] == undirected[i + 2][1])
            return "edge " + std::to_string(undirected[i][0]) + "-" +
                   std::to_string(undirected[i][1]) + " is non-manifold: it is in faces " +
                   std::to_string(undirected[i][2]) + ", " + std::to_string(undirected[i + 1][2]) +
                   " and " + std::to_string(undirected[i + 2][2]);
    std::sort(directed.begin(), directed.end());
    for (std::size_t i = 0; i + 1 < directed.size(); ++i)
        if (directed[i][0] == directed[i + 1][0] && directed[i][1] == directed[i + 1][1])
            return "faces " + std::to_string(directed[i][2]) + " and " +
                   std::to_string(directed[i + 1][2]) +
                   " are oriented inconsistently across edge " + std::to_string(directed[i][0]) +
                   "-" + std::to_string(directed[i][1]);
    return {};
}

}  // namespace

bool is_mesh_file(const std::string& path) {
    const auto ext = lower_extension(path);
    return ext == ".off" || ext == ".ply" || ext == ".obj";
}

TriangleMesh read_mesh(const std::string& path, const ReadMeshOptions& options,
                       const ProgressFn& progress) {
    return read_mesh(path, options, progress, MemoryPlan{});
}

TriangleMesh read_mesh(const std::string& path, const ReadMeshOptions& options,
                       const ProgressFn& progress, const MemoryPlan& memory) {
    if (!std::filesystem::exists(path))
        throw Error("mesh", "'" + path + "' does not exist; check the path");
    if (!is_mesh_file(path)) throw Error("mesh", "'" + path + "' is not a .off, .ply or .obj mesh");
    // Headers and counts checked before CGAL's parser sees the file; the peak of reading,
    // repairing and checking estimated from them.
    const auto counts = check_mesh_file(path, lower_extension(path));
    if (memory.checked)
        check_memory("the mesh '" + path + "' (" + std::to_string(counts.vertices) + " vertices, " +
                         std::to_string(counts.faces) + " faces)",
                     memory.mesh_bytes(double(counts.vertices), double(counts.faces),
                                       double(counts.indices)),
                     memory.limit);
    std::vector<Point> points;
    std::vector<Polygon> polygons;
    bool ok = false;
    try {
        ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
    } catch (const std::exception&) {
        ok = false;
    }
    if (!ok || points.empty() || polygons.empty())
        throw Error("mesh", "cannot read a mesh from '" + path +
                                "'; check that it is a valid OFF, PLY or OBJ file with faces");
    for (std::size_t v = 0; v < points.size(); ++v)
        if (!std::isfinite(points[v].x()) || !std::isfinite(points[v].y()) ||
            !std::isfinite(points[v].z()))
            throw Error("mesh", "vertex " + std::to_string(v) + " of '" + path +
                                    "' has a NaN or infinite coordinate");
        else if (std::max({std::abs(points[v].x()), std::abs(points[v].y()),
                           std::abs(points[v].z())}) > kMaxMeshCoordinate)
            throw Error("mesh", "vertex " + std::to_string(v) + " of '" + path +
                                    "' has a coordinate beyond 1e9; not a surface in metres");
    report_progress(progress, 0.3, "read mesh");

    if (options.repair) {
        for (const auto& poly : polygons)
            for (auto v : poly)
                if (v >= points.size())
                    throw Error("mesh", "'" + path + "' has a face referring to vertex " +
                                            std::to_string(v) + ", which does not exist");
        PMP::repair_polygon_soup(points, polygons);
        triangulate_and_clean(points, polygons);
        PMP::orient_polygon_soup(points, polygons);  // duplicates points where needed
        triangulate_and_clean(points, polygons);
        if (polygons.empty())
            throw Error("mesh", "'" + path + "' has no non-degenerate face left after repair");
    }
    if (const auto problem = first_problem(points, polygons); !problem.empty())
        throw Error("mesh", "'" + path + "': " + problem +
                                (options.repair ? "" : "; pass --repair to fix it"));
    report_progress(progress, 0.6, "read mesh");

    TriangleMesh mesh;
    mesh.frame = MeshFrame::file;
    std::vector<std::array<double, 3>> xyz;
    xyz.reserve(points.size());
    for (const auto& p : points) xyz.push_back({p.x(), p.y(), p.z()});
    set_positions(mesh, xyz);
    mesh.edit_triangles().reserve(polygons.size());
    for (const auto& poly : polygons)
        mesh.edit_triangles().push_back(
            {std::int32_t(poly[0]), std::int32_t(poly[1]), std::int32_t(poly[2])});
    mesh.isolated_vertices = remove_unreferenced_vertices(mesh);
    // A vertex where fans meet only at a point.
    TriangleMesh probe = mesh;
    std::int32_t first = -1;
    const std::size_t pinched = split_pinched_vertices(probe, &first);
    if (pinched > 0) {
        if (!options.repair)
            throw Error("mesh", "'" + path + "': vertex " + std::to_string(first) +
                                    " is non-manifold (faces meet only at it; " +
                                    std::to_string(pinched) +
                                    " such vertices); pass --repair to split them");
        mesh = std::move(probe);
        mesh.pinched_vertices = pinched;
    }
    finish_mesh(mesh);
    report_progress(progress, 1.0, "read mesh");
    return mesh;
}

}  // namespace terrain::io
