#pragma once
// Internals shared by the shape index's methods, not installed: shape_index.cpp (the mesh
// method and the dispatch), shape_index_normals.cpp, shape_index_lanes.cpp (four vertices at
// a time), shape_index_grid.cpp (the grid method of the ball window) and shape_index_disk.cpp
// (the disk window); the fit itself is curvature_fit.hpp's. docs/field.md describes them.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "curvature_fit.hpp"
#include "terrain/field/shape_index.hpp"

namespace terrain::field::detail {

struct Scratch {
    std::vector<std::uint32_t> stamp;
    std::uint32_t current = 0;
    std::vector<std::int32_t> gathered;
};

// The neighbourhood of v (gathered[0] is v itself): the vertices `inside` takes, reached
// from v through vertices it takes, within `rings` rings of mesh edges (< 0: any number),
// breadth first, each neighbour's list in its order. first_seen(w) says whether w is met for
// the first time (and remembers it); v is met first.
template <class Inside, class FirstSeen>
void gather_breadth_first(const TriangleMesh& mesh, std::int32_t v, int rings, const Inside& inside,
                          FirstSeen&& first_seen, std::vector<std::int32_t>& gathered) {
    gathered.clear();
    first_seen(v);
    gathered.push_back(v);
    std::size_t begin = 0;
    for (int ring = 0; rings < 0 || ring < rings; ++ring) {
        const std::size_t end = gathered.size();
        if (begin == end) break;
        for (std::size_t i = begin; i < end; ++i) {
            const auto u = gathered[i];
            for (const auto w : mesh.neighbors_of(std::size_t(u)))
                if (first_seen(w) && inside(w)) gathered.push_back(w);
        }
        begin = end;
    }
}

// gather_breadth_first with a stamp per vertex of the mesh (s.stamp) for the vertices met.
template <class Inside>
void gather_where(const TriangleMesh& mesh, std::int32_t v, int rings, const Inside& inside,
                  Scratch& s) {
    if (s.stamp.size() != mesh.vertex_count()) s.stamp.assign(mesh.vertex_count(), 0);
    if (++s.current == 0) {
        std::fill(s.stamp.begin(), s.stamp.end(), 0);
        s.current = 1;
    }
    gather_breadth_first(
        mesh, v, rings, inside,
        [&](std::int32_t w) {
            if (s.stamp[std::size_t(w)] == s.current) return false;
            s.stamp[std::size_t(w)] = s.current;
            return true;
        },
        s.gathered);
}

struct GridLayout {
    int width = 0, height = 0;
    bool seam = false;
    // Each pixel's vertex, or -1: the mesh's (TriangleMesh::pixel_vertex, not copied), or
    // `own` made for a mesh without it. The collapsed pole rows own none here (`pole_rows`):
    // their one vertex takes the mesh path.
    const std::int32_t* pixel_vertex = nullptr;
    std::array<int, 2> pole_rows{-1, -1};
    std::vector<std::int32_t> own;
    int disk_tile = 64;  // pixels per side of the disk window's tiles

    GridLayout() = default;
    GridLayout(GridLayout&&) = default;  // (own's block moves with it: pixel_vertex stays)
    GridLayout& operator=(GridLayout&&) = default;
    GridLayout(const GridLayout&) = delete;
    GridLayout& operator=(const GridLayout&) = delete;

    // The vertex pixel (col, row) of the grid owns, or -1.
    std::int32_t vertex_at(int col, int row) const {
        if (row == pole_rows[0] || row == pole_rows[1]) return -1;
        return pixel_vertex[std::size_t(row) * std::size_t(width) + std::size_t(col)];
    }
    // The same for any (col, row): -1 off the grid's rows, and off its columns unless it is
    // a global grid, whose columns wrap across the seam.
    std::int32_t vertex_near(int col, int row) const {
        if (row < 0 || row >= height) return -1;
        if (col < 0 || col >= width) {
            if (!seam) return -1;
            col = ((col % width) + width) % width;
        }
        return vertex_at(col, row);
    }
    // f(v, col, row) for each vertex the pixels [c0, c1) x [r0, r1) own, row by row.
    template <class F>
    void for_each_vertex(int r0, int r1, int c0, int c1, F&& f) const {
        for (int row = r0; row < r1; ++row)
            for (int col = c0; col < c1; ++col)
                if (const auto v = vertex_at(col, row); v >= 0) f(v, col, row);
    }
};

// The disk window's tiles span at most this angle on the body: its fit is made in one frame
// per tile, from moments about the tile's first vertex, whose precision falls with the
// distance of a vertex from it.
constexpr double kMaxDiskTileAngle = 0.05;  // radians

constexpr int kTile = 64;       // output pixels per tile side
constexpr int kMaxReach = 128;  // a window reaching further (pixels) takes the mesh path
// The ladder's rungs above the first cut a window reaching up to this far to kMaxReach
// (a quarter past: a few per cent narrower across the tile's narrower pixels) and skip one
// reaching further (disk_tile).
constexpr int kNearReach = kMaxReach + kMaxReach / 4;

// The vertex a pixel owns (-1 where none, and on collapsed pole rows), the grid's seam and
// the disk window's tile size.
GridLayout grid_layout(const TriangleMesh& mesh, double tile_angle = kMaxDiskTileAngle);

// Whether pixel (col, row) of a width x height grid is fitted at a sample stride: every
// stride-th column and row, and the last ones.
inline bool sampled_pixel(int col, int row, int stride, int width, int height) {
    return (col % stride == 0 || col == width - 1) && (row % stride == 0 || row == height - 1);
}

// The disk window: the pixels whose ground offset from the vertex, lifted onto the vertex's
// tangent plane, is within the radius (the ball's footprint where the terrain is its tangent
// plane: an ellipse of the grid, a disk on flat ground). It is drawn as three bands of rows
// on each side of the vertex's row, each band covering a third of the ellipse's half-height
// with the columns the ellipse spans at the band's middle row (the band's area is the
// ellipse's, within 2 %): six rectangles, which the grid method sums from summed-area tables
// in four look-ups each whatever their size.
struct DiskWindow {
    struct Band {
        int row_lo = 0, row_hi = -1, col_lo = 0, col_hi = -1;  // offsets from the vertex
    };
    int bands = 0;
    std::array<Band, 6> band{};
    int reach_x = 0, reach_y = 0;  // the largest |column| and |row| offsets
    bool contains(int dx, int dy) const {
        for (int k = 0; k < bands; ++k) {
            const auto& b = band[std::size_t(k)];
            if (dy >= b.row_lo && dy <= b.row_hi) return dx >= b.col_lo && dx <= b.col_hi;
        }
        return false;
    }
};

// Area-weighted unit vertex normals, each vertex's sum taken in triangle order
// (shape_index_normals.cpp).
std::vector<Vec3> vertex_normals(const TriangleMesh& mesh, const ProgressFn& progress = {});

// Unit vertex normals of the vertices [first, first + values.size()): all of a mesh's, or
// those of a band of a DEM grid's pixel rows (band_normals).
struct Normals {
    std::size_t first = 0;
    std::vector<Vec3> values;
    const Vec3& operator[](std::size_t v) const { return values[v - first]; }
};

// Whether band_normals applies: a DEM mesh whose rows of triangles can be made alone, without
// a split pinch (each vertex then owns its pixel, or its collapsed pole row's).
bool normals_by_bands(const TriangleMesh& mesh);

// The normals of the vertices of pixel rows [r0, r1), as vertex_normals gives them: the same
// sums in the same order, so the same bits (shape_index_normals.cpp). `out` spans the ids of the
// vertices the rows' pixels own; where it holds a vertex of another row, that entry is no
// normal.
void band_normals(const TriangleMesh& mesh, int r0, int r1, Normals& out);

// fit_curvatures for kFitLanes vertices at once, in the lanes of vectors (shape_index_lanes.cpp):
// every lane does the same operations in the same order as fit_curvatures (no operation is fused or
// reordered; a lane past its last neighbour keeps its sums as they are), so each vertex gets the
// same bits. A lane the vectors cannot finish (fewer than 5 neighbours, a zero scale, a singular
// system) is fitted by fit_curvatures.
constexpr int kFitLanes = 4;
struct FitBatch {
    std::array<std::int32_t, kFitLanes> vertex{};
    std::array<const std::int32_t*, kFitLanes> neighbours{};
    std::array<Vec3, kFitLanes> normal{};
    std::array<std::size_t, kFitLanes> m{};  // each lane's neighbour count
};
void fit_curvatures_batch(const TriangleMesh& mesh, const FitBatch& batch,
                          std::array<PrincipalCurvatures, kFitLanes>& out,
                          std::array<double, kFitLanes>& scale, std::array<bool, kFitLanes>& ok);

// A set of vertex ids that holds what one vertex's rings hold (an open-addressing table, its
// room doubled as it fills, emptied entry by entry): gather_rings' visited vertices, instead
// of a stamp per vertex of the mesh on each thread.
class SmallVertexSet {
  public:
    // Whether v was not there (it is now).
    bool insert(std::int32_t v) {
        if (2 * (used_.size() + 1) > slots_.size()) grow();
        for (std::size_t h = slot_of(v);; h = (h + 1) & (slots_.size() - 1)) {
            if (slots_[h] == v) return false;
            if (slots_[h] < 0) {
                slots_[h] = v;
                used_.push_back(h);
                return true;
            }
        }
    }
    void clear() {
        for (const std::size_t h : used_) slots_[h] = -1;
        used_.clear();
    }

  private:
    std::size_t slot_of(std::int32_t v) const {
        return (std::uint32_t(v) * 2654435761u) & (slots_.size() - 1);
    }
    void grow() {
        std::vector<std::int32_t> held;
        for (const std::size_t h : used_) held.push_back(slots_[h]);
        slots_.assign(std::max<std::size_t>(64, 2 * slots_.size()), -1);
        used_.clear();
        for (const std::int32_t v : held) insert(v);
    }
    std::vector<std::int32_t> slots_;
    std::vector<std::size_t> used_;
};

// v and `rings` rings of its neighbours (gathered[0] is v), in gather_where's order, with
// `visited` for the vertices seen.
void gather_rings(const TriangleMesh& mesh, std::int32_t v, int rings, SmallVertexSet& visited,
                  std::vector<std::int32_t>& gathered);

// v and its two rings of neighbours in the order gather_where gives them (rings = 2), read off
// a DEM mesh's grid directions without a stamp per vertex; false (`out` unfinished) where the
// grid does not give them in order (near NoData, the seam, poles, pinches, the grid's first
// and last rows): gather_where then does it.
bool gather_two_rings_on_grid(const TriangleMesh& mesh, std::int32_t v,
                              std::vector<std::int32_t>& out);

// The mesh path for one vertex: gather its neighbourhood on the mesh and fit. With
// `disk_grid` (the disk window applies) the neighbourhood is the vertex's disk, except at a
// collapsed pole, whose pixel is no place on the ground: it takes the ball.
bool mesh_fit(const TriangleMesh& mesh, std::int32_t v, const Vec3& normal,
              const ShapeIndexOptions& options, const GridLayout* disk_grid, Scratch& s,
              PrincipalCurvatures& k, double& scale);

struct GridScratch {
    std::vector<Vec3> position;     // region pixels; x NaN where no vertex
    std::vector<double> prefix;     // per region row, (cols + 1) x kMoments running sums
    std::vector<int> lo, hi;        // the current window's span in each row offset
    std::vector<double> spacing;    // adjacent-pixel distances, to size the region
    std::vector<DiskWindow> disks;  // the tile's vertices' disk windows
    Scratch mesh;
};

using VertexFn = std::function<void(std::int32_t, bool, const PrincipalCurvatures&, double)>;

// The mesh path for vertex v of a tile whose sums could not hold its window: mesh_fit, its
// result through `body`, counted in `fallbacks`.
inline void tile_fallback(const TriangleMesh& mesh, std::int32_t v, const Vec3& normal,
                          const ShapeIndexOptions& options, const GridLayout* disk_grid,
                          GridScratch& s, std::size_t& fallbacks, const VertexFn& body) {
    const bool pole = v == mesh.pole_vertices[0] || v == mesh.pole_vertices[1];
    if (options.skip_wide && !pole) return body(v, false, PrincipalCurvatures{}, 0.0);
    PrincipalCurvatures k;
    double scale = 0;
    const bool ok = mesh_fit(mesh, v, normal, options, disk_grid, s.mesh, k, scale);
    body(v, ok, k, scale);
    ++fallbacks;
}

// One step of a Taylor shift of moments: moments[target] -= t[axis] * moments[source].
// Moving sums of monomials of offsets by a translation t is a run of such steps over each
// chain of moments that differ only in one axis's exponent (M[e] -= t M[e - 1] for
// j = 1..n, e = n down to j).
struct ShiftStep {
    std::uint8_t axis, target, source;
};

template <std::size_t N>
void apply_shift(const std::array<ShiftStep, N>& steps, const double* t, double* moments) {
#pragma GCC unroll 105
    for (const auto& step : steps) moments[step.target] -= t[step.axis] * moments[step.source];
}

// What a tile of pixels [c0, c1) x [r0, r1) works on: the tile and margins of mx columns
// and my rows (rows clipped to the grid; columns clipped, or wrapped across the seam of a
// global grid), its reference point (the tile's first vertex), and per region row the
// running sums of the N monomials `fill` makes of its pixels' positions about the reference
// (and the positions, when asked for).
struct Region {
    int rr0 = 0, cc0 = 0, rows = 0, cols = 0;
    Vec3 ref{0, 0, 0};
};
enum class RegionStatus { ok, empty, mesh_path };

template <int N, class Fill>
RegionStatus region_sums(const TriangleMesh& mesh, const GridLayout& g, int r0, int r1, int c0,
                         int c1, int mx, int my, bool positions, GridScratch& s, Region& out,
                         const Fill& fill) {
    const int W = g.width, H = g.height;
    if (mx > kMaxReach || my > kMaxReach) return RegionStatus::mesh_path;
    const int rr0 = std::max(0, r0 - my), rr1 = std::min(H, r1 + my);
    int cc0 = c0 - mx, cc1 = c1 + mx;
    if (g.seam) {
        if (cc1 - cc0 > W) return RegionStatus::mesh_path;
    } else {
        cc0 = std::max(0, cc0), cc1 = std::min(W, cc1);
    }
    const int rows = rr1 - rr0, cols = cc1 - cc0;
    const auto region_col = [&](int col) { return ((col % W) + W) % W; };
    // A collapsed pole row is one vertex, the pole, at its first pixel (where the mesh path
    // finds it: TriangleMesh::vertex_pixel); the row's other pixels hold none.
    const auto region_vertex = [&](int col, int row) -> std::int32_t {
        for (int k = 0; k < 2; ++k)
            if (row == mesh.pole_rows[std::size_t(k)]) {
                const auto pole = mesh.pole_vertices[std::size_t(k)];
                const auto pixel =
                    std::int32_t(std::size_t(row) * std::size_t(W) + std::size_t(col));
                return pole >= 0 && mesh.vertex_pixel[std::size_t(pole)] == pixel ? pole : -1;
            }
        return g.vertex_at(col, row);
    };
    Vec3 ref{0, 0, 0};
    bool any = false;
    for (int row = r0; row < r1 && !any; ++row)
        for (int col = c0; col < c1 && !any; ++col)
            if (const auto v = g.vertex_at(col, row); v >= 0) {
                const auto& p = mesh.positions()[std::size_t(v)];
                ref = {p[0], p[1], p[2]}, any = true;
            }
    if (!any) return RegionStatus::empty;
    if (positions) s.position.resize(std::size_t(rows) * std::size_t(cols));
    s.prefix.resize(std::size_t(rows) * std::size_t(cols + 1) * N);
    for (int lr = 0; lr < rows; ++lr) {
        double* running = &s.prefix[std::size_t(lr) * std::size_t(cols + 1) * N];
        std::fill_n(running, N, 0.0);
        for (int lc = 0; lc < cols; ++lc) {
            const auto v = region_vertex(region_col(cc0 + lc), rr0 + lr);
            Vec3 p{std::numeric_limits<double>::quiet_NaN(), 0, 0};
            double* next = running + N;
            if (v < 0) {
                std::copy_n(running, N, next);
            } else {
                const auto& q = mesh.positions()[std::size_t(v)];
                p = {q[0], q[1], q[2]};
                double mono[N];
                fill(Vec3{p[0] - ref[0], p[1] - ref[1], p[2] - ref[2]}, mono);
                for (int k = 0; k < N; ++k) next[k] = running[k] + mono[k];
            }
            if (positions) s.position[std::size_t(lr) * std::size_t(cols) + std::size_t(lc)] = p;
            running = next;
        }
    }
    out = {rr0, cc0, rows, cols, ref};
    return RegionStatus::ok;
}

// The disk window of v in its tile's frame, gathered on the mesh, and its Monge fit
// (shape_index_disk.cpp).
bool disk_mesh_fit(const TriangleMesh& mesh, const GridLayout& g, std::int32_t v,
                   const Vec3& normal, double radius, bool clip, Scratch& s, PrincipalCurvatures& k,
                   double& scale);

// How many pixels the disk window of `radius` reaches from a typical place of a DEM mesh:
// the radius over the median distance between neighbouring pixels along the grid's finer
// axis, the median taken by the vertices' areas (at most 4096 pixels sampled on a fixed
// stride); 0 when no two pixels neighbour.
double typical_disk_reach(const TriangleMesh& mesh, double radius);
// Throws terrain::Error when a window of `radius` (the option `name`: the disk, or the ball
// by the grid method) reaches beyond the grid method's tables (kMaxReach) from a typical
// place (typical_disk_reach): most disks would be cut to the tables' reach (vertex_disk's
// clip), and balls gathered on the mesh at a cost growing with their area.
void check_window_reach(const TriangleMesh& mesh, double radius, const char* name);

// The vertices of one tile of output pixels [c0, c0 + t) x [r0, r0 + t), t = g.disk_tile,
// with the disk window, through `body` (shape_index_disk.cpp).
void disk_tile(const TriangleMesh& mesh, const GridLayout& g, const Normals& normals,
               const ShapeIndexOptions& options, int r0, int c0, GridScratch& s,
               std::size_t& mesh_fallbacks, const VertexFn& body);

// Every vertex's fit with `options` (rings or one radius): body(v, ok, curvatures, scale),
// the curvatures times `scale` (shape_index.cpp's for_each_vertex), on several threads.
using CurvatureBody = std::function<void(std::int32_t, bool, const PrincipalCurvatures&, double)>;
void for_each_curvature(const TriangleMesh& mesh, const ShapeIndexOptions& options,
                        const ProgressFn& progress, const CurvatureBody& body);
// Whether vertex v's pixel row is among options' rows [first_row, end_row) (a vertex of a
// mesh not made from a DEM: always).
bool row_asked(const TriangleMesh& mesh, const ShapeIndexOptions& options, std::int32_t v);
// Whether the disk window applies (a radius, the disk window, a mesh made from a DEM) and
// whether the grid method does (shape_index_grid.cpp); the grid method refuses a mesh not made
// from a DEM when asked for.
bool disk_applies(const TriangleMesh& mesh, const ShapeIndexOptions& options);
bool grid_applies(const TriangleMesh& mesh, const ShapeIndexOptions& options);

// The grid method's fits of every vertex through `body`, normals 0 to 0.05 of the progress,
// the grid's layout to 0.06, the vertices to 1 (shape_index_grid.cpp).
void grid_method_for_each_vertex(const TriangleMesh& mesh, const ShapeIndexOptions& options,
                                 const ProgressFn& progress, const VertexFn& body);

}  // namespace terrain::field::detail
