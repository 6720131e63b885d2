// The disk window of --radius on DEM meshes (docs/field.md, "The disk window"): its shape
// on the grid, its Monge fit, and its sums from per-tile summed-area tables.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "shape_index_fit.hpp"
#include "terrain/core/error.hpp"

namespace terrain::field::detail {
namespace {

constexpr double kMaxDiskPixels = 1 << 20;

// floor and ceil of |x| <= kMaxDiskPixels, without a call into libm.
int ifloor(double x) {
    const int i = int(x);
    return i - (x < i);
}
int iceil(double x) {
    const int i = int(x);
    return i + (x > i);
}

// The window {a x^2 + 2 b x y + c y^2 <= 1} of pixel offsets (x columns, y rows), in up to
// three bands of rows on each side of row 0, each band the ellipse's span at its middle row.
// A window up to three rows high on each side (radii under four pixels) is therefore the
// exact set of pixel centres in the ellipse: as wide as it is high, so that a small window
// weighs the two directions alike (a band's span taken elsewhere than on its own rows would
// make a two-pixel disk three columns by five rows, and its curvature across the columns
// three times as sensitive to pixel noise as along them).
// With `clip` > 0 the window is cut to `clip` rows and columns on each side (the grid
// method's tables hold no more).
DiskWindow ellipse_window(double a, double b, double c, int clip) {
    DiskWindow d;
    const double det = a * c - b * b;
    if (!(a > 0) || !(det > 0)) return d;
    const auto clamp = [](double x) { return std::clamp(x, -kMaxDiskPixels, kMaxDiskPixels); };
    // At row y the ellipse spans the columns -b y / a +- sqrt(a - det y^2) / a; its
    // half-height is sqrt(a / det). (The tolerance keeps a pixel centre on the ellipse in.)
    constexpr double kOnEdge = 1e-9;
    const double height = clamp(std::sqrt(a / det) * (1 + kOnEdge)), shear = -b / a;
    for (int side : {1, -1}) {
        int previous = side > 0 ? -1 : 0;  // the row 0 band is on the + side
        for (int k = 0; k < 3; ++k) {
            int hi = ifloor(height * (k + 1) / 3);
            if (clip > 0) hi = std::min(hi, clip);
            if (hi <= previous) continue;
            const double y = side * 0.5 * (previous + 1 + hi);
            const double centre = clamp(shear * y);
            const double half =
                clamp(std::sqrt(std::max(0.0, a - det * y * y)) / a) * (1 + kOnEdge);
            DiskWindow::Band band;
            band.row_lo = side > 0 ? previous + 1 : -hi;
            band.row_hi = side > 0 ? hi : -(previous + 1);
            band.col_lo = iceil(clamp(centre - half));
            band.col_hi = ifloor(clamp(centre + half));
            if (clip > 0)
                band.col_lo = std::max(band.col_lo, -clip),
                band.col_hi = std::min(band.col_hi, clip);
            previous = hi;
            if (band.col_lo > band.col_hi) continue;
            d.band[std::size_t(d.bands++)] = band;
            d.reach_x = std::max({d.reach_x, -band.col_lo, band.col_hi});
            d.reach_y = std::max(d.reach_y, hi);
        }
    }
    return d;
}

// The ground (horizontal: across `up`) offsets between pixel centres along columns and rows
// at vertex v; each from the vertices of the pixels on both sides (or one), or square to the
// other when neither has one.
struct GroundSpacing {
    Vec3 up{0, 0, 1}, col{0, 0, 0}, row{0, 0, 0};
    bool ok = false;
};

GroundSpacing ground_spacing(const TriangleMesh& mesh, const GridLayout& g, std::int32_t v,
                             const Vec3& up) {
    const auto pixel = mesh.vertex_pixel[std::size_t(v)];
    const int col = pixel % g.width, row = pixel / g.width;
    GroundSpacing out;
    out.up = up;
    const auto horizontal = [&](std::int32_t to, std::int32_t from, double share) {
        const Vec3 d = sub(mesh.positions()[std::size_t(to)], mesh.positions()[std::size_t(from)]);
        const double along = dot(d, up);
        return Vec3{(d[0] - along * up[0]) * share, (d[1] - along * up[1]) * share,
                    (d[2] - along * up[2]) * share};
    };
    const auto spacing = [&](int dc, int dr, Vec3& out_spacing) {
        const auto before = g.vertex_near(col - dc, row - dr),
                   after = g.vertex_near(col + dc, row + dr);
        if (before >= 0 && after >= 0)
            out_spacing = horizontal(after, before, 0.5);
        else if (after >= 0)
            out_spacing = horizontal(after, v, 1.0);
        else if (before >= 0)
            out_spacing = horizontal(v, before, 1.0);
        else
            return false;
        return true;
    };
    const bool has_col = spacing(1, 0, out.col), has_row = spacing(0, 1, out.row);
    // Columns run east and rows south on a north-up grid: col = up x row, row = col x up.
    if (has_col && !has_row) out.row = cross(out.col, up);
    if (has_row && !has_col) out.col = cross(up, out.row);
    out.ok = has_col || has_row;
    return out;
}

// The disk window of vertex v for a radius in metres (empty when no neighbouring pixel has
// a vertex). The tangent plane it is lifted onto is the window's: the slope between the
// pixels half the radius away on each side along columns and rows (clipped to the grid),
// which on rough terrain follows the ball's footprint better than the vertex's own normal.
// With `clip`, a window reaching beyond kMaxReach pixels (near the poles of a geographic
// grid, where a row's pixels are narrow) is cut to kMaxReach on each side.
DiskWindow vertex_disk(const TriangleMesh& mesh, const GridLayout& g, std::int32_t v,
                       const Vec3& normal, const Vec3& up, double radius, bool clip) {
    const auto s = ground_spacing(mesh, g, v, up);
    if (!s.ok) return {};
    const auto pixel = mesh.vertex_pixel[std::size_t(v)];
    const int col = pixel % g.width, row = pixel / g.width;
    // The rise along the ground offset `step` (pixels dc, dr) over the window's half-width.
    const auto rise = [&](const Vec3& spacing, int dc, int dr) -> std::optional<double> {
        const double length = std::sqrt(dot(spacing, spacing));
        if (!(length > 0)) return std::nullopt;
        const int k = int(std::clamp(0.5 * radius / length + 0.5, 1.0, 64.0));
        for (int j = k; j >= 1; --j) {
            const auto a = g.vertex_near(col - j * dc, row - j * dr),
                       b = g.vertex_near(col + j * dc, row + j * dr);
            if (a < 0 || b < 0) continue;
            const Vec3 d = sub(mesh.positions()[std::size_t(b)], mesh.positions()[std::size_t(a)]);
            return dot(d, s.up) / (2.0 * j);
        }
        return std::nullopt;
    };
    // The vertical rise per pixel step along columns and rows; the vertex normal's where the
    // pixels on both sides are missing.
    const double nup = std::max(0.2, dot(normal, s.up));
    const double uc = rise(s.col, 1, 0).value_or(-dot(normal, s.col) / nup);
    const double ur = rise(s.row, 0, 1).value_or(-dot(normal, s.row) / nup);
    const double r2 = radius * radius;
    return ellipse_window((dot(s.col, s.col) + uc * uc) / r2, (dot(s.col, s.row) + uc * ur) / r2,
                          (dot(s.row, s.row) + ur * ur) / r2, clip ? kMaxReach : 0);
}

// The disk neighbourhood of v on the mesh: the vertices whose pixels are in its window (a
// global grid's columns wrap), reached through vertices whose pixels are.
void gather_disk(const TriangleMesh& mesh, const GridLayout& g, std::int32_t v,
                 const DiskWindow& disk, Scratch& s) {
    const int W = g.width;
    const auto pv = mesh.vertex_pixel[std::size_t(v)];
    const int cv = pv % W, rv = pv / W;
    gather_where(
        mesh, v, -1,
        [&](std::int32_t w) {
            const auto pw = mesh.vertex_pixel[std::size_t(w)];
            int dc = pw % W - cv;
            if (g.seam) {
                dc = ((dc % W) + W) % W;
                if (dc > W / 2) dc -= W;
            }
            return disk.contains(dc, pw / W - rv);
        },
        s);
}

// ---------------------------------------------------------------------------------------------
// The disk window's fit. A DEM is a graph over its grid, so with the disk window the fit is
// the Monge patch h = a u^2 + b uv + c v^2 + d u + e v of the vertex's neighbours over the
// horizontal plane of its tile's frame (u, v across the vertical `up` of the tile's first
// vertex, h along it; offsets from the vertex); the principal curvatures come from the same
// fundamental forms. Its normal equations need 22 moments: sum u^i v^j (i + j <= 4),
// sum h u^i v^j (i + j <= 2) and sum h^2 (for the neighbours' mean distance). Unlike the
// tangent frame's 35, they need no turning into each vertex's own frame.
struct MongeFrame {
    Vec3 e1{1, 0, 0}, e2{0, 1, 0}, up{0, 0, 1};
};

constexpr int kMonge = 22;

// Index of sum u^i v^j (i + j <= 4) and of sum h u^i v^j (i + j <= 2), and of sum h^2.
constexpr int uv_index(int i, int j) {
    const int d = i + j;
    return d * (d + 1) / 2 + j;
}
constexpr int huv_index(int i, int j) {
    return 15 + uv_index(i, j);
}
constexpr int kHH = 21;

// The tile frame of the tile holding pixel (col, row): its up is the body's radial direction
// (the z axis in a map frame) at the tile's first vertex.
MongeFrame tile_frame(const TriangleMesh& mesh, const GridLayout& g, int col, int row) {
    MongeFrame f;
    if (mesh.frame != MeshFrame::body) return f;
    const int t = g.disk_tile;
    const int r0 = row / t * t, c0 = col / t * t;
    const int r1 = std::min(g.height, r0 + t), c1 = std::min(g.width, c0 + t);
    for (int r = r0; r < r1; ++r)
        for (int c = c0; c < c1; ++c)
            if (const auto v = g.vertex_at(c, r); v >= 0) {
                const auto& p = mesh.positions()[std::size_t(v)];
                f.up = normalized(
                    {mesh.origin[0] + p[0], mesh.origin[1] + p[1], mesh.origin[2] + p[2]});
                const auto [t1, t2] = tangent_frame(f.up);
                f.e1 = t1, f.e2 = t2;
                return f;
            }
    return f;
}

// The 22 monomials of the offset d in the frame.
void monge_monomials(const MongeFrame& f, const Vec3& d, double* out) {
    const double u = dot(d, f.e1), v = dot(d, f.e2), h = dot(d, f.up);
    const double pu[5] = {1, u, u * u, u * u * u, u * u * u * u};
    const double pv[5] = {1, v, v * v, v * v * v, v * v * v * v};
#pragma GCC unroll 5
    for (int deg = 0; deg <= 4; ++deg)
#pragma GCC unroll 5
        for (int j = 0; j <= deg; ++j) out[uv_index(deg - j, j)] = pu[deg - j] * pv[j];
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) out[15 + k] = h * out[k];
    out[kHH] = h * h;
}

// The Taylor shift of the moments by (u0, v0) (ShiftStep): u then v, for the 15 sum u^i v^j
// (n = 4 - the other exponent) and the 6 sum h u^i v^j (n = 2 - the other exponent), 48
// steps in all.
constexpr int kMongeSteps = 48;
constexpr std::array<ShiftStep, kMongeSteps> kMongeShift = [] {
    std::array<ShiftStep, kMongeSteps> steps{};
    int k = 0;
    for (int axis = 0; axis < 2; ++axis)
        for (int group = 0; group < 2; ++group) {
            const int top = group == 0 ? 4 : 2;
            const auto at = [&](int e, int other) {
                const int i = axis == 0 ? e : other, j = axis == 0 ? other : e;
                return group == 0 ? uv_index(i, j) : huv_index(i, j);
            };
            for (int other = 0; other <= top; ++other) {
                const int n = top - other;
                for (int step = 1; step <= n; ++step)
                    for (int e = n; e >= step; --e)
                        steps[std::size_t(k++)] = {std::uint8_t(axis), std::uint8_t(at(e, other)),
                                                   std::uint8_t(at(e - 1, other))};
            }
        }
    return steps;
}();

// Moves moments about the tile's reference to moments about the vertex at offset (u0, v0,
// h0) from it.
void monge_shift(double* m, double u0, double v0, double h0) {
    const double t[2] = {u0, v0};
    apply_shift(kMongeShift, t, m);
    // sum (h - h0)^2 and sum (h - h0) u^i v^j.
    m[kHH] += h0 * (h0 * m[uv_index(0, 0)] - 2 * m[huv_index(0, 0)]);
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) m[15 + k] -= h0 * m[k];
}

// The normal equations of the Monge fit from the moments about the vertex.
NormalEquations monge_equations(const double* m) {
    NormalEquations e;
    auto& a = e.ata;
    a[0][0] = m[uv_index(4, 0)];
    a[1][0] = m[uv_index(3, 1)], a[1][1] = m[uv_index(2, 2)];
    a[2][0] = m[uv_index(2, 2)], a[2][1] = m[uv_index(1, 3)], a[2][2] = m[uv_index(0, 4)];
    a[3][0] = m[uv_index(3, 0)], a[3][1] = m[uv_index(2, 1)], a[3][2] = m[uv_index(1, 2)],
    a[3][3] = m[uv_index(2, 0)];
    a[4][0] = m[uv_index(2, 1)], a[4][1] = m[uv_index(1, 2)], a[4][2] = m[uv_index(0, 3)],
    a[4][3] = m[uv_index(1, 1)], a[4][4] = m[uv_index(0, 2)];
    e.atb = {m[huv_index(2, 0)], m[huv_index(1, 1)], m[huv_index(0, 2)], m[huv_index(1, 0)],
             m[huv_index(0, 1)]};
    const double count = m[0] - 1;  // the vertex itself is in its window, at d = 0
    e.m = count > 0 ? std::size_t(std::llround(count)) : 0;
    // The mean neighbour distance, as the grid method of the ball takes it.
    const double sum2 = m[uv_index(2, 0)] + m[uv_index(0, 2)] + m[kHH];
    e.scale =
        count > 0 ? std::sqrt(std::max(0.0, sum2) / count) * (2 * std::numbers::sqrt2 / 3) : 0.0;
    return e;
}

}  // namespace

// The disk window of v in its tile's frame, gathered on the mesh, and its Monge fit.
bool disk_mesh_fit(const TriangleMesh& mesh, const GridLayout& g, std::int32_t v,
                   const Vec3& normal, double radius, bool clip, Scratch& s, PrincipalCurvatures& k,
                   double& scale) {
    const auto pixel = mesh.vertex_pixel[std::size_t(v)];
    const auto frame = tile_frame(mesh, g, pixel % g.width, pixel / g.width);
    gather_disk(mesh, g, v, vertex_disk(mesh, g, v, normal, frame.up, radius, clip), s);
    double m[kMonge] = {};
    double mono[kMonge];
    const auto& centre = mesh.positions()[std::size_t(v)];
    for (const auto w : s.gathered) {
        monge_monomials(frame, sub(mesh.positions()[std::size_t(w)], centre), mono);
        for (int i = 0; i < kMonge; ++i) m[i] += mono[i];
    }
    const auto e = monge_equations(m);
    scale = e.scale;
    return solve_curvatures(e, k);
}

double typical_disk_reach(const TriangleMesh& mesh, double radius) {
    const int w = mesh.grid_width, h = mesh.grid_height;
    const std::size_t pixels = std::size_t(std::max(w, 0)) * std::size_t(std::max(h, 0));
    if (pixels == 0 || mesh.pixel_vertex.size() != pixels) return 0;
    const bool weighted = mesh.vertex_areas.size() == mesh.vertex_count();
    constexpr std::size_t kSamples = 4096;
    const std::size_t stride = std::max<std::size_t>(1, pixels / kSamples);
    // The vertical at a vertex: radial on the body, the map's z on a map.
    const auto up_at = [&](std::int32_t v) -> Vec3 {
        if (mesh.frame != MeshFrame::body) return {0, 0, 1};
        const auto& p = mesh.positions()[std::size_t(v)];
        return normalized({mesh.origin[0] + p[0], mesh.origin[1] + p[1], mesh.origin[2] + p[2]});
    };
    // (ground distance, area of the vertex it starts at): between neighbouring columns, rows.
    // On the ground, as a flat vertex's window counts its pixels: slopes lengthen the
    // distances between neighbours, not the pixels' spacing across the ground.
    std::vector<std::pair<double, double>> along[2];
    for (std::size_t i = 0; i < pixels; i += stride) {
        const auto v = mesh.pixel_vertex[i];
        if (v < 0) continue;
        const double area = weighted ? double(mesh.vertex_areas[std::size_t(v)]) : 1.0;
        if (!(area > 0)) continue;
        const int col = int(i % std::size_t(w)), row = int(i / std::size_t(w));
        const std::int32_t next[2] = {col + 1 < w ? mesh.pixel_vertex[i + 1] : -1,
                                      row + 1 < h ? mesh.pixel_vertex[i + std::size_t(w)] : -1};
        const Vec3 up = up_at(v);
        for (int axis = 0; axis < 2; ++axis)
            if (next[axis] >= 0) {
                const Vec3 d = sub(mesh.positions()[std::size_t(next[axis])],
                                   mesh.positions()[std::size_t(v)]);
                const double rise = dot(d, up);
                along[axis].emplace_back(std::sqrt(std::max(0.0, dot(d, d) - rise * rise)), area);
            }
    }
    // The median by area: the spacing at a typical place of the surface (a geographic grid's
    // many narrow polar pixels hold little of it).
    double finest = 0;
    for (auto& distances : along) {
        if (distances.empty()) continue;
        std::sort(distances.begin(), distances.end());
        double total = 0;
        for (const auto& d : distances) total += d.second;
        double below = 0, mid = distances.back().first;
        for (const auto& d : distances)
            if ((below += d.second) >= 0.5 * total) {
                mid = d.first;
                break;
            }
        if (mid > 0 && (finest == 0 || mid < finest)) finest = mid;
    }
    return finest > 0 ? radius / finest : 0.0;
}

void check_window_reach(const TriangleMesh& mesh, double radius, const char* name) {
    const double reach = typical_disk_reach(mesh, radius);
    if (!(reach > kMaxReach)) return;
    const auto metres = [](double x) {
        char text[32];
        std::snprintf(text, sizeof text, "%.0f", x);
        return std::string(text);
    };
    throw Error("field", std::string(name) + " " + metres(radius) + " m reaches " + metres(reach) +
                             " pixels of this DEM; the window's tables reach at "
                             "most " +
                             std::to_string(kMaxReach) + ": give at most " +
                             metres(radius * kMaxReach / reach) +
                             " m, or a DEM averaged to coarser pixels (gdalwarp -tr)");
}

// The vertices of one tile of output pixels [c0, c0 + t) x [r0, r0 + t), t = g.disk_tile,
// with the disk window: the region's row sums of the 22 Monge moments are summed down the rows too
// (summed-area tables), so that each of a window's six bands costs four look-ups whatever
// its size.
void disk_tile(const TriangleMesh& mesh, const GridLayout& g, const Normals& normals,
               const ShapeIndexOptions& options, int r0, int c0, GridScratch& s,
               std::size_t& mesh_fallbacks, const VertexFn& body) {
    const int W = g.width, H = g.height;
    const int tile = g.disk_tile;
    const int r1 = std::min(H, r0 + tile), c1 = std::min(W, c0 + tile);
    const auto fallback = [&](std::int32_t v) {
        tile_fallback(mesh, v, normals[std::size_t(v)], options, &g, s, mesh_fallbacks, body);
    };
    const auto frame = tile_frame(mesh, g, c0, r0);
    // Each vertex's window, and the margins the windows the tables can hold need.
    s.disks.resize(std::size_t(tile) * std::size_t(tile));  // set below where a vertex is
    const auto disk_of = [&](int col, int row) -> DiskWindow& {
        return s.disks[std::size_t(row - r0) * std::size_t(tile) + std::size_t(col - c0)];
    };
    // With a sample stride, only the sampled pixels' vertices.
    const int sample_stride = options.sample_stride;
    const auto for_each_fitted = [&](auto&& f) {
        g.for_each_vertex(r0, r1, c0, c1, [&](std::int32_t v, int col, int row) {
            if (sample_stride <= 1 || sampled_pixel(col, row, sample_stride, W, H)) f(v, col, row);
        });
    };
    int mx = 0, my = 0;
    for_each_fitted([&](std::int32_t v, int col, int row) {
        auto& d = disk_of(col, row) = vertex_disk(mesh, g, v, normals[std::size_t(v)], frame.up,
                                                  options.radius, !options.skip_wide);
        // Above the ladder's first rung a window a little past the tables (where a tile's
        // pixels narrow away from the place its ladder's top was sized at) is cut to them, as
        // the first rung's windows are; one further past is skipped.
        if (options.skip_wide && std::max(d.reach_x, d.reach_y) > kMaxReach &&
            std::max(d.reach_x, d.reach_y) <= kNearReach)
            d = vertex_disk(mesh, g, v, normals[std::size_t(v)], frame.up, options.radius, true);
        if (d.reach_x <= kMaxReach && d.reach_y <= kMaxReach)
            mx = std::max(mx, d.reach_x), my = std::max(my, d.reach_y);
    });
    Region region;
    const auto status =
        region_sums<kMonge>(mesh, g, r0, r1, c0, c1, mx, my, false, s, region,
                            [&](const Vec3& d, double* out) { monge_monomials(frame, d, out); });
    if (status == RegionStatus::empty) return;
    if (status == RegionStatus::mesh_path)
        return for_each_fitted([&](std::int32_t v, int, int) { fallback(v); });
    const int rows = region.rows, cols = region.cols;
    const std::size_t stride = std::size_t(cols + 1) * kMonge;
    for (int lr = 1; lr < rows; ++lr) {
        const double* above = &s.prefix[std::size_t(lr - 1) * stride];
        double* here = &s.prefix[std::size_t(lr) * stride];
        for (std::size_t k = 0; k < stride; ++k) here[k] += above[k];
    }
    // Adds the sums over rows [ra, rb] and columns [ca, cb] of the region (clipped to it).
    const auto add_rectangle = [&](double* moments, int ra, int rb, int ca, int cb) {
        ra = std::max(ra, 0), rb = std::min(rb, rows - 1);
        ca = std::max(ca, 0), cb = std::min(cb, cols - 1);
        if (ra > rb || ca > cb) return;
        const double* b0 = &s.prefix[std::size_t(rb) * stride + std::size_t(ca) * kMonge];
        const double* b1 = &s.prefix[std::size_t(rb) * stride + std::size_t(cb + 1) * kMonge];
        if (ra == 0) {
            for (int k = 0; k < kMonge; ++k) moments[k] += b1[k] - b0[k];
            return;
        }
        const double* a0 = &s.prefix[std::size_t(ra - 1) * stride + std::size_t(ca) * kMonge];
        const double* a1 = &s.prefix[std::size_t(ra - 1) * stride + std::size_t(cb + 1) * kMonge];
        for (int k = 0; k < kMonge; ++k) moments[k] += (b1[k] - b0[k]) - (a1[k] - a0[k]);
    };
    for_each_fitted([&](std::int32_t v, int col, int row) {
        const DiskWindow& d = disk_of(col, row);
        // Beyond the margins (a window wider than kMaxReach): the mesh path.
        if (d.reach_x > mx || d.reach_y > my) return fallback(v);
        const int lr = row - region.rr0, lc = col - region.cc0;
        double moments[kMonge] = {};
        for (int k = 0; k < d.bands; ++k) {
            const auto& b = d.band[std::size_t(k)];
            add_rectangle(moments, lr + b.row_lo, lr + b.row_hi, lc + b.col_lo, lc + b.col_hi);
        }
        const auto& p = mesh.positions()[std::size_t(v)];
        const Vec3 t{p[0] - region.ref[0], p[1] - region.ref[1], p[2] - region.ref[2]};
        monge_shift(moments, dot(t, frame.e1), dot(t, frame.e2), dot(t, frame.up));
        PrincipalCurvatures k;
        const auto equations = monge_equations(moments);
        const bool fitted = solve_curvatures(equations, k);
        body(v, fitted, k, equations.scale);
    });
}

}  // namespace terrain::field::detail
