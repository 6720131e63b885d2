// The Shape Diameter Function. Our computation follows CGAL's Surface_mesh_segmentation step
// by step (SDF_calculation.h: cone of rays around the inward normal from each face's centroid,
// Vogel disk samples, first hit through the inside, median/MAD outlier removal; then
// Surface_mesh_segmentation.h's post-processing: missing values from neighbours, bilateral
// filtering) with our own BVH and threads. CGAL itself is not compiled here: the reference
// the tests compare with is tests/support/cgal_reference_sdf.cpp.
#include "terrain/field/sdf.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>

#include "terrain/core/error.hpp"
#include "triangle_bvh.hpp"

namespace terrain::field {
namespace {

using detail::cross;
using detail::dot;
using detail::sub;
using detail::TriangleBvh;
using detail::Vec3;
using Face = std::array<std::int32_t, 3>;

constexpr double kMissing = -1.0;  // CGAL's mark for a face without a value
// CGAL_NUMBER_OF_MAD: rays further than this many median absolute deviations from the
// median distance are outliers.
constexpr double kOutlierMads = 1.5;
// A face whose doubled area is below this fraction of its longest edge squared has no
// reliable normal: it is degenerate (CGAL tests exact collinearity).
constexpr double kDegenerateRatio = 1e-12;

Vec3 scaled(const Vec3& a, double s) {
    return {a[0] * s, a[1] * s, a[2] * s};
}
Vec3 normalised(const Vec3& a) {
    return scaled(a, 1.0 / std::sqrt(dot(a, a)));
}

// What the SDF needs to know about the faces before casting rays.
struct FaceData {
    std::vector<Vec3> points;             // vertex positions relative to the mesh origin
    std::vector<double> twice_area;       // 0 for degenerate faces
    std::vector<char> degenerate;         // no rays: repeated vertex, zero area, not finite
    std::vector<char> repeated;           // a vertex repeats: outside the edge topology
    std::vector<std::int32_t> ray_faces;  // the others: the BVH's triangles
};

FaceData face_data(const TriangleMesh& mesh) {
    FaceData d;
    const std::size_t n = mesh.vertex_count(), f = mesh.triangle_count();
    d.points.resize(n);
    for (std::size_t v = 0; v < n; ++v)
        for (int k = 0; k < 3; ++k) d.points[v][k] = mesh.positions()[v][k];
    d.twice_area.assign(f, 0.0);
    d.degenerate.assign(f, 0);
    d.repeated.assign(f, 0);
    for (std::size_t i = 0; i < f; ++i) {
        const Face& t = mesh.triangles()[i];
        for (int k = 0; k < 3; ++k)
            if (t[k] < 0 || static_cast<std::size_t>(t[k]) >= n)
                throw Error("sdf", "face " + std::to_string(i) + " refers to vertex " +
                                       std::to_string(t[k]) + ", which does not exist");
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
            d.degenerate[i] = d.repeated[i] = 1;
            continue;
        }
        const Vec3 &a = d.points[t[0]], &b = d.points[t[1]], &c = d.points[t[2]];
        const Vec3 ab = sub(b, a), bc = sub(c, b), ca = sub(a, c);
        const double longest = std::max({dot(ab, ab), dot(bc, bc), dot(ca, ca)});
        const Vec3 normal = cross(ab, sub(c, a));
        const double area2 = std::sqrt(dot(normal, normal));
        if (!std::isfinite(area2) || !std::isfinite(longest) ||
            area2 <= kDegenerateRatio * longest) {
            d.degenerate[i] = 1;
            continue;
        }
        d.twice_area[i] = area2;
        d.ray_faces.push_back(static_cast<std::int32_t>(i));
    }
    return d;
}

// The face across each edge (corner k: the edge from vertex k to k+1), -1 for none, and
// the edges the SDF cannot live with.
struct Adjacency {
    std::vector<Face> across;
    std::size_t boundary_edges = 0, nonmanifold_edges = 0;
};

Adjacency face_adjacency(const TriangleMesh& mesh, const FaceData& d) {
    struct Edge {
        std::int32_t lo, hi, face, corner;
        bool operator<(const Edge& o) const {
            return std::tie(lo, hi, face, corner) < std::tie(o.lo, o.hi, o.face, o.corner);
        }
    };
    std::vector<Edge> edges;
    edges.reserve(3 * mesh.triangle_count());
    for (std::size_t i = 0; i < mesh.triangle_count(); ++i) {
        if (d.repeated[i]) continue;
        const Face& t = mesh.triangles()[i];
        for (int k = 0; k < 3; ++k) {
            const auto [lo, hi] = std::minmax(t[k], t[(k + 1) % 3]);
            edges.push_back({lo, hi, static_cast<std::int32_t>(i), k});
        }
    }
    tbb::parallel_sort(edges.begin(), edges.end());  // keys are unique: same order always
    Adjacency adj;
    adj.across.assign(mesh.triangle_count(), Face{-1, -1, -1});
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i + 1;
        while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
        if (j - i == 1) {
            ++adj.boundary_edges;
        } else if (j - i == 2) {
            adj.across[edges[i].face][edges[i].corner] = edges[i + 1].face;
            adj.across[edges[i + 1].face][edges[i + 1].corner] = edges[i].face;
        } else {
            ++adj.nonmanifold_edges;
        }
        i = j;
    }
    return adj;
}

// Six times the signed volume enclosed by the faces (positive when they face outwards).
double signed_volume6(const TriangleMesh& mesh, const FaceData& d) {
    double sum = 0;
    for (const std::int32_t f : d.ray_faces) {
        const Face& t = mesh.triangles()[f];
        sum += dot(d.points[t[0]], cross(d.points[t[1]], d.points[t[2]]));
    }
    return sum;
}

// CGAL's Vogel_disk_sampling (not uniform): sample i at radius i/n, angle i (3 - sqrt 5) pi.
std::vector<std::pair<double, double>> disk_samples(int rays) {
    std::vector<std::pair<double, double>> out(rays);
    const double golden = 3.0 - std::sqrt(5.0);
    for (int i = 0; i < rays; ++i) {
        const double q = i * golden * std::numbers::pi, r = double(i) / rays;
        out[i] = {r * std::cos(q), r * std::sin(q)};
    }
    return out;
}

// CGAL's Plane_3::base1() for the plane with normal n, normalised.
Vec3 plane_base1(const Vec3& n) {
    Vec3 b;
    const double a = std::abs(n[0]), bb = std::abs(n[1]), c = std::abs(n[2]);
    if (n[0] == 0)
        b = {1, 0, 0};
    else if (n[1] == 0)
        b = {0, 1, 0};
    else if (n[2] == 0)
        b = {0, 0, 1};
    else if (a <= bb && a <= c)
        b = {0, -n[2], n[1]};
    else if (bb <= a && bb <= c)
        b = {-n[2], 0, n[0]};
    else
        b = {-n[1], n[0], 0};
    return normalised(b);
}

// CGAL's remove_outliers_and_calculate_sdf_value (all weights 1 with Vogel sampling): the
// mean of the distances within 1.5 median absolute deviations of the median.
double robust_mean(std::vector<double>& dist, std::vector<double>& deviation) {
    const std::size_t n = dist.size();
    if (n == 1) return dist[0];
    const std::size_t half = n / 2;
    std::nth_element(dist.begin(), dist.begin() + half, dist.end());
    double median = dist[half];
    if (n % 2 == 0) median = 0.5 * (median + *std::max_element(dist.begin(), dist.begin() + half));
    deviation.resize(n);
    for (std::size_t i = 0; i < n; ++i) deviation[i] = std::abs(dist[i] - median);
    std::nth_element(deviation.begin(), deviation.begin() + half, deviation.end());
    double mad = deviation[half];
    if (n % 2 == 0)
        mad = 0.5 * (mad + *std::max_element(deviation.begin(), deviation.begin() + half));
    double total = 0;
    std::size_t count = 0;
    for (const double x : dist)
        if (std::abs(x - median) <= mad * kOutlierMads) total += x, ++count;
    return total == 0 ? median : total / count;
}

struct RayCaster {
    const TriangleMesh& mesh;
    const FaceData& data;
    const TriangleBvh& bvh;
    std::vector<std::pair<double, double>> samples;
    double cos_half, sin_half, max_distance, orientation;

    struct Scratch {
        std::vector<double> dist, deviation;
    };

    // The face's SDF, or kMissing when no ray left through the inner side of a face.
    double face_value(std::int32_t f, Scratch& s) const {
        const Face& t = mesh.triangles()[f];
        const Vec3 &p1 = data.points[t[0]], &p2 = data.points[t[1]], &p3 = data.points[t[2]];
        Vec3 centre;
        for (int k = 0; k < 3; ++k) centre[k] = (p1[k] + p2[k] + p3[k]) / 3.0;
        // Inward normal as CGAL takes it: normal(p2, p1, p3).
        const Vec3 n = scaled(normalised(cross(sub(p1, p2), sub(p3, p2))), orientation);
        const Vec3 v1 = plane_base1(n), v2 = normalised(cross(n, v1));
        const Vec3 axis = scaled(n, cos_half);
        s.dist.clear();
        for (const auto& [x, y] : samples) {
            Vec3 dir;
            for (int k = 0; k < 3; ++k)
                dir[k] = axis[k] + sin_half * x * v1[k] + sin_half * y * v2[k];
            const auto hit = bvh.first_hit(centre, normalised(dir), max_distance, f);
            // CGAL keeps the nearest hit only when the ray meets that face from inside (an
            // acute angle with its inward normal); otherwise the ray is dropped.
            if (hit.face >= 0 && (orientation > 0 ? hit.exits : !hit.exits))
                s.dist.push_back(hit.t);
        }
        return s.dist.empty() ? kMissing : robust_mean(s.dist, s.deviation);
    }
};

// CGAL's check_missing_sdf_values: in face order, a face without a value takes the mean of
// its edge neighbours that have one (values filled earlier included); faces still without
// take the smallest value found by rays.
void fill_missing(const Adjacency& adj, std::vector<double>& value) {
    double smallest = std::numeric_limits<double>::infinity();
    std::vector<std::size_t> still;
    for (std::size_t f = 0; f < value.size(); ++f) {
        if (value[f] != kMissing) {
            smallest = std::min(smallest, value[f]);
            continue;
        }
        double sum = 0;
        int count = 0;
        for (const std::int32_t g : adj.across[f])
            if (g >= 0 && value[g] != kMissing) sum += value[g], ++count;
        if (count > 0)
            value[f] = sum / count;
        else
            still.push_back(f);
    }
    for (const std::size_t f : still) value[f] = smallest;
}

// CGAL's Bilateral_filtering with Neighbor_selector_by_edge: every face within `window`
// edge steps weighs exp(-steps^2 / (2 (window/2)^2)) exp(-dv^2 / (2 (1.5 sigma)^2)), sigma
// the RMS difference of their values from the face's; a face whose neighbours all have its
// value keeps it.
std::vector<double> bilateral_filter(const Adjacency& adj, const std::vector<double>& value,
                                     int window) {
    const auto n = static_cast<std::int32_t>(value.size());
    std::vector<double> out(value.size());
    struct Scratch {
        std::vector<std::uint32_t> seen;  // stamp of the face whose window last reached it
        std::vector<std::pair<std::int32_t, int>> ring;  // (face, steps), in BFS order
    };
    tbb::enumerable_thread_specific<Scratch> scratch;
    const double spatial = window / 2.0;
    tbb::parallel_for(tbb::blocked_range<std::int32_t>(0, n, 256), [&](const auto& r) {
        Scratch& s = scratch.local();
        if (s.seen.empty()) s.seen.assign(value.size(), 0);
        for (std::int32_t f = r.begin(); f < r.end(); ++f) {
            const auto stamp = static_cast<std::uint32_t>(f) + 1;
            s.ring.clear();
            s.ring.push_back({f, 0});
            s.seen[f] = stamp;
            for (std::size_t i = 0; i < s.ring.size(); ++i) {
                const auto [g, steps] = s.ring[i];
                if (steps == window) continue;
                for (const std::int32_t h : adj.across[g])
                    if (h >= 0 && s.seen[h] != stamp) {
                        s.seen[h] = stamp;
                        s.ring.push_back({h, steps + 1});
                    }
            }
            const double own = value[f];
            double deviation = 0;
            for (const auto& [g, steps] : s.ring) deviation += (value[g] - own) * (value[g] - own);
            deviation = std::sqrt(deviation / s.ring.size());
            if (deviation == 0) {
                out[f] = own;
                continue;
            }
            const double range = 1.5 * deviation;
            double sum = 0, weights = 0;
            for (const auto& [g, steps] : s.ring) {
                const double a = steps / spatial, b = (value[g] - own) / range;
                const double w = std::exp(-0.5 * a * a) * std::exp(-0.5 * b * b);
                sum += value[g] * w;
                weights += w;
            }
            out[f] = sum / weights;
        }
    });
    return out;
}

void check_options(const SdfOptions& options) {
    if (options.rays < 1) throw Error("sdf", "the number of rays must be at least 1");
    if (!(options.cone_angle > 0 && options.cone_angle < std::numbers::pi))
        throw Error("sdf", "the cone angle must be between 0 and 180 degrees (exclusive)");
}

}  // namespace

SdfResult shape_diameter_function(const TriangleMesh& mesh, const SdfOptions& options,
                                  const ProgressFn& progress) {
    check_options(options);
    const FaceData data = face_data(mesh);
    const Adjacency adj = face_adjacency(mesh, data);
    SdfResult result;
    result.boundary_edges = adj.boundary_edges;
    result.nonmanifold_edges = adj.nonmanifold_edges;
    if ((adj.boundary_edges > 0 || adj.nonmanifold_edges > 0) && !options.allow_open)
        throw Error("sdf", "the mesh is not closed (" + std::to_string(adj.boundary_edges) +
                               " boundary edges, " + std::to_string(adj.nonmanifold_edges) +
                               " non-manifold edges) and the SDF measures thickness inside a "
                               "closed surface; close it, or use --allow-open to compute anyway");
    if (data.ray_faces.empty())
        throw Error("sdf", "the mesh has no face with a non-zero area; nothing to measure");
    result.degenerate_faces = mesh.triangle_count() - data.ray_faces.size();
    result.reoriented = signed_volume6(mesh, data) < 0;

    const TriangleBvh bvh(data.points, mesh.triangles(), data.ray_faces);
    report_progress(progress, 0.02, "sdf");
    // CGAL casts segments as long as the diagonal of the box around the non-degenerate
    // faces (its AABB tree's); so do we.
    const Vec3 extent = sub(bvh.upper(), bvh.lower());
    RayCaster caster{mesh,
                     data,
                     bvh,
                     disk_samples(options.rays),
                     std::cos(options.cone_angle / 2),
                     std::sin(options.cone_angle / 2),
                     std::sqrt(dot(extent, extent)),
                     result.reoriented ? -1.0 : 1.0};

    std::vector<double> value(mesh.triangle_count(), kMissing);
    tbb::enumerable_thread_specific<RayCaster::Scratch> scratch;
    const auto faces = static_cast<std::int32_t>(data.ray_faces.size());
    const std::int32_t chunk = 1 << 13;
    for (std::int32_t start = 0; start < faces; start += chunk) {
        const std::int32_t stop = std::min(faces, start + chunk);
        tbb::parallel_for(tbb::blocked_range<std::int32_t>(start, stop, 64), [&](const auto& r) {
            RayCaster::Scratch& s = scratch.local();
            for (std::int32_t i = r.begin(); i < r.end(); ++i) {
                const std::int32_t f = data.ray_faces[i];
                value[f] = caster.face_value(f, s);
            }
        });
        report_progress(progress, 0.02 + 0.88 * stop / faces, "sdf");
    }
    for (const std::int32_t f : data.ray_faces) result.faces_without_value += value[f] == kMissing;
    if (result.faces_without_value == data.ray_faces.size())
        throw Error("sdf",
                    "no ray met the surface from inside; are the faces oriented "
                    "consistently (terrain mesh --repair)?");

    fill_missing(adj, value);
    if (options.postprocess) {
        // CGAL's window: 1 up to 2000 faces, 2 up to 8000, 3 up to 18000, ...
        const int window = static_cast<int>(std::sqrt(mesh.triangle_count() / 2000.0)) + 1;
        value = bilateral_filter(adj, value, window);
    }
    report_progress(progress, 0.97, "sdf");

    // Per vertex: the mean of the incident faces weighted by area (serial: same sums always);
    // a vertex with only degenerate faces takes their plain mean.
    const std::size_t nv = mesh.vertex_count();
    std::vector<double> sum(nv, 0), weight(nv, 0), plain(nv, 0);
    std::vector<std::int32_t> count(nv, 0);
    for (std::size_t f = 0; f < mesh.triangle_count(); ++f)
        for (const std::int32_t v : mesh.triangles()[f]) {
            sum[v] += data.twice_area[f] * value[f];
            weight[v] += data.twice_area[f];
            plain[v] += value[f];
            ++count[v];
        }
    std::vector<double> diameter(nv, std::numeric_limits<double>::quiet_NaN());
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t v = 0; v < nv; ++v) {
        if (weight[v] > 0)
            diameter[v] = sum[v] / weight[v];
        else if (count[v] > 0)
            diameter[v] = plain[v] / count[v];
        else
            continue;  // in no face
        lo = std::min(lo, diameter[v]);
        hi = std::max(hi, diameter[v]);
    }
    // Linear normalisation, as CGAL's post-processing does for faces; a vertex in no face
    // gets the smallest value, a constant field 0.
    result.values.resize(nv);
    for (std::size_t v = 0; v < nv; ++v) {
        const double d = std::isnan(diameter[v]) ? lo : diameter[v];
        result.values[v] = hi > lo ? static_cast<float>(100.0 * (d - lo) / (hi - lo)) : 0.0f;
    }
    result.min_diameter = lo;
    result.max_diameter = hi;
    result.face_diameters = std::move(value);
    report_progress(progress, 1.0, "sdf");
    return result;
}

}  // namespace terrain::field
