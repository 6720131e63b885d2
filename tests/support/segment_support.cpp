#include "support/segment_support.hpp"

#include <ogr_spatialref.h>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "terrain/field/vertex_field.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/mesh/dem_to_mesh.hpp"

namespace terrain::test {

Dem crop(const Dem& dem, int col0, int row0, int width, int height) {
    Dem out = dem;
    out.width = width;
    out.height = height;
    const auto origin = dem.map_xy(col0, row0);
    out.transform[0] = origin[0];
    out.transform[3] = origin[1];
    out.values.clear();
    for (int r = row0; r < row0 + height; ++r)
        for (int c = col0; c < col0 + width; ++c) out.values.push_back(dem.at(c, r));
    geo::georeference(out);  // a smaller grid: another extent
    return out;
}

SegmentedTile segment_tile(Dem dem, const std::function<std::uint32_t(int, int)>& label_of) {
    SegmentedTile t;
    t.dem = std::move(dem);
    t.mesh = mesh::dem_to_mesh(t.dem);
    t.field = field::vertex_field(t.mesh, &t.dem, {});
    std::map<std::uint32_t, std::uint32_t> ids;
    std::vector<std::uint32_t> raw;
    for (auto p : t.mesh.vertex_pixel) {
        raw.push_back(label_of(p % t.dem.width, p / t.dem.width));
        ids[raw.back()] = 0;
    }
    for (auto& [raw_id, id] : ids) id = ++t.region_count;
    for (auto r : raw) t.labels.push_back(ids[r]);
    t.graph = segment::region_graph(t.mesh, t.field, t.labels, t.region_count, &t.dem);
    t.pixels = segment::label_pixels(t.mesh, t.dem, t.labels);
    return t;
}

std::function<std::uint32_t(int, int)> voronoi_cells(const Dem& dem, int nx, int ny) {
    std::vector<std::array<double, 2>> seeds;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            // A fixed jitter: the cells are irregular but the same every run.
            const double jx = 0.3 * std::sin(7.1 * i + 3.3 * j),
                         jy = 0.3 * std::cos(5.3 * i - 2.9 * j);
            seeds.push_back({(i + 0.5 + jx) * dem.width / nx, (j + 0.5 + jy) * dem.height / ny});
        }
    return [seeds](int col, int row) {
        std::uint32_t best = 0;
        double d_best = 1e300;
        for (std::size_t k = 0; k < seeds.size(); ++k) {
            const double d = std::hypot(col + 0.5 - seeds[k][0], row + 0.5 - seeds[k][1]);
            if (d < d_best) {
                d_best = d;
                best = static_cast<std::uint32_t>(k + 1);
            }
        }
        return best;
    };
}

namespace {

// Geodesic areas of pixel footprints, with the CRS transformation made once.
class ReferenceAreas {
  public:
    explicit ReferenceAreas(const Dem& dem)
        : dem_(dem),
          geodesic_(dem.body.has_crs ? dem.body.semi_major_axis : 1,
                    dem.body.has_crs ? dem.body.flattening : 0) {
        if (dem.crs_wkt.empty()) return;
        source_.SetFromUserInput(dem.crs_wkt.c_str());
        source_.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
        geographic_.reset(source_.CloneGeogCS());
        geographic_->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
        ct_.reset(OGRCreateCoordinateTransformation(&source_, geographic_.get()));
    }
    double operator()(int col, int row) const {
        const auto& t = dem_.transform;
        if (!ct_) return std::abs(t[1] * t[5] - t[2] * t[4]);
        GeographicLib::PolygonArea polygon(geodesic_);
        const double corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        for (const auto& k : corner) {
            auto p = dem_.map_xy(col + k[0], row + k[1]);
            ct_->Transform(1, &p[0], &p[1]);
            polygon.AddPoint(p[1], p[0]);
        }
        double perimeter = 0, area = 0;
        polygon.Compute(false, true, perimeter, area);
        return std::abs(area);
    }

  private:
    const Dem& dem_;
    GeographicLib::Geodesic geodesic_;
    OGRSpatialReference source_;
    std::unique_ptr<OGRSpatialReference> geographic_;
    std::unique_ptr<OGRCoordinateTransformation> ct_;
};

}  // namespace

double pixel_area(const Dem& dem, int col, int row) {
    return ReferenceAreas(dem)(col, row);
}

double labelled_area(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                     std::uint32_t label) {
    const ReferenceAreas area(dem);
    double sum = 0;
    for (int r = 0; r < dem.height; ++r)
        for (int c = 0; c < dem.width; ++c) {
            const auto l = pixels[dem.index(c, r)];
            if (l != 0 && (label == 0 || l == label)) sum += area(c, r);
        }
    return sum;
}

}  // namespace terrain::test
