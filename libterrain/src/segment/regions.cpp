#include "terrain/segment/regions.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "pixel_areas.hpp"
#include "terrain/core/error.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/mesh/grid_triangles.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

namespace terrain::segment {
namespace {

using Point = std::array<double, 3>;

Point midpoint(const Point& p, const Point& q) {
    return {(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2};
}

double distance(const Point& p, const Point& q) {
    return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
}

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (std::uint64_t{a} << 32) | b;
}

struct EdgeSums {
    double length = 0;
    std::size_t mesh_edges = 0;
};

void check_inputs(const TriangleMesh& mesh, const std::vector<float>& field,
                  const std::vector<std::uint32_t>& labels, std::uint32_t region_count,
                  const Dem* dem) {
    const std::size_t n = mesh.vertex_count();
    if (field.size() != n || labels.size() != n)
        throw Error("segment", "the field (" + std::to_string(field.size()) + ") and labels (" +
                                   std::to_string(labels.size()) +
                                   ") need one value per mesh vertex (" + std::to_string(n) + ")");
    for (std::size_t v = 0; v < n; ++v)
        if (labels[v] == 0 || labels[v] > region_count)
            throw Error("segment", "vertex " + std::to_string(v) + " has label " +
                                       std::to_string(labels[v]) + ", outside 1.." +
                                       std::to_string(region_count));
    if (dem && (mesh.vertex_pixel.size() != n || dem->width != mesh.grid_width ||
                dem->height != mesh.grid_height))
        throw Error("segment", "the mesh was not made from this DEM's grid");
}

// Vertices on the mesh's boundary: in a 2-manifold, fewer incident triangles than neighbours.
// (The triangles counted in bands of rows in parallel on a grid, the vertices in ranges.)
std::vector<std::uint8_t> mesh_boundary(const TriangleMesh& mesh, const ProgressFn& progress) {
    std::vector<std::int32_t> triangles(mesh.vertex_count(), 0);
    detail::for_each_triangle_by_bands(mesh, progress, 0, 0.7, "regions",
                                       [&](const std::array<std::int32_t, 3>& t) {
                                           for (auto v : t)
                                               ++triangles[static_cast<std::size_t>(v)];
                                       });
    std::vector<std::uint8_t> out(mesh.vertex_count(), 0);
    detail::parallel_slices(out.size(), std::size_t{1} << 14, progress, 0.7, 1.0, "regions",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t v = r.begin(); v < r.end(); ++v)
                                    out[v] =
                                        static_cast<std::size_t>(triangles[v]) != mesh.degree(v);
                            });
    return out;
}

// For each region the vertex with the largest BFS distance (in mesh edges, through the
// region) from the region's boundary: its cut edges and the mesh boundary. Ties: lowest index.
// The distances level by level, each level's vertices in parallel: a vertex reached from
// several takes the same distance (the first claim wins), so the distances, and the vertex
// chosen, are those of one BFS whatever the threads.
std::vector<std::int32_t> representative_vertices(const TriangleMesh& mesh,
                                                  const std::vector<std::uint32_t>& labels,
                                                  std::uint32_t region_count,
                                                  const ProgressFn& progress) {
    const std::size_t n = mesh.vertex_count();
    // Its passes: the boundary (0 to 0.2), the sources (to 0.3), the distances (to 0.9), the
    // deepest (to 1).
    const auto on_boundary = mesh_boundary(mesh, scaled_progress(progress, 0, 0.2));
    std::vector<std::int32_t> depth(n, -1);
    // Level 0: the sources; `level` holds a level's vertices, found chunk by chunk in order.
    constexpr std::size_t kGrain = std::size_t{1} << 12;
    std::vector<std::int32_t> level;
    // visit(first, end, out) over [0, count) in chunks, their finds joined in order; with
    // progress from `from` to `to` between slices (else one parallel loop: a level is short).
    const auto gather = [&](std::size_t count, const auto& visit, const ProgressFn& sliced,
                            double from, double to) {
        std::vector<std::vector<std::int32_t>> parts((count + kGrain - 1) / kGrain);
        detail::parallel_slices(parts.size(), std::size_t{1}, sliced, from, to, "regions",
                                [&](const tbb::blocked_range<std::size_t>& r) {
                                    for (std::size_t k = r.begin(); k < r.end(); ++k)
                                        visit(k * kGrain, std::min(count, (k + 1) * kGrain),
                                              parts[k]);
                                });
        std::size_t total = 0;
        for (const auto& p : parts) total += p.size();
        std::vector<std::int32_t> next;
        next.reserve(total);
        for (const auto& p : parts) next.insert(next.end(), p.begin(), p.end());
        return next;
    };
    level = gather(
        n,
        [&](std::size_t first, std::size_t end, std::vector<std::int32_t>& out) {
            for (std::size_t v = first; v < end; ++v) {
                bool source = on_boundary[v];
                const auto nb = mesh.neighbors_of(v);
                for (auto w = nb.begin(); !source && w != nb.end(); ++w)
                    source = labels[static_cast<std::size_t>(*w)] != labels[v];
                if (source) {
                    depth[v] = 0;
                    out.push_back(static_cast<std::int32_t>(v));
                }
            }
        },
        progress, 0.2, 0.3);
    std::size_t reached = level.size();
    for (std::int32_t d = 1; !level.empty(); ++d) {
        level = gather(
            level.size(),
            [&](std::size_t first, std::size_t end, std::vector<std::int32_t>& out) {
                for (std::size_t i = first; i < end; ++i) {
                    const auto v = static_cast<std::size_t>(level[i]);
                    for (const auto nb : mesh.neighbors_of(v)) {
                        const auto w = static_cast<std::size_t>(nb);
                        if (labels[w] != labels[v]) continue;
                        std::atomic_ref<std::int32_t> claim(depth[w]);
                        std::int32_t unset = -1;
                        if (claim.load(std::memory_order_relaxed) >= 0 ||
                            !claim.compare_exchange_strong(unset, d, std::memory_order_relaxed))
                            continue;
                        out.push_back(static_cast<std::int32_t>(w));
                    }
                }
            },
            {}, 0, 0);
        reached += level.size();
        report_progress(progress, 0.3 + 0.6 * double(reached) / double(std::max<std::size_t>(n, 1)),
                        "regions");
    }
    report_progress(progress, 0.9, "regions");
    const detail::PassProgress deepest(progress, 0.9, 1, "regions");
    std::vector<std::int32_t> best(region_count, -1);
    for (std::size_t v = 0; v < n; ++v) {
        deepest.at(v, n);
        auto& b = best[labels[v] - 1];
        if (b < 0 || depth[v] > depth[static_cast<std::size_t>(b)])
            b = static_cast<std::int32_t>(v);
    }
    return best;
}

// Boundary length and cut mesh edges per pair of labels (see RegionEdge). The cut edges are
// counted on every thread (whole numbers: any order gives the same counts). The lengths are
// sums of doubles, each pair's in triangle order: a DEM mesh whose rows of blocks can be made
// alone finds its triangles with corners in two or three regions on every thread, row by row,
// and the lengths are then added in the order of the rows, each row's in its order: the
// sums of one pass over the triangles.
std::unordered_map<std::uint64_t, EdgeSums> boundary_sums(const TriangleMesh& mesh,
                                                          const std::vector<std::uint32_t>& labels,
                                                          const ProgressFn& progress) {
    std::unordered_map<std::uint64_t, EdgeSums> sums;
    {
        tbb::enumerable_thread_specific<std::unordered_map<std::uint64_t, std::size_t>> cuts;
        detail::parallel_slices(mesh.vertex_count(), std::size_t{1} << 14, progress, 0, 0.5,
                                "regions", [&](const tbb::blocked_range<std::size_t>& r) {
                                    auto& mine = cuts.local();
                                    for (std::size_t v = r.begin(); v < r.end(); ++v)
                                        for (const auto nb : mesh.neighbors_of(v)) {
                                            const auto w = static_cast<std::size_t>(nb);
                                            if (w > v && labels[w] != labels[v])
                                                ++mine[pair_key(labels[v], labels[w])];
                                        }
                                });
        for (const auto& mine : cuts)
            for (const auto& [key, count] : mine) sums[key].mesh_edges += count;
    }
    const auto add = [&](const std::array<std::int32_t, 3>& t) {
        const std::uint32_t l[3] = {labels[std::size_t(t[0])], labels[std::size_t(t[1])],
                                    labels[std::size_t(t[2])]};
        if (l[0] == l[1] && l[1] == l[2]) return;
        const Point p[3] = {mesh.position(std::size_t(t[0])), mesh.position(std::size_t(t[1])),
                            mesh.position(std::size_t(t[2]))};
        // Edge k joins corners k and k+1.
        const Point mid[3] = {midpoint(p[0], p[1]), midpoint(p[1], p[2]), midpoint(p[2], p[0])};
        if (l[0] != l[1] && l[1] != l[2] && l[2] != l[0]) {
            const Point centre = {(p[0][0] + p[1][0] + p[2][0]) / 3,
                                  (p[0][1] + p[1][1] + p[2][1]) / 3,
                                  (p[0][2] + p[1][2] + p[2][2]) / 3};
            for (int k = 0; k < 3; ++k)
                sums[pair_key(l[k], l[(k + 1) % 3])].length += distance(centre, mid[k]);
            return;
        }
        // Two labels: the corner alone on its side is k; its two edges are k-1 and k.
        const int k = l[0] == l[1] ? 2 : (l[1] == l[2] ? 0 : 1);
        sums[pair_key(l[k], l[(k + 1) % 3])].length += distance(mid[(k + 2) % 3], mid[k]);
    };
    if (detail::rows_of_triangles(mesh) && mesh.grid_height > 1) {
        const int rows = mesh.grid_height - 1;
        std::vector<std::vector<std::array<std::int32_t, 3>>> crossing(
            static_cast<std::size_t>(rows));
        detail::parallel_slices(
            rows, 1, progress, 0.5, 0.95, "regions", [&](const tbb::blocked_range<int>& r) {
                for (int row = r.begin(); row < r.end(); ++row)
                    detail::for_each_row_triangle(mesh, row, [&](const auto& t) {
                        const auto a = labels[std::size_t(t[0])];
                        if (labels[std::size_t(t[1])] != a || labels[std::size_t(t[2])] != a)
                            crossing[std::size_t(row)].push_back(t);
                    });
            });
        const detail::PassProgress added(progress, 0.95, 1, "regions");
        for (int row = 0; row < rows; ++row) {
            added.at(std::size_t(row), std::size_t(rows));
            for (const auto& t : crossing[std::size_t(row)]) add(t);
        }
        return sums;
    }
    const detail::PassProgress by_triangle(progress, 0.5, 1, "regions");
    const std::size_t nt = mesh.triangle_count();
    detail::for_each_triangle(mesh, [&](std::size_t i, const std::array<std::int32_t, 3>& t) {
        by_triangle.at(i, nt);
        add(t);
    });
    return sums;
}

// Position of each region's representative vertex (see Region::point); on a DEM, of the
// first pixel of a region of pixels in no triangle (first_pixel, by region index).
void set_points(RegionGraph& graph, const TriangleMesh& mesh, const Dem* dem,
                const std::vector<std::size_t>& first_pixel) {
    if (!dem) {
        graph.point_frame = PointFrame::mesh;
        for (auto& r : graph.regions) r.point = mesh.position(std::size_t(r.representative_vertex));
        return;
    }
    std::vector<double> x, y;
    for (auto& r : graph.regions) {
        const auto pixel =
            r.representative_vertex >= 0
                ? std::size_t(mesh.vertex_pixel[std::size_t(r.representative_vertex)])
                : first_pixel[r.id - 1];
        const int col = int(pixel % std::size_t(dem->width)),
                  row = int(pixel / std::size_t(dem->width));
        const auto xy = dem->map_xy(col + 0.5, row + 0.5);
        x.push_back(xy[0]);
        y.push_back(xy[1]);
        r.point[2] = dem->height_at(col, row);
    }
    graph.point_frame = PointFrame::map;
    if (!dem->crs_wkt.empty()) {
        if (!dem->georef_current() || !dem->georef.output_lonlat)
            throw Error("segment",
                        "the DEM has no longitude/latitude on its body (no "
                        "georeference for its CRS and grid, or no transformation)");
        const LonLatMapping& frame = *dem->georef.output_lonlat;
        if (!frame.to_lonlat(x.size(), x.data(), y.data()))
            throw Error("segment", "a region's point has no longitude/latitude on the body");
        graph.point_frame = PointFrame::lonlat;
        graph.point_crs_wkt = frame.lonlat_crs_wkt();
    }
    for (std::size_t i = 0; i < graph.regions.size(); ++i) {
        graph.regions[i].point[0] = x[i];
        graph.regions[i].point[1] = y[i];
    }
}

// The 8 neighbours of pixel (col, row) that lie on the grid (columns wrap on a closed seam).
template <class F>
void for_each_neighbour(const Dem& dem, bool wrap, int col, int row, F&& f) {
    for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
            if (dr == 0 && dc == 0) continue;
            const int r = row + dr;
            int c = col + dc;
            if (r < 0 || r >= dem.height) continue;
            if (c < 0 || c >= dem.width) {
                if (!wrap) continue;
                c = (c + dem.width) % dem.width;
            }
            f(dem.index(c, r));
        }
}

// Valid pixels in no triangle (labelled 0 so far) get a label. Ring by ring outwards from the
// labelled pixels, each takes the most common label among its 8-neighbours labelled in an
// earlier ring (ties: the lowest); pixels no ring reaches form regions of their own, one per
// 8-connected group, numbered from first_new in row-major order of their first pixel.
void label_unmeshed_pixels(const Dem& dem, bool wrap, std::vector<std::uint32_t>& out,
                           std::uint32_t first_new) {
    std::vector<std::size_t> pending;
    for (std::size_t p = 0; p < out.size(); ++p)
        if (out[p] == 0 && !std::isnan(dem.values[p])) pending.push_back(p);
    if (pending.empty()) return;
    const auto col_of = [&](std::size_t p) { return int(p % std::size_t(dem.width)); };
    const auto row_of = [&](std::size_t p) { return int(p / std::size_t(dem.width)); };
    std::vector<std::uint8_t> queued(out.size(), 0);
    std::vector<std::size_t> ring;
    for (const auto p : pending) {
        bool touches = false;
        for_each_neighbour(dem, wrap, col_of(p), row_of(p),
                           [&](std::size_t q) { touches = touches || out[q] != 0; });
        if (touches) {
            ring.push_back(p);
            queued[p] = 1;
        }
    }
    std::vector<std::uint32_t> chosen;
    while (!ring.empty()) {
        chosen.assign(ring.size(), 0);
        for (std::size_t i = 0; i < ring.size(); ++i) {
            std::uint32_t label[8];
            int count[8], n = 0;
            for_each_neighbour(dem, wrap, col_of(ring[i]), row_of(ring[i]), [&](std::size_t q) {
                if (out[q] == 0) return;
                int k = 0;
                while (k < n && label[k] != out[q]) ++k;
                if (k == n) {
                    label[n] = out[q];
                    count[n++] = 0;
                }
                ++count[k];
            });
            int best = 0;
            for (int k = 1; k < n; ++k)
                if (count[k] > count[best] || (count[k] == count[best] && label[k] < label[best]))
                    best = k;
            chosen[i] = label[best];
        }
        std::vector<std::size_t> next;
        for (std::size_t i = 0; i < ring.size(); ++i) out[ring[i]] = chosen[i];
        for (const auto p : ring)
            for_each_neighbour(dem, wrap, col_of(p), row_of(p), [&](std::size_t q) {
                if (out[q] != 0 || queued[q] || std::isnan(dem.values[q])) return;
                queued[q] = 1;
                next.push_back(q);
            });
        std::sort(next.begin(), next.end());
        ring.swap(next);
    }
    // Groups out of reach of every labelled pixel.
    std::uint32_t id = first_new;
    std::vector<std::size_t> stack;
    for (const auto p : pending) {
        if (out[p] != 0) continue;
        out[p] = id;
        stack.assign(1, p);
        while (!stack.empty()) {
            const auto v = stack.back();
            stack.pop_back();
            for_each_neighbour(dem, wrap, col_of(v), row_of(v), [&](std::size_t q) {
                if (out[q] != 0 || std::isnan(dem.values[q])) return;
                out[q] = id;
                stack.push_back(q);
            });
        }
        ++id;
    }
}

}  // namespace

Landform landform_of(double shape_index) {
    // Bin edges at 100 (2k + 1) / 16: 6.25, 18.75, ..., 93.75.
    if (std::isnan(shape_index)) return Landform::unknown;
    const double s = std::clamp(shape_index, 0.0, 100.0);
    const int bin = static_cast<int>(std::floor((s * 16.0 / 100.0 + 1.0) / 2.0));
    return static_cast<Landform>(std::min(bin, 8));
}

double landform_centre(Landform landform) {
    if (landform == Landform::unknown) return std::numeric_limits<double>::quiet_NaN();
    const int k = static_cast<int>(landform);
    return k == 0 ? 3.125 : (k == 8 ? 96.875 : 12.5 * k);
}

const char* to_string(Landform landform) {
    static const char* const names[] = {"cup",          "trough", "rut",  "saddle rut", "saddle",
                                        "saddle ridge", "ridge",  "dome", "cap",        "unknown"};
    return names[static_cast<int>(landform)];
}

std::vector<std::uint32_t> label_pixels(const TriangleMesh& mesh, const Dem& dem,
                                        const std::vector<std::uint32_t>& labels,
                                        const ProgressFn& progress) {
    if (mesh.vertex_pixel.size() != mesh.vertex_count() || labels.size() != mesh.vertex_count() ||
        dem.width != mesh.grid_width || dem.height != mesh.grid_height)
        throw Error("segment", "labels, mesh and DEM grid do not match");
    std::vector<std::int32_t> storage;
    const auto& vertex = mesh::pixel_vertices(mesh, dem, storage);
    report_progress(progress, 0.2, "regions");
    std::vector<std::uint32_t> out;  // made a slice at a time: its first touch is slow
    detail::assign_in_slices(out, vertex.size(), std::uint32_t{0},
                             detail::PassProgress(progress, 0.2, 0.5, "regions"));
    const detail::PassProgress labelled(progress, 0.5, 0.8, "regions"),
        highest(progress, 0.8, 0.9, "regions");
    for (std::size_t p = 0; p < vertex.size(); ++p)
        if (labelled.at(p, vertex.size()); vertex[p] >= 0)
            out[p] = labels[static_cast<std::size_t>(vertex[p])];
    std::uint32_t top = 0;
    for (std::size_t v = 0; v < labels.size(); ++v) {
        highest.at(v, labels.size());
        top = std::max(top, labels[v]);
    }
    label_unmeshed_pixels(dem, mesh.seam_closed, out, top + 1);
    return out;
}

RegionGraph region_graph(const TriangleMesh& mesh, const std::vector<float>& field,
                         const std::vector<std::uint32_t>& labels, std::uint32_t region_count,
                         const Dem* dem, const ProgressFn& progress) {
    check_inputs(mesh, field, labels, region_count, dem);
    report_progress(progress, 0, "regions");
    // On a DEM, the regions of valid pixels in no triangle come after the vertices' regions.
    std::vector<std::uint32_t> pixels;
    std::uint32_t total = region_count;
    if (dem) {
        pixels = label_pixels(mesh, *dem, labels, scaled_progress(progress, 0, 0.2));
        for (const auto l : pixels) total = std::max(total, l);
    }
    report_progress(progress, 0.2, "regions");
    RegionGraph graph;
    graph.regions.resize(total);
    std::vector<double> weighted(region_count, 0.0), plain(region_count, 0.0);
    for (std::uint32_t i = 0; i < total; ++i) {
        graph.regions[i].id = i + 1;
        graph.regions[i].field_min = std::numeric_limits<double>::infinity();
        graph.regions[i].field_max = -std::numeric_limits<double>::infinity();
    }
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        auto& r = graph.regions[labels[v] - 1];
        const double f = field[v], a = mesh.vertex_areas[v];
        ++r.vertex_count;
        r.surface_area_m2 += a;
        weighted[labels[v] - 1] += a * f;
        plain[labels[v] - 1] += f;
        r.field_min = std::min(r.field_min, f);
        r.field_max = std::max(r.field_max, f);
    }
    for (std::uint32_t i = 0; i < region_count; ++i) {
        auto& r = graph.regions[i];
        if (r.vertex_count == 0)
            throw Error("segment", "region " + std::to_string(r.id) +
                                       " has no vertex; number the regions 1..N without gaps");
        r.field_mean = r.surface_area_m2 > 0 ? weighted[i] / r.surface_area_m2
                                             : plain[i] / double(r.vertex_count);
        r.landform = landform_of(r.field_mean);
        r.area_m2 = r.surface_area_m2;
    }

    report_progress(progress, 0.4, "regions");
    // Regions of pixels only: no vertex, no field (NaN), no mesh area.
    for (std::uint32_t i = region_count; i < total; ++i) {
        auto& r = graph.regions[i];
        r.field_mean = r.field_min = r.field_max = std::numeric_limits<double>::quiet_NaN();
        r.landform = landform_of(r.field_mean);
    }

    std::vector<std::size_t> first_pixel(total, 0);
    if (dem) {
        const PixelAreas pixel_area(*dem);
        for (auto& r : graph.regions) r.area_m2 = 0;
        for (int row = 0; row < dem->height; ++row)
            for (int col = 0; col < dem->width; ++col) {
                const auto l = pixels[dem->index(col, row)];
                if (l == 0) continue;
                auto& r = graph.regions[l - 1];
                if (r.pixel_count++ == 0) first_pixel[l - 1] = dem->index(col, row);
                r.area_m2 += pixel_area(col, row);
            }
        // (Not read again: 4 bytes a pixel less through the representatives and boundaries.)
        std::vector<std::uint32_t>().swap(pixels);
    }

    report_progress(progress, 0.5, "regions");
    const auto best =
        representative_vertices(mesh, labels, region_count, scaled_progress(progress, 0.5, 0.7));
    for (std::uint32_t i = 0; i < region_count; ++i)
        graph.regions[i].representative_vertex = best[i];
    set_points(graph, mesh, dem, first_pixel);

    report_progress(progress, 0.7, "regions");
    const auto sums = boundary_sums(mesh, labels, scaled_progress(progress, 0.7, 0.98));
    graph.edges.reserve(sums.size());
    for (const auto& [key, s] : sums) {
        RegionEdge e;
        e.a = static_cast<std::uint32_t>(key >> 32);
        e.b = static_cast<std::uint32_t>(key & 0xffffffffu);
        e.boundary_length_m = s.length;
        e.mesh_edges = s.mesh_edges;
        e.contrast =
            std::abs(graph.regions[e.a - 1].field_mean - graph.regions[e.b - 1].field_mean);
        graph.edges.push_back(e);
    }
    std::sort(graph.edges.begin(), graph.edges.end(), [](const RegionEdge& p, const RegionEdge& q) {
        return p.a != q.a ? p.a < q.a : p.b < q.b;
    });
    for (const auto& e : graph.edges) {
        ++graph.regions[e.a - 1].neighbor_count;
        ++graph.regions[e.b - 1].neighbor_count;
    }
    report_progress(progress, 1, "regions");
    return graph;
}

}  // namespace terrain::segment
