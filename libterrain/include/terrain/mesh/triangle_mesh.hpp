#pragma once
// The triangle mesh every later stage works on: compact arrays (float positions re-centred
// on an origin, int32 triangles, float vertex areas) and the vertex adjacency, a CSR for
// meshes read from files, on the pixel grid for DEM meshes (`terrain mesh` prints the bytes
// per vertex it holds). Vertices made from a DEM keep their pixel.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "terrain/core/body.hpp"
#include "terrain/core/progress.hpp"

namespace terrain {

// The neighbours of one vertex, sorted by index: a view of a stored list, or the few a grid
// computes, held in the object itself (so it may be copied freely).
class VertexNeighbors {
  public:
    const std::int32_t* begin() const { return list_ ? list_ : own_.data(); }
    const std::int32_t* end() const { return begin() + size_; }
    std::size_t size() const { return size_; }
    std::int32_t operator[](std::size_t i) const { return begin()[i]; }

  private:
    friend struct TriangleMesh;
    const std::int32_t* list_ = nullptr;
    std::uint32_t size_ = 0;
    std::array<std::int32_t, 8> own_;
};

enum class MeshFrame { body, map, file };

const char* to_string(MeshFrame frame);

struct TriangleMesh {
    using Triangle = std::array<std::int32_t, 3>;
    // Position of vertex v in metres = origin + positions()[v]; floats keep ~0.1 m on a
    // whole planet and sub-millimetre on a tile.
    std::array<double, 3> origin{0, 0, 0};
    // The positions and the triangles (counter-clockwise seen from outside the body, or from
    // above for a map frame). A DEM mesh may release them while no stage reads them (below):
    // positions() and triangles() then throw terrain::Error, and the stages that run meanwhile
    // walk the triangles in order through detail::for_each_triangle
    // (terrain/internal/mesh/grid_triangles.hpp), which makes them again from the grid, or
    // through for_each_triangle below. edit_positions() and edit_triangles() are for the code
    // that makes a mesh; they throw the same.
    const std::vector<std::array<float, 3>>& positions() const {
        if (released_vertices_ > 0) [[unlikely]]
            away("positions");
        return positions_;
    }
    std::vector<std::array<float, 3>>& edit_positions() {
        if (released_vertices_ > 0) [[unlikely]]
            away("positions");
        return positions_;
    }
    const std::vector<Triangle>& triangles() const {
        if (released_triangles_ > 0) [[unlikely]]
            away("triangles");
        return triangles_;
    }
    std::vector<Triangle>& edit_triangles() {
        if (released_triangles_ > 0) [[unlikely]]
            away("triangles");
        return triangles_;
    }
    // f(index, triangle) for each triangle in order, held or released (made again from the
    // grid, no position read): the triangle source for code outside the library's layers.
    void for_each_triangle(const std::function<void(std::size_t, const Triangle&)>& f) const;
    // One third of the incident triangles' areas, m^2 (their sum is the surface area).
    std::vector<float> vertex_areas;
    // The adjacency; read it through neighbors_of(v). Meshes from files: a CSR, the
    // neighbours of v are neighbors[neighbor_offsets[v] .. neighbor_offsets[v+1]), sorted by
    // index. DEM meshes leave these empty and keep it on the grid (below).
    std::vector<std::int32_t> neighbor_offsets;
    std::vector<std::int32_t> neighbors;

    // The adjacency on the grid (DEM meshes, docs/mesh.md "The adjacency on the grid"):
    // - pixel_vertex[p]: the vertex of pixel p (-1: none; a collapsed pole row: its pole; a
    //   split pinch: its first copy);
    // - neighbor_directions[v]: bit d set when the vertex of the pixel at vertex_pixel[v] +
    //   direction_offsets[d] (the 8 pixels around, in increasing order) is a neighbour;
    // - 0 there for the few vertices whose neighbours the grid does not give in order
    //   (poles, seam columns, pinches and their neighbours): their sorted lists are
    //   irregular_neighbors[irregular_offsets[i] .. [i+1]), i their rank in
    //   irregular_vertices.
    std::vector<std::int32_t> pixel_vertex;
    std::vector<std::uint8_t> neighbor_directions;
    std::array<std::int64_t, 8> direction_offsets{};
    std::vector<std::int32_t> irregular_vertices;
    std::vector<std::uint32_t> irregular_offsets;
    std::vector<std::int32_t> irregular_neighbors;
    // - uniform_ranges: vertex ranges [first, end) where each vertex's neighbours in the grid
    //   are v + direction_offsets[d] (the rows around it have a vertex for every pixel, all
    //   numbered alike); neighbors_of reads no pixel map there (a whole global grid without
    //   NoData is one range). At most kUniformRanges, ascending.
    std::vector<std::array<std::int32_t, 2>> uniform_ranges;
    static constexpr std::size_t kUniformRanges = 8;
    std::size_t grid_edges = 0;  // the edges of a grid adjacency
    // DEM meshes: the triangles can be made again from the grid (release_triangles): their
    // orientation, and those that name a split pinch's copy (index, corners), in order.
    bool triangles_flipped = false;
    std::vector<std::pair<std::uint64_t, std::array<std::int32_t, 3>>> pinch_triangles;
    // The diagonal each 2x2 block of four vertices was split along: bit `col` of row `row`'s
    // words (ceil(grid_width / 64) of them a row of blocks) set for top-right to bottom-left.
    std::vector<std::uint64_t> block_diagonals;

    // DEM meshes: the pixel (row*grid_width + col) each vertex was made from; empty for
    // meshes read from files. A pole vertex keeps the first pixel of its row.
    std::vector<std::int32_t> vertex_pixel;
    int grid_width = 0, grid_height = 0;

    MeshFrame frame = MeshFrame::file;
    Body body;            // the body for DEM meshes in the body frame
    std::string crs_wkt;  // the DEM's CRS (map frame: the CRS of x, y)

    // What the triangulation met (DEM meshes).
    std::size_t pinched_vertices = 0;   // vertices split because fans met only at them
    std::size_t isolated_vertices = 0;  // valid pixels (or file vertices) in no triangle, left out
    bool seam_closed = false;           // a global grid: last column joined to the first
    // Collapsed pole rows (north, south) and their vertices; -1 when not collapsed.
    std::array<int, 2> pole_rows{-1, -1};
    std::array<std::int32_t, 2> pole_vertices{-1, -1};

    std::size_t vertex_count() const {
        return positions_released() ? released_vertices_ : positions_.size();
    }
    // A DEM mesh may also free its positions (12 bytes a vertex) while the stages that do not
    // read them run (the Reeb graph and the simplification): mesh::restore_positions(dem, mesh)
    // places them again, the same floats. Returns false, keeping them, for a mesh that cannot
    // (read from a file, or without its recorded diagonals, which the triangles made again from
    // the grid read instead of the positions).
    bool release_positions();
    bool positions_released() const { return released_vertices_ > 0; }
    // For mesh::restore_positions: the positions placed again (one a vertex).
    void set_restored_positions(std::vector<std::array<float, 3>>&& placed);
    std::size_t triangle_count() const {
        return triangles_released() ? released_triangles_ : triangles_.size();
    }
    // A DEM mesh may free its triangles once no stage needs them at random (after the Reeb
    // graph): detail::for_each_triangle (src/mesh/grid_triangles.hpp) makes them again from the
    // grid, in order. Returns false, keeping them, for a mesh that cannot (read from a file).
    bool release_triangles();
    bool triangles_released() const { return released_triangles_ > 0; }
    // Makes the triangles released again from the grid (the same ones, in the same order);
    // nothing to do when it holds them.
    void restore_triangles();
    // Whether release_triangles would free them (a DEM mesh that holds them).
    bool triangles_releasable() const;
    std::array<double, 3> position(std::size_t v) const {
        const auto& p = positions()[v];
        return {origin[0] + p[0], origin[1] + p[1], origin[2] + p[2]};
    }
    bool grid_adjacency() const { return !neighbor_directions.empty(); }
    // The neighbours of v, sorted by index.
    VertexNeighbors neighbors_of(std::size_t v) const {
        VertexNeighbors out;
        if (!grid_adjacency()) {
            out.list_ = neighbors.data() + neighbor_offsets[v];
            out.size_ = static_cast<std::uint32_t>(neighbor_offsets[v + 1] - neighbor_offsets[v]);
            return out;
        }
        if (const unsigned bits = neighbor_directions[v]; bits != 0) {
            if (in_uniform_range(v)) {
                for (unsigned b = bits; b != 0; b &= b - 1)
                    out.own_[out.size_++] = static_cast<std::int32_t>(
                        std::int64_t(v) +
                        direction_offsets[static_cast<std::size_t>(__builtin_ctz(b))]);
                return out;
            }
            const std::int64_t p = vertex_pixel[v];
            for (unsigned b = bits; b != 0; b &= b - 1)
                out.own_[out.size_++] = pixel_vertex[static_cast<std::size_t>(
                    p + direction_offsets[static_cast<std::size_t>(__builtin_ctz(b))])];
            return out;
        }
        return irregular_neighbors_of(v);
    }
    std::size_t degree(std::size_t v) const { return neighbors_of(v).size(); }
    // Edges of the adjacency (each counted once).
    std::size_t edge_count() const { return grid_adjacency() ? grid_edges : neighbors.size() / 2; }
    // Bytes held by the arrays above (capacity, not size).
    std::size_t memory_bytes() const;
    // Frees the positions and the triangles for good, held or released (what is written after
    // the growing reads neither).
    void drop_geometry();
    // Frees the adjacency (both forms).
    void release_adjacency();

  private:
    [[noreturn]] static void away(const char* what);
    std::vector<std::array<float, 3>> positions_;
    std::vector<Triangle> triangles_;
    VertexNeighbors irregular_neighbors_of(std::size_t v) const;
    bool in_uniform_range(std::size_t v) const {
        for (const auto& r : uniform_ranges)
            if (v < std::size_t(r[1])) return v >= std::size_t(r[0]);
        return false;
    }
    // A DEM mesh whose triangles the grid makes again (its pixel maps and recorded diagonals).
    bool grid_describes_it() const;
    std::size_t released_triangles_ = 0;
    std::size_t released_vertices_ = 0;
};

// Counts of a mesh's topology.
struct MeshTopology {
    std::size_t vertices = 0, edges = 0, faces = 0;
    std::size_t boundary_edges = 0;         // edges in one triangle
    std::size_t boundary_loops = 0;         // connected cycles of boundary edges
    std::size_t components = 0;             // connected components (by triangles)
    std::int64_t euler_characteristic = 0;  // V - E + F
};

// Sets origin to the centre of the points' bounding box and positions to the points
// relative to it, as floats.
void set_positions(TriangleMesh& mesh, const std::vector<std::array<double, 3>>& points,
                   const ProgressFn& progress = {});

// Fills vertex_areas and the CSR adjacency from positions and triangles (dropping any
// adjacency on the grid).
void finish_mesh(TriangleMesh& mesh, const ProgressFn& progress = {});

// Fills vertex_areas and the adjacency on the grid from positions, triangles, vertex_pixel,
// the grid's size and pixel_vertex (set by the caller); a grid under 3 pixels wide gets the
// CSR. Any vertex the grid does not describe (its neighbours not at the 8 pixels around, or
// not in increasing order) gets an explicit list, so the adjacency is that of the triangles.
void finish_grid_mesh(TriangleMesh& mesh, const ProgressFn& progress = {});

MeshTopology mesh_topology(const TriangleMesh& mesh);

// The mean of the vertex areas (the vertex areas summed in order as doubles, over their
// count); 0 for a mesh without areas. On a DEM mesh, the ground area of a pixel.
double mean_vertex_area(const TriangleMesh& mesh);

// Each vertex's first slot among the directed edges (the prefix sums of the degrees, n + 1 of
// them): the edge a -> b is slot first[a] + b's rank among a's neighbours. Throws
// terrain::Error (stage "mesh") past 2^31 directed edges.
std::vector<std::uint32_t> first_edge_slots(const TriangleMesh& mesh);

// Splits every vertex whose triangles form several fans (meeting only at the vertex): the
// largest fan (ties: the one with the lowest triangle) keeps it, each other fan gets a copy
// appended at the end (vertex_pixel copied too). Returns the number of vertices split and
// stores the first one in *first_pinched when given. Call before finish_mesh.
// `may_pinch` (when given) names the only vertices that can be pinched: the others are not
// looked at, and their incident triangles are not listed (dem_to_mesh: the vertices next to a
// missing pixel or the grid's edge; a full grid lists almost none, 24 bytes a pixel less).
std::size_t split_pinched_vertices(TriangleMesh& mesh, std::int32_t* first_pinched = nullptr,
                                   const ProgressFn& progress = {},
                                   const std::function<bool(std::size_t)>& may_pinch = {});

// Removes vertices that are in no triangle, keeping the order of the others (and their
// vertex_pixel). Returns the number removed.
std::size_t remove_unreferenced_vertices(TriangleMesh& mesh, const ProgressFn& progress = {});

}  // namespace terrain
