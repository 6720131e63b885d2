#include "terrain/mesh/dem_to_mesh.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/LocalCartesian.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>

#include "terrain/core/error.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"

namespace terrain::mesh {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
using detail::Triangle;

// The DEM's georeference, or an error saying how to get one.
const GridGeoref& georef_of(const Dem& dem) {
    if (!dem.georef_current())
        throw Error("mesh", "'" + dem.source +
                                "' has no georeference for its CRS and grid; read it with "
                                "io::read_dem or call geo::georeference(dem)");
    return dem.georef;
}

}  // namespace

MeshFrame default_frame(const Dem& dem) {
    if (dem.crs_wkt.empty()) return MeshFrame::map;
    if (dem.body.name == "Earth" && georef_of(dem).kind == CrsKind::projected)
        return MeshFrame::map;
    return MeshFrame::body;
}

namespace {

// Vertex numbering: valid pixels in row-major order; a collapsed pole row is one vertex.
// Returns each pixel's vertex (-1 for NoData) and fills the mesh's vertex -> pixel map and
// pole vertices. Each row's vertices are counted, then numbered from the count before the
// row, both on every thread: the numbers of one pass in order.
std::vector<std::int32_t> number_vertices(const Dem& dem, std::array<bool, 2> pole,
                                          TriangleMesh& mesh, const ProgressFn& progress) {
    const int W = dem.width, H = dem.height;
    const auto pole_of = [&](int row) {
        return row == 0 && pole[0] ? 0 : (row == H - 1 && pole[1] ? 1 : -1);
    };
    std::vector<std::int64_t> first(std::size_t(H) + 1, 0);
    detail::parallel_slices(
        H, 8, progress, 0, 0.3, "mesh", [&](const tbb::blocked_range<int>& rows) {
            for (int row = rows.begin(); row < rows.end(); ++row) {
                std::int64_t valid = 0;
                for (int col = 0; col < W; ++col) valid += dem.valid(col, row);
                first[std::size_t(row) + 1] = pole_of(row) >= 0 ? std::int64_t(valid > 0) : valid;
            }
        });
    std::partial_sum(first.begin(), first.end(), first.begin());
    const std::int64_t count = first.back();
    if (count < 3) throw Error("mesh", "'" + dem.source + "' has fewer than 3 valid pixels");
    if (count > std::int64_t{INT32_MAX})
        throw Error("mesh", "'" + dem.source + "' has more than 2^31 valid pixels: too large");
    std::vector<std::int32_t> vertex_of(dem.size());
    mesh.vertex_pixel.resize(std::size_t(count));
    detail::parallel_slices(
        H, 8, progress, 0.3, 1, "mesh", [&](const tbb::blocked_range<int>& rows) {
            for (int row = rows.begin(); row < rows.end(); ++row) {
                const auto own = static_cast<std::int32_t>(first[std::size_t(row)]);
                const bool collapsed = pole_of(row) >= 0;
                std::int32_t next = own;
                for (int col = 0; col < W; ++col) {
                    const auto p = dem.index(col, row);
                    if (!dem.valid(col, row)) {
                        vertex_of[p] = -1;
                    } else if (collapsed) {
                        if (next == own) mesh.vertex_pixel[std::size_t(next++)] = std::int32_t(p);
                        vertex_of[p] = own;
                    } else {
                        vertex_of[p] = next;
                        mesh.vertex_pixel[std::size_t(next++)] = std::int32_t(p);
                    }
                }
            }
        });
    for (int row : {0, H - 1}) {
        const int which = pole_of(row);
        if (which < 0 || first[std::size_t(row) + 1] == first[std::size_t(row)]) continue;
        mesh.pole_rows[std::size_t(which)] = row;
        mesh.pole_vertices[std::size_t(which)] = static_cast<std::int32_t>(first[std::size_t(row)]);
    }
    return vertex_of;
}

// Vertex positions in metres in the mesh's frame (docs/mesh.md, "Frames"): body-fixed X,Y,Z
// from lon/lat and the value (a radius along the geocentric direction, or a height on the
// ellipsoid); in the map frame easting/northing and height, or a local tangent plane for a
// lon/lat grid. dem_to_mesh places them once; restore_positions places them again, the same
// numbers, for a mesh that freed them (TriangleMesh::release_positions).
class VertexPlacer {
  public:
    // `heights`: the DEM's values, when not read from dem.values (restore_positions).
    VertexPlacer(const Dem& dem, const GridGeoref& geo, MeshFrame frame,
                 const float* heights = nullptr)
        : dem_(dem), heights_(heights), frame_(frame), unit_(geo.linear_unit_m) {
        const bool geographic_crs = geo.kind == CrsKind::geographic;
        const bool need_lonlat = frame == MeshFrame::body || geographic_crs;
        if (need_lonlat && !geographic_crs) {
            if (!geo.lonlat)
                throw Error("mesh",
                            "cannot transform the DEM's CRS to longitude/latitude on its body");
            lonlat_ = geo.lonlat.get();
        }
        if (need_lonlat)
            earth_ = std::make_unique<GeographicLib::Geocentric>(dem.body.semi_major_axis,
                                                                 dem.body.flattening);
        // Latitudes beyond the poles (a projected grid off its body) place nothing: half a
        // pixel of slack, as io::read_dem checks.
        if (need_lonlat && dem.body.semi_minor_axis() > 0) {
            const double step_y = std::hypot(dem.transform[2], dem.transform[5]);
            const double pixel_degrees =
                geographic_crs ? step_y : geo.pixel_height_m / dem.body.semi_minor_axis() / kDegree;
            max_latitude_ = 90 + 0.5 * pixel_degrees;
        }
        if (frame == MeshFrame::map && geographic_crs) {
            const auto centre = dem.map_xy(dem.width / 2.0, dem.height / 2.0);
            tangent_ =
                std::make_unique<GeographicLib::LocalCartesian>(centre[1], centre[0], 0.0, *earth_);
        }
    }

    // put(v, point) for each pixel whose vertex_of is a vertex v >= 0, rows in parallel (the
    // mapping keeps one PROJ transformation per thread), rows `skip[0]` and `skip[1]` left
    // out; the progress from `begin` to `end`. Throws when a pixel cannot be placed.
    template <class Put>
    void place_pixels(const std::vector<std::int32_t>& vertex_of, std::array<int, 2> skip,
                      const ProgressFn& progress, double begin, double end, Put&& put) const {
        const int W = dem_.width, H = dem_.height;
        std::vector<std::uint8_t> failed(static_cast<std::size_t>(H), 0);
        // Radii on a lon/lat grid whose columns are meridians and rows parallels (no
        // rotation terms): a column's longitude, and so its cosine and sine, is the same in
        // every row (x + row * 0 is x), and a row's latitude in every column; they are taken
        // once per column and once per row, the same numbers point() takes per pixel.
        const bool meridians = !lonlat_ && frame_ == MeshFrame::body &&
                               dem_.elevation == ElevationKind::radius && dem_.transform[2] == 0 &&
                               dem_.transform[4] == 0;
        detail::parallel_slices(
            H, 8, progress, begin, end, "mesh", [&](const tbb::blocked_range<int>& rows) {
                std::vector<double> lon(W), lat(W);
                std::vector<std::uint8_t> ok(W, 1);
                std::vector<double> cos_lon, sin_lon;
                for (int row = rows.begin(); row < rows.end(); ++row) {
                    if (row == skip[0] || row == skip[1]) continue;
                    for (int col = 0; col < W; ++col) {
                        const auto xy = dem_.map_xy(col + 0.5, row + 0.5);
                        lon[col] = xy[0];
                        lat[col] = xy[1];
                    }
                    if (lonlat_)
                        lonlat_->to_lonlat(std::size_t(W), lon.data(), lat.data(), ok.data());
                    if (meridians) {
                        if (cos_lon.empty()) {
                            cos_lon.resize(std::size_t(W));
                            sin_lon.resize(std::size_t(W));
                            for (int col = 0; col < W; ++col) {
                                cos_lon[std::size_t(col)] = std::cos(lon[col] * kDegree);
                                sin_lon[std::size_t(col)] = std::sin(lon[col] * kDegree);
                            }
                        }
                        place_radius_row(vertex_of, row, lon, lat, cos_lon, sin_lon, failed, put);
                        continue;
                    }
                    for (int col = 0; col < W; ++col) {
                        const auto p = dem_.index(col, row);
                        const auto v = vertex_of[p];
                        if (v < 0) continue;
                        if (!ok[col] || !on_body(lon[col], lat[col])) {
                            failed[row] = 1;
                            continue;
                        }
                        const auto xyz = point(col, row, lon[col], lat[col]);
                        if (!finite(xyz)) {
                            failed[row] = 1;
                            continue;
                        }
                        put(v, xyz);
                    }
                }
            });
        const auto bad = std::find(failed.begin(), failed.end(), 1);
        if (bad != failed.end())
            throw Error("mesh", "row " + std::to_string(bad - failed.begin()) + " of '" +
                                    dem_.source + "' has valid pixels that cannot be placed on " +
                                    dem_.body.name +
                                    " (outside the CRS's valid area, past the poles or with no "
                                    "finite position); check the CRS's radius, the "
                                    "geotransform (or the label's map projection) and the values");
    }

    // A collapsed pole row's vertex (0: north, 1: south): at the pole, at the mean radius
    // (height) of its row.
    std::array<double, 3> pole(int which, int row) const {
        double sum = 0;
        int n = 0;
        for (int col = 0; col < dem_.width; ++col)
            if (const double v = value(col, row); !std::isnan(v)) sum += v, ++n;
        const double value = sum / n, lat = which == 0 ? 90.0 : -90.0;
        std::array<double, 3> out;
        if (dem_.elevation == ElevationKind::radius)
            out = {0.0, 0.0, which == 0 ? value : -value};
        else
            earth_->Forward(lat, 0.0, value, out[0], out[1], out[2]);
        return out;
    }

  private:
    // The DEM's value at a pixel (as Dem::at), and its height (as Dem::height_at).
    double value(int col, int row) const {
        const std::size_t i = dem_.index(col, row);
        return heights_ ? static_cast<double>(heights_[i]) : dem_.values[i];
    }
    double height(int col, int row) const {
        const double v = value(col, row);
        return dem_.elevation == ElevationKind::radius ? v - dem_.body.semi_major_axis : v;
    }
    bool on_body(double lon, double lat) const {
        return std::isfinite(lon) && std::isfinite(lat) && std::abs(lat) <= max_latitude_;
    }
    static bool finite(const std::array<double, 3>& p) {
        return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
    }

    // Radii are distances from the centre along the geocentric direction.
    static std::array<double, 3> along_radius(double value, double cos_lat, double sin_lat,
                                              double cos_lon, double sin_lon) {
        return {value * cos_lat * cos_lon, value * cos_lat * sin_lon, value * sin_lat};
    }

    // point() for a row of radii whose longitudes' cosines and sines are known.
    template <class Put>
    void place_radius_row(const std::vector<std::int32_t>& vertex_of, int row,
                          const std::vector<double>& lon, const std::vector<double>& lat,
                          const std::vector<double>& cos_lon, const std::vector<double>& sin_lon,
                          std::vector<std::uint8_t>& failed, Put& put) const {
        const int W = dem_.width;
        const double cl = std::cos(lat[0] * kDegree), sl = std::sin(lat[0] * kDegree);
        for (int col = 0; col < W; ++col) {
            const auto v = vertex_of[dem_.index(col, row)];
            if (v < 0) continue;
            if (!on_body(lon[std::size_t(col)], lat[std::size_t(col)])) {
                failed[std::size_t(row)] = 1;
                continue;
            }
            const auto p = along_radius(value(col, row), cl, sl, cos_lon[std::size_t(col)],
                                        sin_lon[std::size_t(col)]);
            if (!finite(p)) {
                failed[std::size_t(row)] = 1;
                continue;
            }
            put(v, p);
        }
    }

    std::array<double, 3> point(int col, int row, double lon, double lat) const {
        const double v = value(col, row);
        std::array<double, 3> out;
        if (frame_ == MeshFrame::body) {
            if (dem_.elevation == ElevationKind::radius) {
                out = along_radius(v, std::cos(lat * kDegree), std::sin(lat * kDegree),
                                   std::cos(lon * kDegree), std::sin(lon * kDegree));
            } else {
                earth_->Forward(lat, lon, v, out[0], out[1], out[2]);
            }
        } else if (tangent_) {
            tangent_->Forward(lat, lon, height(col, row), out[0], out[1], out[2]);
        } else {
            out = {lon * unit_, lat * unit_, height(col, row)};
        }
        return out;
    }

    const Dem& dem_;
    const float* heights_;
    MeshFrame frame_;
    double unit_;
    const LonLatMapping* lonlat_ = nullptr;  // null: map coordinates are lon/lat already
    double max_latitude_ = std::numeric_limits<double>::infinity();  // map frame: no limit
    std::unique_ptr<GeographicLib::Geocentric> earth_;
    std::unique_ptr<GeographicLib::LocalCartesian> tangent_;
};

void place_vertices(const Dem& dem, const GridGeoref& geo,
                    const std::vector<std::int32_t>& vertex_of, TriangleMesh& mesh,
                    const ProgressFn& progress) {
    const VertexPlacer placer(dem, geo, mesh.frame);
    // The points' memory (0 to 0.35 of the progress), then the rows (to 0.9).
    std::vector<std::array<double, 3>> xyz;
    detail::assign_in_slices(xyz, mesh.vertex_pixel.size(), {},
                             detail::PassProgress(progress, 0, 0.35, "mesh"));
    placer.place_pixels(vertex_of, {-1, -1}, progress, 0.35, 0.9,
                        [&](std::int32_t v, const std::array<double, 3>& p) { xyz[v] = p; });
    for (int which = 0; which < 2; ++which)
        if (mesh.pole_rows[which] >= 0)
            xyz[mesh.pole_vertices[which]] = placer.pole(which, mesh.pole_rows[which]);
    set_positions(mesh, xyz, scaled_progress(progress, 0.9, 1));
}

// Two triangles per 2x2 block of valid pixels, one for three (grid_triangles.hpp); a closed
// seam adds the blocks between the last and the first column.
void triangulate_blocks(const Dem& dem, const std::vector<std::int32_t>& vertex_of,
                        TriangleMesh& mesh, const ProgressFn& progress) {
    const int W = dem.width, H = dem.height;
    const int block_rows = std::max(H - 1, 0);
    // Each block's diagonal is recorded (a bit, each row of blocks in its own words), so
    // that the triangles can be made again without the positions.
    const std::size_t words = detail::diagonal_words(W);
    mesh.block_diagonals.assign(static_cast<std::size_t>(block_rows) * words, 0);
    const auto row_top = [&](int row) { return vertex_of.data() + dem.index(0, row); };
    // Two passes over the rows of blocks, each in parallel: the first chooses the diagonals
    // and counts each row's triangles (0 to 0.6 of the progress), the second writes them at
    // their row's place in the one array, made again from the recorded diagonals (to 1). Rows
    // made apart and joined after were held beside the joined array (24 bytes a pixel more
    // at the mesh's peak: freed rows stay with the allocator).
    std::vector<std::size_t> offsets(static_cast<std::size_t>(block_rows) + 1, 0);
    detail::parallel_slices(block_rows, 16, progress, 0, 0.6, "mesh", [&](const auto& rows) {
        for (int row = rows.begin(); row < rows.end(); ++row) {
            std::uint64_t* bits = mesh.block_diagonals.data() + std::size_t(row) * words;
            const auto split = [&](int col, std::int32_t v00, std::int32_t v10, std::int32_t v01,
                                   std::int32_t v11) {
                const bool across = detail::split_top_right(mesh.positions(), v00, v10, v01, v11);
                if (across) bits[unsigned(col) / 64] |= std::uint64_t{1} << (unsigned(col) % 64);
                return across;
            };
            std::size_t count = 0;
            detail::block_row_triangles(row_top(row), row_top(row) + W, W, mesh.seam_closed,
                                        mesh.triangles_flipped, split,
                                        [&](const Triangle&) { ++count; });
            offsets[std::size_t(row) + 1] = count;
        }
    });
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    if (offsets.back() == 0)
        throw Error("mesh",
                    "'" + dem.source + "' gives no triangle: no 2x2 block has three valid pixels");
    detail::assign_in_slices(mesh.edit_triangles(), offsets.back(), Triangle{},
                             detail::PassProgress(progress, 0.6, 0.7, "mesh"));
    detail::parallel_slices(block_rows, 16, progress, 0.7, 1, "mesh", [&](const auto& rows) {
        for (int row = rows.begin(); row < rows.end(); ++row) {
            Triangle* out = mesh.edit_triangles().data() + offsets[std::size_t(row)];
            detail::block_row_triangles(row_top(row), row_top(row) + W, W, mesh.seam_closed,
                                        mesh.triangles_flipped, detail::recorded_split(mesh, row),
                                        [&](const Triangle& t) { *out++ = t; });
        }
    });
}

}  // namespace

TriangleMesh dem_to_mesh(const Dem& dem, const DemToMeshOptions& options,
                         const ProgressFn& progress) {
    const MeshFrame frame = options.frame.value_or(default_frame(dem));
    if (frame == MeshFrame::file) throw Error("mesh", "a DEM mesh is in the body or map frame");
    if (frame == MeshFrame::body && dem.crs_wkt.empty())
        throw Error("mesh", "'" + dem.source +
                                "' has no CRS, so it has no body to place it on; use --frame map");
    const GridGeoref& geo = georef_of(dem);

    TriangleMesh mesh;
    mesh.frame = frame;
    mesh.body = dem.body;
    mesh.crs_wkt = dem.crs_wkt;
    mesh.grid_width = dem.width;
    mesh.grid_height = dem.height;
    const auto& t = dem.transform;
    mesh.triangles_flipped = t[1] * t[5] - t[2] * t[4] > 0;
    // A global grid closes in the body frame: seam, and pole rows whose outer edge is a pole.
    std::array<bool, 2> pole{false, false};
    if (frame == MeshFrame::body && options.close_global && geo.global_longitude) {
        mesh.seam_closed = true;
        pole = geo.pole_row;
    }

    // Slices of the progress by the passes' measured cost on global grids.
    auto vertex_of = number_vertices(dem, pole, mesh, scaled_progress(progress, 0, 0.05));
    place_vertices(dem, geo, vertex_of, mesh, scaled_progress(progress, 0.05, 0.3));
    triangulate_blocks(dem, vertex_of, mesh, scaled_progress(progress, 0.3, 0.5));

    // Leave out valid pixels in no triangle (isolated, or only in degenerate blocks).
    mesh.isolated_vertices =
        remove_unreferenced_vertices(mesh, scaled_progress(progress, 0.5, 0.6));
    const auto before_split = static_cast<std::int32_t>(mesh.positions().size());
    // Only a vertex next to a missing pixel, or on the grid's first or last two rows or
    // columns (the grid's edge, the poles, the seam), can be pinched: the fan of a vertex
    // whose 8 neighbouring pixels are valid is the full disk of its four complete blocks, and
    // a split elsewhere never parts two triangles sharing an edge.
    const auto may_pinch = [&](std::size_t v) {
        const std::int32_t p = mesh.vertex_pixel[v];
        const int col = p % dem.width, row = p / dem.width;
        if (row < 2 || row >= dem.height - 2 || col < 1 || col >= dem.width - 1) return true;
        for (int r = row - 1; r <= row + 1; ++r)
            for (int c = col - 1; c <= col + 1; ++c)
                if (!dem.valid(c, r)) return true;
        return false;
    };
    mesh.pinched_vertices =
        split_pinched_vertices(mesh, nullptr, scaled_progress(progress, 0.6, 0.7), may_pinch);
    // The triangles naming a copy, which the grid alone would not make again.
    if (mesh.pinched_vertices > 0)
        for (std::size_t i = 0; i < mesh.triangles().size(); ++i) {
            const auto& c = mesh.triangles()[i];
            if (std::max({c[0], c[1], c[2]}) >= before_split)
                mesh.pinch_triangles.emplace_back(i, c);
        }
    mesh.edit_positions().shrink_to_fit();
    mesh.vertex_pixel.shrink_to_fit();
    // The pixels' vertices after those changes, in the same memory.
    fill_pixel_to_vertex(mesh, dem, vertex_of);
    mesh.pixel_vertex = std::move(vertex_of);
    // (24 bytes a pixel less at the mesh's peak, the end of its areas and adjacency.)
    if (options.release_triangles && mesh.pinched_vertices == 0 && dem.width >= 3)
        mesh.release_triangles();
    report_progress(progress, 0.7, "mesh");
    finish_grid_mesh(mesh, scaled_progress(progress, 0.7, 1));
    report_progress(progress, 1.0, "mesh");
    return mesh;
}

namespace {

void place_again(const Dem& dem, const float* heights, TriangleMesh& mesh,
                 const ProgressFn& progress) {
    if (!mesh.positions_released()) return;
    if (dem.width != mesh.grid_width || dem.height != mesh.grid_height)
        throw Error("mesh", "the positions are placed again from the DEM the mesh was made of");
    const VertexPlacer placer(dem, georef_of(dem), mesh.frame, heights);
    const std::size_t n = mesh.vertex_count();
    // The same points as dem_to_mesh's, less the same origin, as floats.
    std::vector<std::array<float, 3>> positions;
    detail::assign_in_slices(positions, n, {}, detail::PassProgress(progress, 0, 0.3, "mesh"));
    const auto& o = mesh.origin;
    const auto put = [&](std::int32_t v, const std::array<double, 3>& p) {
        for (int k = 0; k < 3; ++k) positions[std::size_t(v)][k] = static_cast<float>(p[k] - o[k]);
    };
    // Every pixel's vertex but the pole rows' (the pole is placed alone) ...
    placer.place_pixels(mesh.pixel_vertex, mesh.pole_rows, progress, 0.3, 0.9, put);
    for (int which = 0; which < 2; ++which)
        if (mesh.pole_rows[which] >= 0)
            put(mesh.pole_vertices[which], placer.pole(which, mesh.pole_rows[which]));
    // ... and a split pinch's copies where its first copy is (pixel_vertex names the first).
    const detail::PassProgress copies(progress, 0.9, 1, "mesh");
    for (std::size_t v = 0; v < n; ++v) {
        copies.at(v, n);
        const std::int32_t first = mesh.pixel_vertex[std::size_t(mesh.vertex_pixel[v])];
        if (first != std::int32_t(v))  // (a pole's pixel names the pole itself)
            positions[v] = positions[std::size_t(first)];
    }
    mesh.set_restored_positions(std::move(positions));
    report_progress(progress, 1.0, "mesh");
}

}  // namespace

void restore_positions(const Dem& dem, TriangleMesh& mesh, const ProgressFn& progress) {
    place_again(dem, nullptr, mesh, progress);
}

void restore_positions(const Dem& dem, const std::vector<float>& heights, TriangleMesh& mesh,
                       const ProgressFn& progress) {
    if (heights.size() != std::size_t(dem.width) * std::size_t(dem.height))
        throw Error("mesh", "the heights to place the positions from are not one a pixel");
    place_again(dem, heights.data(), mesh, progress);
}

void fill_pixel_to_vertex(const TriangleMesh& mesh, const Dem& dem,
                          std::vector<std::int32_t>& out) {
    out.assign(std::size_t(mesh.grid_width) * mesh.grid_height, -1);
    // Backwards, so that the first copy of a split pinch wins.
    for (std::size_t v = mesh.vertex_pixel.size(); v-- > 0;)
        out[mesh.vertex_pixel[v]] = std::int32_t(v);
    for (int which = 0; which < 2; ++which) {
        const int row = mesh.pole_rows[which];
        if (row < 0 || mesh.pole_vertices[which] < 0) continue;
        for (int col = 0; col < mesh.grid_width; ++col)
            if (dem.valid(col, row)) out[dem.index(col, row)] = mesh.pole_vertices[which];
    }
}

const std::vector<std::int32_t>& pixel_vertices(const TriangleMesh& mesh, const Dem& dem,
                                                std::vector<std::int32_t>& storage) {
    if (!mesh.pixel_vertex.empty()) return mesh.pixel_vertex;
    fill_pixel_to_vertex(mesh, dem, storage);
    return storage;
}

std::vector<std::int32_t> pixel_to_vertex(const TriangleMesh& mesh, const Dem& dem) {
    if (!mesh.pixel_vertex.empty()) return mesh.pixel_vertex;
    std::vector<std::int32_t> out;
    fill_pixel_to_vertex(mesh, dem, out);
    return out;
}

}  // namespace terrain::mesh
