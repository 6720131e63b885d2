// Craters read from the regions (craters.hpp, docs/craters.md).
//
// Each concave region with convex neighbours is a possible crater floor. Its centroid and the
// plane tangent to the body there give a local frame in metres; the rim crest is looked for
// in 36 directions around the centroid, as the highest vertex of the convex neighbours in each
// direction; a circle fitted to those points is the rim. The floor's own vertices also give
// the affine map from the frame to the grid's pixels, which places the circle's centre on the
// grid (and so on the body, as the regions' points are) and finds the ring of surroundings.
#include "terrain/segment/craters.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

#include "crater_floors.hpp"
#include "terrain/core/error.hpp"

namespace terrain::segment {
namespace {

using V3 = std::array<double, 3>;
constexpr int kSectors = 36;
constexpr int kMinSectors = 12;
// The points round a rim circle whose heights give its spread (rim_spread).
constexpr int kLevelPoints = 24;
constexpr double kInf = std::numeric_limits<double>::infinity();

V3 sub(const V3& a, const V3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const V3& a, const V3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
V3 cross(const V3& a, const V3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
V3 unit(const V3& a) {
    const double n = std::sqrt(dot(a, a));
    return n > 0 ? V3{a[0] / n, a[1] / n, a[2] / n} : V3{0, 0, 1};
}

// Solves the 3 x 3 system m x = b (Cramer); false when it is singular.
bool solve3(const std::array<std::array<double, 3>, 3>& m, const V3& b, V3& x) {
    const auto det = [](const std::array<std::array<double, 3>, 3>& a) {
        return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
               a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    const double d = det(m);
    if (!(std::abs(d) > 0) || !std::isfinite(d)) return false;
    for (int k = 0; k < 3; ++k) {
        auto a = m;
        for (int i = 0; i < 3; ++i) a[std::size_t(i)][std::size_t(k)] = b[std::size_t(i)];
        x[std::size_t(k)] = det(a) / d;
    }
    return true;
}

// Linear least squares in three unknowns c (y ~ c . p), its normal equations accumulated
// point by point.
struct LeastSquares3 {
    std::array<std::array<double, 3>, 3> m{};
    V3 b{};
    int points = 0;
    void add(const V3& p, double y) {
        for (std::size_t i = 0; i < 3; ++i) {
            for (std::size_t j = 0; j < 3; ++j) m[i][j] += p[i] * p[j];
            b[i] += p[i] * y;
        }
        ++points;
    }
    bool solve(V3& c) const { return points >= 3 && solve3(m, b, c); }
};

struct Circle {
    double x = 0, y = 0, r = 0, rms = 0;
    int points = 0;
};

// Kasa's algebraic fit (x^2 + y^2 + a x + b y + c = 0) to the points with `use`.
bool fit_circle(const std::array<double, kSectors>& px, const std::array<double, kSectors>& py,
                const std::array<bool, kSectors>& use, Circle& out) {
    LeastSquares3 fit;
    for (int s = 0; s < kSectors; ++s) {
        if (!use[std::size_t(s)]) continue;
        const double x = px[std::size_t(s)], y = py[std::size_t(s)];
        fit.add({x, y, 1}, -(x * x + y * y));
    }
    V3 abc;
    if (!fit.solve(abc)) return false;
    const int n = fit.points;
    out.x = -abc[0] / 2;
    out.y = -abc[1] / 2;
    const double r2 = out.x * out.x + out.y * out.y - abc[2];
    if (!(r2 > 0)) return false;
    out.r = std::sqrt(r2);
    double e2 = 0;
    for (int s = 0; s < kSectors; ++s)
        if (use[std::size_t(s)]) {
            const double e =
                std::hypot(px[std::size_t(s)] - out.x, py[std::size_t(s)] - out.y) - out.r;
            e2 += e * e;
        }
    out.rms = std::sqrt(e2 / n);
    out.points = n;
    return true;
}

// A possible floor and what the passes gather for it.
struct Floor {
    std::vector<std::uint32_t> members;  // its regions, the largest first
    double area = 0, perimeter = 0;
    V3 sum{};
    std::size_t count = 0;
    V3 centre{}, e1{}, e2{};
    double radius = 0;       // of a disk of the floor's area
    int sectors = kSectors;  // directions looked in: kSectors, fewer on a small floor
    double lowest = kInf;
    int first_col = -1;      // columns unwrapped around this one on a closed grid
    LeastSquares3 col, row;  // pixel column and row from the frame's x, y (affine)
    std::array<double, kSectors> x{}, y{}, h{};
    std::array<std::uint32_t, kSectors> from{};
    Circle circle;
    std::array<bool, kSectors> kept{};
    double crest = 0;
    double spread = 0;  // the sum of the floor vertices' squared distances from the centroid
};

// The possible floors of a segmentation and which floors each region is in or rims.
struct Floors {
    std::vector<Floor> floors;
    std::vector<std::vector<std::int32_t>> in;   // by region: the floors it is part of
    std::vector<std::vector<std::int32_t>> rim;  // by convex region: the floors it borders
};

// The possible floors (crater_floors.cpp) and the convex neighbours of each.
Floors select_floors(const RegionGraph& graph, const CraterOptions& options) {
    Floors out;
    out.in.resize(graph.regions.size() + 1);
    out.rim.resize(graph.regions.size() + 1);
    for (auto& candidate : internal::floor_candidates(graph, options)) {
        const auto f = std::int32_t(out.floors.size());
        for (const auto id : candidate.members) out.in[id].push_back(f);
        Floor fl;
        fl.members = std::move(candidate.members);
        fl.area = candidate.area_m2;
        fl.perimeter = candidate.perimeter_m;
        fl.radius = std::sqrt(fl.area / std::numbers::pi);
        out.floors.push_back(std::move(fl));
    }
    for (const auto& e : graph.edges)
        for (const auto& [inner, outer] : {std::pair{e.a, e.b}, std::pair{e.b, e.a}}) {
            if (!internal::convex_region(graph, outer, options)) continue;
            for (const auto f : out.in[inner]) {
                auto& list = out.rim[outer];
                if (std::find(list.begin(), list.end(), f) == list.end()) list.push_back(f);
            }
        }
    return out;
}

// The height of the DEM at a vertex's pixel.
double vertex_height(const TriangleMesh& mesh, const Dem& dem, std::size_t v) {
    const auto p = std::size_t(mesh.vertex_pixel[v]);
    return dem.height_at(int(p % std::size_t(dem.width)), int(p / std::size_t(dem.width)));
}

// Pass 1: the floors' centroids, lowest heights and a column of each; then their frames.
void find_centres(const TriangleMesh& mesh, const Dem& dem,
                  const std::vector<std::uint32_t>& labels, Floors& floors) {
    const std::size_t m = floors.in.size() - 1;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (labels[v] == 0 || labels[v] > m || floors.in[labels[v]].empty()) continue;
        const auto p = mesh.position(v);
        const double h = vertex_height(mesh, dem, v);
        const int col = int(std::size_t(mesh.vertex_pixel[v]) % std::size_t(dem.width));
        for (const auto f : floors.in[labels[v]]) {
            auto& fl = floors.floors[std::size_t(f)];
            for (int k = 0; k < 3; ++k) fl.sum[std::size_t(k)] += p[std::size_t(k)];
            ++fl.count;
            fl.lowest = std::min(fl.lowest, h);
            if (fl.first_col < 0) fl.first_col = col;
        }
    }
    for (auto& fl : floors.floors) {
        const double c = double(std::max<std::size_t>(fl.count, 1));
        fl.centre = {fl.sum[0] / c, fl.sum[1] / c, fl.sum[2] / c};
        const V3 up = mesh.frame == MeshFrame::body ? unit(fl.centre) : V3{0, 0, 1};
        const V3 axis = std::abs(up[2]) < 0.9 ? V3{0, 0, 1} : V3{1, 0, 0};
        fl.e1 = unit(cross(axis, up));
        fl.e2 = cross(up, fl.e1);
        fl.h.fill(-kInf);
        // A direction a pixel of the circle of the floor's radius: a small floor's rim has
        // fewer pixels than kSectors directions, which would leave some empty whatever the rim.
        const double pixel = std::sqrt(fl.area / c);
        const double around = pixel > 0 ? 2 * std::numbers::pi * fl.radius / pixel : kSectors;
        fl.sectors = std::clamp(int(around), kMinSectors, kSectors);
    }
}

// Pass 2: the affine maps to pixels over each floor; the highest rim vertex by direction.
void find_crests(const TriangleMesh& mesh, const Dem& dem, const std::vector<std::uint32_t>& labels,
                 const CraterOptions& options, Floors& floors) {
    const std::size_t m = floors.in.size() - 1;
    const double width = dem.width;
    const auto unwrapped = [&](const Floor& fl, double col) {
        if (!mesh.seam_closed) return col;
        if (col - fl.first_col > width / 2) return col - width;
        if (fl.first_col - col > width / 2) return col + width;
        return col;
    };
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const auto label = labels[v];
        if (label == 0 || label > m) continue;
        const auto& in = floors.in[label];
        const auto& rim = floors.rim[label];
        if (in.empty() && rim.empty()) continue;
        const auto p = mesh.position(v);
        const auto pixel = std::size_t(mesh.vertex_pixel[v]);
        for (const auto f : in) {
            auto& fl = floors.floors[std::size_t(f)];
            const V3 d = sub(p, fl.centre);
            const double x = dot(d, fl.e1), y = dot(d, fl.e2);
            fl.spread += x * x + y * y;
            fl.col.add({1, x, y}, unwrapped(fl, double(pixel % std::size_t(dem.width)) + 0.5));
            fl.row.add({1, x, y}, double(pixel / std::size_t(dem.width)) + 0.5);
        }
        if (rim.empty()) continue;
        const double h = vertex_height(mesh, dem, v);
        for (const auto f : rim) {
            auto& fl = floors.floors[std::size_t(f)];
            const V3 d = sub(p, fl.centre);
            const double x = dot(d, fl.e1), y = dot(d, fl.e2), r = std::hypot(x, y);
            if (r < options.crest_from * fl.radius || r > options.crest_to * fl.radius) continue;
            const double turn = (std::atan2(y, x) + std::numbers::pi) / (2 * std::numbers::pi);
            const auto s = std::size_t(std::min(fl.sectors - 1, int(turn * fl.sectors)));
            if (h > fl.h[s]) {
                fl.h[s] = h;
                fl.x[s] = x;
                fl.y[s] = y;
                fl.from[s] = label;
            }
        }
    }
}

// The rim circles: fitted twice, the second time without the points a quarter radius off.
// The floors whose circle holds (enough directions, a radius the floor allows, a positive
// depth), in floor order.
std::vector<std::size_t> fit_rims(const CraterOptions& options, std::vector<Floor>& floors) {
    std::vector<std::size_t> found;
    for (std::size_t f = 0; f < floors.size(); ++f) {
        auto& fl = floors[f];
        for (int s = 0; s < kSectors; ++s) fl.kept[std::size_t(s)] = fl.h[std::size_t(s)] > -kInf;
        Circle c;
        if (!fit_circle(fl.x, fl.y, fl.kept, c)) continue;
        for (int s = 0; s < kSectors; ++s) {
            const auto i = std::size_t(s);
            if (fl.kept[i] && std::abs(std::hypot(fl.x[i] - c.x, fl.y[i] - c.y) - c.r) > 0.25 * c.r)
                fl.kept[i] = false;
        }
        if (!fit_circle(fl.x, fl.y, fl.kept, c)) continue;
        // The floor lies within its rim: its RMS distance from the circle's centre is at most
        // the radius (a disk filling the circle: 0.71 radius; a floor round a central peak:
        // about as much). A moat round a knob, rimmed by the knob's flanks, lies outside it.
        const double inside =
            fl.spread / double(std::max<std::size_t>(fl.count, 1)) + c.x * c.x + c.y * c.y;
        if (!(inside <= c.r * c.r)) continue;
        fl.circle = c;
        double crest = 0;
        for (int s = 0; s < kSectors; ++s)
            if (fl.kept[std::size_t(s)]) crest += fl.h[std::size_t(s)];
        fl.crest = crest / c.points;
        const double fraction = double(c.points) / fl.sectors;
        if (fraction < options.min_rim_fraction || c.r < 0.8 * options.crest_from * fl.radius ||
            c.r > options.crest_to * fl.radius || !(fl.crest > fl.lowest))
            continue;
        found.push_back(f);
    }
    return found;
}

// The mean height of the surroundings of a crater: the pixels 1.5 to 2 radii from its centre
// (NaN when there are none).
double surroundings_height(const TriangleMesh& mesh, const Dem& dem, const Floor& fl,
                           const std::function<std::array<double, 2>(double, double)>& to_pixel) {
    const auto& c = fl.circle;
    double lo_c = kInf, hi_c = -kInf, lo_r = kInf, hi_r = -kInf;
    for (const double sx : {-2.0, 2.0})
        for (const double sy : {-2.0, 2.0}) {
            const auto q = to_pixel(c.x + sx * c.r, c.y + sy * c.r);
            lo_c = std::min(lo_c, q[0]);
            hi_c = std::max(hi_c, q[0]);
            lo_r = std::min(lo_r, q[1]);
            hi_r = std::max(hi_r, q[1]);
        }
    double ring = 0;
    std::size_t ring_n = 0;
    const int r0 = std::max(0, int(std::floor(lo_r))),
              r1 = std::min(dem.height - 1, int(std::ceil(hi_r)));
    const int c0 = std::max(0, int(std::floor(lo_c))),
              c1 = std::min(dem.width - 1, int(std::ceil(hi_c)));
    for (int row = r0; row <= r1; ++row)
        for (int col = c0; col <= c1; ++col) {
            const auto v =
                mesh.pixel_vertex[std::size_t(row) * std::size_t(dem.width) + std::size_t(col)];
            if (v < 0) continue;
            const V3 d = sub(mesh.position(std::size_t(v)), fl.centre);
            const double r = std::hypot(dot(d, fl.e1) - c.x, dot(d, fl.e2) - c.y);
            if (r < 1.5 * c.r || r > 2 * c.r) continue;
            ring += dem.height_at(col, row);
            ++ring_n;
        }
    return ring_n > 0 ? ring / double(ring_n) : std::numeric_limits<double>::quiet_NaN();
}

// The standard deviation of the DEM's heights at kLevelPoints points round the rim circle,
// over their mean's height above the crater's centre: about 0 for a crater's rim, which is
// level; 1 or more for a low between the rims of other craters. Infinity when under half the
// points are on the grid or the centre is not below them.
double rim_spread(const TriangleMesh& mesh, const Dem& dem, const Circle& c,
                  const std::function<std::array<double, 2>(double, double)>& to_pixel) {
    const auto height = [&](double x, double y, double& h) {
        const auto q = to_pixel(x, y);
        int col = int(std::floor(q[0]));
        const int row = int(std::floor(q[1]));
        if (mesh.seam_closed) col = ((col % dem.width) + dem.width) % dem.width;
        if (col < 0 || col >= dem.width || row < 0 || row >= dem.height) return false;
        if (mesh.pixel_vertex[std::size_t(row) * std::size_t(dem.width) + std::size_t(col)] < 0)
            return false;
        h = dem.height_at(col, row);
        return std::isfinite(h);
    };
    double centre = 0, sum = 0, sum2 = 0;
    int n = 0;
    for (int i = 0; i < kLevelPoints; ++i) {
        const double t = 2 * std::numbers::pi * i / kLevelPoints;
        double h = 0;
        if (!height(c.x + c.r * std::cos(t), c.y + c.r * std::sin(t), h)) continue;
        sum += h, sum2 += h * h, ++n;
    }
    if (2 * n < kLevelPoints || !height(c.x, c.y, centre)) return kInf;
    const double mean = sum / n, depth = mean - centre;
    const double sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
    return depth > 0 ? sd / depth : kInf;
}

// A crater of a floor whose rim circle holds; false when its confidence is too low or its
// frame has no map to the grid. `xy`: its centre in the DEM's map coordinates.
bool make_crater(const TriangleMesh& mesh, const Dem& dem, const RegionGraph& graph,
                 const CraterOptions& options, const Floor& fl, Crater& k,
                 std::array<double, 2>& xy) {
    const auto& c = fl.circle;
    k.floor_region = fl.members[0];
    k.diameter_m = 2 * c.r;
    k.depth_m = fl.crest - fl.lowest;
    k.rim_fraction = double(c.points) / fl.sectors;
    k.fit_rms_m = c.rms;
    k.field_scale_m = graph.regions[fl.members[0] - 1].field_scale_m;
    k.circularity = std::min(1.0, 4 * std::numbers::pi * fl.area / (fl.perimeter * fl.perimeter));
    double field = 0, area = 0;  // the floor's mean field, over its regions
    for (const auto id : fl.members) {
        const auto& region = graph.regions[id - 1];
        field += region.field_mean * region.area_m2;
        area += region.area_m2;
    }
    V3 ac, ar;
    if (!fl.col.solve(ac) || !fl.row.solve(ar)) return false;
    const auto to_pixel = [&](double x, double y) {
        return std::array<double, 2>{ac[0] + ac[1] * x + ac[2] * y, ar[0] + ar[1] * x + ar[2] * y};
    };
    CraterEvidence evidence;
    evidence.rim_fraction = k.rim_fraction;
    evidence.fit_rms_m = c.rms;
    evidence.radius_m = c.r;
    evidence.pixel_m = std::sqrt(fl.area / double(std::max<std::size_t>(fl.count, 1)));
    evidence.circularity = k.circularity;
    evidence.floor_mean = area > 0 ? field / area : options.concave_below;
    evidence.rim_spread = rim_spread(mesh, dem, c, to_pixel);
    k.confidence = crater_confidence(evidence, options);
    if (k.confidence < options.min_confidence) return false;
    for (int s = 0; s < kSectors; ++s)
        if (fl.kept[std::size_t(s)]) k.rim_regions.push_back(fl.from[std::size_t(s)]);
    std::sort(k.rim_regions.begin(), k.rim_regions.end());
    k.rim_regions.erase(std::unique(k.rim_regions.begin(), k.rim_regions.end()),
                        k.rim_regions.end());
    const auto centre = to_pixel(c.x, c.y);
    k.col = centre[0];
    k.row = centre[1];
    for (int i = 0; i <= kRimPoints; ++i) {
        const double t = 2 * std::numbers::pi * (i % kRimPoints) / kRimPoints;
        const auto q = to_pixel(c.x + c.r * std::cos(t), c.y + c.r * std::sin(t));
        k.rim.push_back(dem.map_xy(q[0], q[1]));
    }
    k.rim_height_m = fl.crest - surroundings_height(mesh, dem, fl, to_pixel);
    xy = dem.map_xy(centre[0], centre[1]);
    return true;
}

// Of two craters at one place and size, the more confident (ties: the lower floor region,
// then the floor made of fewer regions, then the lower floor index); the others are marked.
std::vector<std::uint8_t> duplicates(const CraterTable& table, const std::vector<Floor>& floors,
                                     const std::vector<std::size_t>& floor_of) {
    std::vector<V3> at;
    std::vector<double> radius;
    for (std::size_t i = 0; i < table.craters.size(); ++i) {
        const auto& fl = floors[floor_of[i]];
        const auto& c = fl.circle;
        V3 p = fl.centre;
        for (std::size_t j = 0; j < 3; ++j) p[j] += c.x * fl.e1[j] + c.y * fl.e2[j];
        at.push_back(p);
        radius.push_back(c.r);
    }
    std::vector<std::size_t> by_x(at.size());
    for (std::size_t i = 0; i < by_x.size(); ++i) by_x[i] = i;
    std::sort(by_x.begin(), by_x.end(), [&](std::size_t a, std::size_t b) {
        return at[a][0] < at[b][0] || (at[a][0] == at[b][0] && a < b);
    });
    std::vector<std::uint8_t> gone(at.size(), 0);
    const auto better = [&](std::size_t a, std::size_t b) {
        const auto &ka = table.craters[a], &kb = table.craters[b];
        if (ka.confidence != kb.confidence) return ka.confidence > kb.confidence;
        if (ka.floor_region != kb.floor_region) return ka.floor_region < kb.floor_region;
        return floor_of[a] < floor_of[b];
    };
    for (std::size_t i = 0; i < by_x.size(); ++i)
        for (std::size_t j = i + 1; j < by_x.size(); ++j) {
            const auto a = by_x[i], b = by_x[j];
            // Radii within 1.5x and centres within half the larger: |dx| < 0.75 of a's.
            if (at[b][0] - at[a][0] > 0.75 * radius[a]) break;
            const double big = std::max(radius[a], radius[b]),
                         small = std::min(radius[a], radius[b]);
            if (big > 1.5 * small ||
                std::sqrt(dot(sub(at[a], at[b]), sub(at[a], at[b]))) > 0.5 * big)
                continue;
            gone[better(a, b) ? b : a] = 1;
        }
    return gone;
}

// The centres and rims in lon/lat where the DEM has a frame for them.
void to_lonlat(const Dem& dem, CraterTable& table, std::vector<double>& cx,
               std::vector<double>& cy) {
    table.lonlat = false;
    if (dem.crs_wkt.empty() || !dem.georef_current() || !dem.georef.output_lonlat) return;
    const LonLatMapping& frame = *dem.georef.output_lonlat;
    if (!frame.to_lonlat(cx.size(), cx.data(), cy.data()))
        throw Error("craters", "a crater's centre has no longitude/latitude on the body");
    for (std::size_t i = 0; i < table.craters.size(); ++i) {
        auto& ring = table.craters[i].rim;
        std::vector<double> x, y;
        for (const auto& p : ring) {
            x.push_back(p[0]);
            y.push_back(p[1]);
        }
        if (!frame.to_lonlat(x.size(), x.data(), y.data()))
            throw Error("craters", "a crater's rim has no longitude/latitude on the body");
        for (std::size_t j = 0; j < ring.size(); ++j)
            ring[j] = {x[j] + 360 * std::round((cx[i] - x[j]) / 360), y[j]};
    }
    table.lonlat = true;
    table.lonlat_crs_wkt = frame.lonlat_crs_wkt();
}

}  // namespace

double crater_confidence(const CraterEvidence& e, const CraterOptions& options) {
    const double half_pixel = 0.5 * e.pixel_m;
    const double misfit =
        std::sqrt(std::max(0.0, e.fit_rms_m * e.fit_rms_m - half_pixel * half_pixel));
    const double quality = e.radius_m > 0 ? std::max(0.0, 1 - 4 * misfit / e.radius_m) : 0.0;
    const double roundness =
        options.round_floor > 0 ? std::min(1.0, e.circularity / options.round_floor) : 1.0;
    const double band = options.concave_below - options.concave_full;
    const double concavity =
        band > 0 ? std::clamp((options.concave_below - e.floor_mean) / band, 0.0, 1.0)
                 : (e.floor_mean < options.concave_below ? 1.0 : 0.0);
    const double spread = options.level_spread > 0 ? e.rim_spread / options.level_spread : 0.0;
    const double level = std::isfinite(spread) ? 1 / (1 + spread * spread) : 0.0;
    return std::clamp(e.rim_fraction, 0.0, 1.0) * quality * roundness * concavity * level;
}

CraterTable find_craters(const TriangleMesh& mesh, const Dem& dem,
                         const std::vector<std::uint32_t>& labels, const RegionGraph& graph,
                         const CraterOptions& options) {
    const std::size_t n = mesh.vertex_count();
    if (labels.size() != n || mesh.vertex_pixel.size() != n ||
        mesh.pixel_vertex.size() != std::size_t(dem.width) * std::size_t(dem.height))
        throw Error("craters", "the labels, the mesh and the DEM do not match");
    auto floors = select_floors(graph, options);
    find_centres(mesh, dem, labels, floors);
    find_crests(mesh, dem, labels, options, floors);
    const auto found = fit_rims(options, floors.floors);
    CraterTable table;
    std::vector<double> cx, cy;
    std::vector<std::size_t> floor_of;  // by crater
    for (const auto f : found) {
        Crater k;
        std::array<double, 2> xy{};
        if (!make_crater(mesh, dem, graph, options, floors.floors[f], k, xy)) continue;
        table.craters.push_back(std::move(k));
        cx.push_back(xy[0]);
        cy.push_back(xy[1]);
        floor_of.push_back(f);
    }
    const auto gone = duplicates(table, floors.floors, floor_of);
    // The craters kept, by floor region (then by floor: a region alone before its pairs and
    // groups).
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < table.craters.size(); ++i)
        if (!gone[i]) order.push_back(i);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        const auto ra = table.craters[a].floor_region, rb = table.craters[b].floor_region;
        return ra < rb || (ra == rb && floor_of[a] < floor_of[b]);
    });
    CraterTable sorted;
    std::vector<double> sx, sy;
    for (const auto i : order) {
        sorted.craters.push_back(std::move(table.craters[i]));
        sx.push_back(cx[i]);
        sy.push_back(cy[i]);
    }
    table = std::move(sorted);
    cx = std::move(sx);
    cy = std::move(sy);
    to_lonlat(dem, table, cx, cy);
    for (std::size_t i = 0; i < table.craters.size(); ++i) {
        table.craters[i].id = std::uint32_t(i + 1);
        table.craters[i].lon = cx[i];
        table.craters[i].lat = cy[i];
    }
    return table;
}

}  // namespace terrain::segment
