// The grid method of the shape index (DEM meshes with a metric radius; docs/field.md,
// "Windows and methods"): the grid's layout, which method applies, and the ball window's fits
// by tiles of pixels from row sums of the moments (grid_moments.hpp).
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "curvature_fit.hpp"
#include "grid_moments.hpp"
#include "shape_index_fit.hpp"
#include "terrain/core/error.hpp"

namespace terrain::field::detail {

GridLayout grid_layout(const TriangleMesh& mesh, double tile_angle) {
    GridLayout g;
    g.width = mesh.grid_width, g.height = mesh.grid_height;
    g.seam = mesh.seam_closed;
    const std::size_t pixels = std::size_t(g.width) * std::size_t(g.height);
    if (mesh.pixel_vertex.size() == pixels) {
        g.pixel_vertex = mesh.pixel_vertex.data();
    } else {  // the first copy of a split pinch owns its pixel, as in the mesh's map
        g.own.assign(pixels, -1);
        for (std::size_t v = mesh.vertex_pixel.size(); v-- > 0;)
            g.own[std::size_t(mesh.vertex_pixel[v])] = std::int32_t(v);
        g.pixel_vertex = g.own.data();
    }
    // A collapsed pole row is one vertex: it takes the mesh path.
    g.pole_rows = mesh.pole_rows;
    // On a body, the disk window's tiles are made smaller where 64 pixels span more than
    // kMaxDiskTileAngle: from the longest distance between neighbouring pixels and the
    // largest distance from the body's centre among about 64 x 64 pixels spread over the grid.
    if (mesh.frame == MeshFrame::body) {
        double spacing = 0, radius = 0;
        const int row_step = std::max(1, g.height / 64), col_step = std::max(1, g.width / 64);
        for (int r = 0; r + 1 < g.height; r += row_step)
            for (int c = 0; c + 1 < g.width; c += col_step) {
                const auto v = g.vertex_at(c, r);
                if (v < 0) continue;
                const auto& p = mesh.positions()[std::size_t(v)];
                const Vec3 q{mesh.origin[0] + p[0], mesh.origin[1] + p[1], mesh.origin[2] + p[2]};
                radius = std::max(radius, std::sqrt(dot(q, q)));
                for (const auto w : {g.vertex_at(c + 1, r), g.vertex_at(c, r + 1)})
                    if (w >= 0) {
                        const Vec3 d = sub(mesh.positions()[std::size_t(w)], p);
                        spacing = std::max(spacing, std::sqrt(dot(d, d)));
                    }
            }
        if (spacing > 0) g.disk_tile = int(std::clamp(tile_angle * radius / spacing, 8.0, 64.0));
    }
    return g;
}

namespace {

bool dem_mesh(const TriangleMesh& mesh) {
    return mesh.grid_width > 0 && mesh.grid_height > 0 &&
           mesh.vertex_pixel.size() == mesh.vertex_count();
}

}  // namespace

bool disk_applies(const TriangleMesh& mesh, const ShapeIndexOptions& options) {
    return options.radius > 0 && options.window == ShapeIndexWindow::disk && dem_mesh(mesh);
}

bool grid_applies(const TriangleMesh& mesh, const ShapeIndexOptions& options) {
    if (options.method == ShapeIndexMethod::mesh || !(options.radius > 0)) return false;
    const bool grid = dem_mesh(mesh);
    if (options.method == ShapeIndexMethod::grid && !grid)
        throw Error("field", "the grid method needs a mesh made from a DEM");
    return grid;
}

namespace {

// Moves moments about the reference to moments about the vertex at `centre` (sum (e - t)^a
// from sum e^a, axis by axis), fits and hands the result to `body`.
void fit_from_moments(double* moments, const Vec3& centre, const Vec3& ref, const Vec3& normal,
                      std::int32_t v, const VertexFn& body) {
    const Vec3 t{centre[0] - ref[0], centre[1] - ref[1], centre[2] - ref[2]};
    apply_shift(kShift, t.data(), moments);
    PrincipalCurvatures k;
    const auto equations = equations_from_moments(moments, normal);
    const bool fitted = solve_curvatures(equations, k);
    body(v, fitted, k, equations.scale);
}

// How far (in pixels) the ball can reach from the tile [c0, c1) x [r0, r1) along (dc, dr):
// from the short end of the tile's distances between neighbouring pixels, with a margin;
// kMaxReach + 1 (the mesh path) when a window would reach further.
int tile_reach(const TriangleMesh& mesh, const GridLayout& g, double radius, int r0, int r1, int c0,
               int c1, int dc, int dr, std::vector<double>& spacing) {
    spacing.clear();
    for (int row = r0; row + dr < r1; ++row)
        for (int col = c0; col + dc < c1; ++col) {
            const auto a = g.vertex_at(col, row), b = g.vertex_at(col + dc, row + dr);
            if (a < 0 || b < 0) continue;
            const Vec3 d = sub(mesh.positions()[std::size_t(a)], mesh.positions()[std::size_t(b)]);
            spacing.push_back(std::sqrt(dot(d, d)));
        }
    if (spacing.empty()) return kMaxReach + 1;
    const auto tenth = spacing.begin() + std::ptrdiff_t(spacing.size() / 10);
    std::nth_element(spacing.begin(), tenth, spacing.end());
    if (!(*tenth > 0)) return kMaxReach + 1;
    const double r = 1.25 * radius / *tenth + 2;
    return r > kMaxReach ? kMaxReach + 1 : int(std::ceil(r));
}

// The ball of one vertex in a tile's region: its pixels row by row.
struct BallInRegion {
    const GridLayout& g;
    const Region& region;
    int mx, my;  // the region's margins (columns, rows)
    double r2;   // the radius squared
};

// Each row offset's span of the region's pixels within the ball around region pixel
// (lr, lc), in s.lo and s.hi (lo > hi: none); with `warm`, moved from the spans of the
// previous pixel of the row. False when the ball may reach beyond the region: the vertex
// then takes the mesh path.
bool ball_spans(const BallInRegion& ball, int lr, int lc, bool warm, GridScratch& s) {
    const int W = ball.g.width, H = ball.g.height, mx = ball.mx, my = ball.my;
    const int rr0 = ball.region.rr0, cc0 = ball.region.cc0, rows = ball.region.rows,
              cols = ball.region.cols;
    const Vec3 centre = s.position[std::size_t(lr) * std::size_t(cols) + std::size_t(lc)];
    // Within the ball, as the mesh path tests it.
    // (A pixel without a vertex has a NaN position: never inside.)
    const auto inside = [&](int r, int c) {
        const Vec3& p = s.position[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
        const Vec3 d{p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]};
        return dot(d, d) <= ball.r2;
    };
    // The next pixel of the row within the ball beyond `from` in direction `step`,
    // stepping over pixels without a vertex, at most mx columns from the centre; -1.
    const auto next_inside = [&](int r, int from, int step) {
        for (int c = from + step; c >= 0 && c < cols && std::abs(c - lc) <= mx; c += step) {
            if (inside(r, c)) return c;
            const Vec3& p = s.position[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
            if (!std::isnan(p[0])) return -1;
        }
        return -1;
    };
    for (int dir = 1; dir >= -1; dir -= 2) {
        int guess = lc;
        for (int k = dir > 0 ? 0 : 1; k <= my; ++k) {
            const int dy = dir * k, r = lr + dy;
            int& lo = s.lo[std::size_t(dy + my)];
            int& hi = s.hi[std::size_t(dy + my)];
            if (r < 0 || r >= rows) {
                lo = 0, hi = -1;
                continue;
            }
            if (warm && lo <= hi) {
                if (inside(r, hi))
                    for (int c; (c = next_inside(r, hi, 1)) >= 0;) hi = c;
                else
                    while (hi >= lo && !inside(r, hi)) --hi;
                if (hi >= lo) {
                    if (inside(r, lo))
                        for (int c; (c = next_inside(r, lo, -1)) >= 0;) lo = c;
                    else
                        while (lo <= hi && !inside(r, lo)) ++lo;
                }
            } else {
                lo = 0, hi = -1;
            }
            if (lo > hi) {
                // Search next to where the row nearer the centre had its middle.
                for (int t : {0, -1, 1, -2, 2}) {
                    const int c = guess + t;
                    if (c >= 0 && c < cols && inside(r, c)) {
                        lo = hi = c;
                        for (int n; (n = next_inside(r, hi, 1)) >= 0;) hi = n;
                        for (int n; (n = next_inside(r, lo, -1)) >= 0;) lo = n;
                        break;
                    }
                }
            }
            if (lo > hi) {  // the ball ends here: the rows beyond are empty too
                for (int j = k + 1; j <= my; ++j) {
                    s.lo[std::size_t(dir * j + my)] = 0;
                    s.hi[std::size_t(dir * j + my)] = -1;
                }
                break;
            }
            guess = (lo + hi) / 2;
            // At the region's margin the ball may go on beyond it.
            const bool edge_left = lc - lo >= mx && (ball.g.seam || cc0 + lo > 0);
            const bool edge_right = hi - lc >= mx && (ball.g.seam || cc0 + hi < W - 1);
            const bool edge_row = k == my && (dir > 0 ? rr0 + r < H - 1 : rr0 + r > 0);
            if (edge_left || edge_right || edge_row) return false;
        }
    }
    return true;
}

// The moments about the region's reference of the pixels in the spans s.lo, s.hi around
// region row lr, from the rows' running sums.
void span_moments(const GridScratch& s, int cols, int lr, int my, double* moments) {
    for (int dy = -my; dy <= my; ++dy) {
        const int lo = s.lo[std::size_t(dy + my)], hi = s.hi[std::size_t(dy + my)];
        if (lo > hi) continue;
        const double* row_sums = &s.prefix[std::size_t(lr + dy) * std::size_t(cols + 1) * kMoments];
        const double* a = row_sums + std::size_t(lo) * kMoments;
        const double* b = row_sums + std::size_t(hi + 1) * kMoments;
        for (int k = 0; k < kMoments; ++k) moments[k] += b[k] - a[k];
    }
}

// The vertices of one tile of output pixels [c0, c0 + kTile) x [r0, r0 + kTile).
void grid_tile(const TriangleMesh& mesh, const GridLayout& g, const Normals& normals,
               const ShapeIndexOptions& options, int r0, int c0, GridScratch& s,
               std::size_t& mesh_fallbacks, const VertexFn& body) {
    const int r1 = std::min(g.height, r0 + kTile), c1 = std::min(g.width, c0 + kTile);
    const auto fallback = [&](std::int32_t v) {
        tile_fallback(mesh, v, normals[std::size_t(v)], options, nullptr, s, mesh_fallbacks, body);
    };
    const int mx = tile_reach(mesh, g, options.radius, r0, r1, c0, c1, 1, 0, s.spacing),
              my = tile_reach(mesh, g, options.radius, r0, r1, c0, c1, 0, 1, s.spacing);
    Region region;
    const auto status =
        region_sums<kMoments>(mesh, g, r0, r1, c0, c1, mx, my, true, s, region, monomials);
    if (status == RegionStatus::empty) return;
    if (status == RegionStatus::mesh_path)
        return g.for_each_vertex(r0, r1, c0, c1, [&](std::int32_t v, int, int) { fallback(v); });
    const BallInRegion ball{g, region, mx, my, options.radius * options.radius};
    const int offsets = 2 * my + 1;
    s.lo.assign(std::size_t(offsets), 0);
    s.hi.assign(std::size_t(offsets), -1);
    for (int row = r0; row < r1; ++row) {
        bool warm = false;  // the spans hold the previous pixel's window
        const int lr = row - region.rr0;
        for (int col = c0; col < c1; ++col) {
            const auto v = g.vertex_at(col, row);
            if (v < 0) {
                warm = false;
                continue;
            }
            const int lc = col - region.cc0;
            if (!ball_spans(ball, lr, lc, warm, s)) {
                fallback(v);
                warm = false;
                continue;
            }
            warm = true;
            double moments[kMoments] = {};  // about the reference, then about the vertex
            span_moments(s, region.cols, lr, my, moments);
            const Vec3 centre =
                s.position[std::size_t(lr) * std::size_t(region.cols) + std::size_t(lc)];
            fit_from_moments(moments, centre, region.ref, normals[std::size_t(v)], v, body);
        }
    }
}

// The normals the grid method reads, a band of pixel rows at a time where band_normals
// applies (24 bytes a vertex of the band, not of the mesh: a ladder of radii holds its fits'
// normals beside its own state), else the whole mesh's.
class GridNormals {
  public:
    GridNormals(const TriangleMesh& mesh, const ProgressFn& progress)
        : mesh_(mesh), by_bands_(normals_by_bands(mesh)) {
        if (!by_bands_) normals_.values = vertex_normals(mesh, progress);
    }
    // The normals of (at least) the vertices of pixel rows [r0, r1).
    const Normals& rows(int r0, int r1) {
        if (by_bands_) band_normals(mesh_, r0, r1, normals_);
        return normals_;
    }

  private:
    const TriangleMesh& mesh_;
    bool by_bands_;
    Normals normals_;
};

// The vertices no pixel of g owns (pinched copies, collapsed poles), by their pixel's row.
std::vector<std::int32_t> unowned_vertices(const TriangleMesh& mesh, const GridLayout& g) {
    std::vector<std::int32_t> unowned;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const auto p = std::size_t(mesh.vertex_pixel[v]);
        if (g.vertex_at(int(p % std::size_t(g.width)), int(p / std::size_t(g.width))) !=
            std::int32_t(v))
            unowned.push_back(std::int32_t(v));
    }
    std::stable_sort(unowned.begin(), unowned.end(), [&](std::int32_t a, std::int32_t b) {
        return mesh.vertex_pixel[std::size_t(a)] / g.width <
               mesh.vertex_pixel[std::size_t(b)] / g.width;
    });
    return unowned;
}

// Every vertex once through `body`, by tiles of pixels, a row of tiles at a time; vertices no
// pixel owns and windows the tiles cannot hold take the mesh path, the former after the
// tiles with the normals kept from their row's band.
std::size_t grid_for_each_vertex(const TriangleMesh& mesh, const GridLayout& g,
                                 const ShapeIndexOptions& options, GridNormals& normals,
                                 const ProgressFn& progress, const VertexFn& body) {
    const bool disk = disk_applies(mesh, options);
    const GridLayout* disk_grid = disk ? &g : nullptr;
    tbb::enumerable_thread_specific<GridScratch> scratch;
    tbb::enumerable_thread_specific<std::size_t> fallbacks(0);
    const int tile = disk ? g.disk_tile : kTile;
    const int tile_rows = (g.height + tile - 1) / tile, tile_cols = (g.width + tile - 1) / tile;
    // With the disk's sample stride (disk_tile fits only the lattice's pixels), of the vertices
    // no pixel owns only the poles (pinched copies share their pixel's sample with its owner).
    auto unowned = unowned_vertices(mesh, g);
    if (disk && options.sample_stride > 1)
        std::erase_if(unowned, [&](std::int32_t v) {
            return v != mesh.pole_vertices[0] && v != mesh.pole_vertices[1];
        });
    // (Rows of tiles with no row asked for are skipped, and vertices no pixel owns outside
    // them.)
    const auto asked = [&](int r0, int r1) {
        return r1 > options.first_row && r0 < options.end_row;
    };
    std::erase_if(unowned, [&](std::int32_t v) { return !row_asked(mesh, options, v); });
    std::vector<Vec3> unowned_normals(unowned.size());
    std::size_t next_unowned = 0;
    for (int tr = 0; tr < tile_rows; ++tr) {
        const int r0 = tr * tile, r1 = std::min(g.height, r0 + tile);
        if (!asked(r0, r1)) continue;
        const Normals& band = normals.rows(r0, r1);
        tbb::parallel_for(tbb::blocked_range<int>(0, tile_cols, 1), [&](const auto& r) {
            for (int tc = r.begin(); tc < r.end(); ++tc)
                (disk ? disk_tile : grid_tile)(mesh, g, band, options, r0, tc * tile,
                                               scratch.local(), fallbacks.local(), body);
        });
        for (; next_unowned < unowned.size() &&
               mesh.vertex_pixel[std::size_t(unowned[next_unowned])] / g.width < r1;
             ++next_unowned)
            unowned_normals[next_unowned] = band[std::size_t(unowned[next_unowned])];
        report_progress(progress, double(tr + 1) / tile_rows, "shape index");
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, unowned.size(), 64), [&](const auto& r) {
        auto& s = scratch.local();
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            const auto v = unowned[i];
            PrincipalCurvatures k;
            double scale = 0;
            const bool ok =
                mesh_fit(mesh, v, unowned_normals[i], options, disk_grid, s.mesh, k, scale);
            body(v, ok, k, scale);
        }
    });
    return fallbacks.combine(std::plus<>()) + unowned.size();
}

}  // namespace

void grid_method_for_each_vertex(const TriangleMesh& mesh, const ShapeIndexOptions& options,
                                 const ProgressFn& progress, const VertexFn& body) {
    GridNormals normals(mesh, scaled_progress(progress, 0, 0.05));
    const auto layout = grid_layout(mesh, options.disk_tile_angle);
    report_progress(progress, 0.06, "shape index");
    grid_for_each_vertex(mesh, layout, options, normals, scaled_progress(progress, 0.06, 1), body);
}

}  // namespace terrain::field::detail
