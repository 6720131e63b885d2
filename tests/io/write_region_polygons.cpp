#include <gdal_priv.h>
#include <ogrsf_frmts.h>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_region_polygons.hpp"

using namespace terrain;

namespace {

// Region 1: two blocks touching at one corner (a MultiPolygon); region 3: a block inside
// region 2 (a hole in it); the rest Voronoi cells.
std::function<std::uint32_t(int, int)> designed_labels(const Dem& dem) {
    const auto cells = test::voronoi_cells(dem, 3, 2);
    return [cells](int col, int row) -> std::uint32_t {
        if ((col < 6 && row < 6) || (col >= 6 && col < 12 && row >= 6 && row < 12)) return 1;
        if (col >= 20 && col < 24 && row >= 14 && row < 18) return 3;
        if (col >= 16 && col < 28 && row >= 10 && row < 22) return 2;
        return 3 + cells(col, row);
    };
}

// The geodesic area (m^2) of a lon/lat ring densified to 0.01 degree steps, on the ellipsoid.
double ring_area(const OGRLinearRing& ring, const GeographicLib::Geodesic& geodesic) {
    GeographicLib::PolygonArea polygon(geodesic);
    for (int i = 0; i + 1 < ring.getNumPoints(); ++i) {
        const double x0 = ring.getX(i), y0 = ring.getY(i);
        const double x1 = ring.getX(i + 1), y1 = ring.getY(i + 1);
        const int steps = std::max(1, static_cast<int>(std::hypot(x1 - x0, y1 - y0) / 0.01));
        for (int s = 0; s < steps; ++s)
            polygon.AddPoint(y0 + (y1 - y0) * s / steps, x0 + (x1 - x0) * s / steps);
    }
    double perimeter = 0, area = 0;
    polygon.Compute(false, true, perimeter, area);
    return area;  // signed: counter-clockwise positive
}

double geodesic_area(const OGRGeometry& g, const GeographicLib::Geodesic& geodesic) {
    double sum = 0;
    auto add = [&](const OGRPolygon& p) {
        sum += ring_area(*p.getExteriorRing(), geodesic);
        for (int k = 0; k < p.getNumInteriorRings(); ++k)
            sum += ring_area(*p.getInteriorRing(k), geodesic);
    };
    if (wkbFlatten(g.getGeometryType()) == wkbPolygon)
        add(*g.toPolygon());
    else
        for (const auto* p : *g.toMultiPolygon()) add(*p);
    return sum;
}

// Same CRS up to the axis order GeoJSON imposes.
bool same_crs(const OGRSpatialReference& a, const OGRSpatialReference& b) {
    const char* equivalent[] = {"CRITERION=EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS",
                                "IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES", nullptr};
    return a.IsSame(&b, equivalent);
}

struct Read {
    std::unique_ptr<GDALDataset> ds;
    OGRLayer* layer = nullptr;  // the polygons (a GeoPackage also holds layer_styles)
    std::vector<std::unique_ptr<OGRFeature>> features;
};

Read read_features(const std::string& path) {
    GDALAllRegister();
    Read r;
    r.ds.reset(GDALDataset::Open(path.c_str(), GDAL_OF_VECTOR));
    REQUIRE(r.ds);
    const bool styles = r.ds->GetLayerByName("layer_styles") != nullptr;
    REQUIRE(r.ds->GetLayerCount() == (styles ? 2 : 1));
    for (int k = 0; k < r.ds->GetLayerCount(); ++k)
        if (std::string(r.ds->GetLayer(k)->GetName()) != "layer_styles")
            r.layer = r.ds->GetLayer(k);
    REQUIRE(r.layer);
    OGRLayer* layer = r.layer;
    for (std::unique_ptr<OGRFeature> f(layer->GetNextFeature()); f;
         f.reset(layer->GetNextFeature()))
        r.features.push_back(std::move(f));
    return r;
}

// Checks every feature of a polygon file against the tile: one per region, in id order,
// valid, the designed shapes, and every 3rd pixel centre inside its region's polygon.
void check_features(const Read& r, const test::SegmentedTile& t,
                    const std::function<std::array<double, 2>(double, double)>& to_output) {
    REQUIRE(r.features.size() == t.region_count);
    for (std::size_t i = 0; i < r.features.size(); ++i) {
        const auto& f = *r.features[i];
        const auto& region = t.graph.regions[i];
        CHECK(f.GetFieldAsInteger64("id") == region.id);
        CHECK(f.GetFieldAsDouble("area_m2") == Approx(region.area_m2));
        CHECK(f.GetFieldAsInteger64("pixel_count") == GIntBig(region.pixel_count));
        CHECK(std::string(f.GetFieldAsString("landform")) == segment::to_string(region.landform));
        CHECK(f.GetFieldAsInteger64("neighbor_count") == GIntBig(region.neighbor_count));
        const OGRGeometry* g = f.GetGeometryRef();
        REQUIRE(g);
        CHECK(g->IsValid());
    }
    const auto* first = r.features[0]->GetGeometryRef()->toMultiPolygon();
    CHECK(first->getNumGeometries() == 2);
    const OGRGeometry* second = r.features[1]->GetGeometryRef();
    const OGRPolygon* with_hole = wkbFlatten(second->getGeometryType()) == wkbPolygon
                                      ? second->toPolygon()
                                      : second->toMultiPolygon()->getGeometryRef(0);
    CHECK(with_hole->getNumInteriorRings() == 1);
    for (int row = 1; row < t.dem.height; row += 3)
        for (int col = 1; col < t.dem.width; col += 3) {
            const auto label = t.pixels[t.dem.index(col, row)];
            if (label == 0) continue;
            const auto xy = t.dem.map_xy(col + 0.5, row + 0.5);
            const auto p = to_output(xy[0], xy[1]);
            const OGRPoint point(p[0], p[1]);
            CHECK(r.features[label - 1]->GetGeometryRef()->Contains(&point));
        }
}

}  // namespace

TEST_CASE("regions.geojson on the Moon: lon/lat on the Moon, CRS recorded, areas add up",
          "[write_region_polygons]") {
    const Dem moon =
        test::crop(io::read_dem(test::sample("moon_ldem4_copernicus.tif")), 30, 20, 36, 30);
    const auto t = test::segment_tile(moon, designed_labels(moon));
    const auto dir = test::scratch_dir("write_region_polygons_moon");
    const auto path = (dir / "regions.geojson").string();
    io::write_region_polygons(t.dem, t.pixels, t.graph, path, false);
    const auto r = read_features(path);

    const OGRSpatialReference* srs = r.layer->GetSpatialRef();
    REQUIRE(srs);
    CHECK(srs->IsGeographic());
    CHECK(srs->GetSemiMajor() == Approx(1737400));
    OGRSpatialReference dem_srs;
    dem_srs.SetFromUserInput(t.dem.crs_wkt.c_str());
    dem_srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    std::unique_ptr<OGRSpatialReference> geographic(dem_srs.CloneGeogCS());
    geographic->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    // Stated as the Moon's IAU_2015 CRS (the same sphere), by its code.
    // (OGR names the authority "IAU", WKT1's form of IAU_2015.)
    CHECK(std::string(srs->GetAuthorityName(nullptr)).rfind("IAU", 0) == 0);
    CHECK(std::string(srs->GetAuthorityCode(nullptr)) == "30100");
    OGRSpatialReference iau;
    REQUIRE(iau.SetFromUserInput("IAU_2015:30100") == OGRERR_NONE);
    CHECK(same_crs(*srs, iau));
    std::unique_ptr<OGRCoordinateTransformation> ct(
        OGRCreateCoordinateTransformation(&dem_srs, geographic.get()));
    check_features(r, t, [&](double x, double y) {
        ct->Transform(1, &x, &y);
        return std::array<double, 2>{x, y};
    });

    // Each outline's own area on the sphere is its area_m2; together they are the tile's.
    const GeographicLib::Geodesic geodesic(1737400, 0);
    double sum = 0;
    for (const auto& f : r.features) {
        CHECK(geodesic_area(*f->GetGeometryRef(), geodesic) ==
              Approx(f->GetFieldAsDouble("area_m2")).epsilon(1e-6));
        sum += f->GetFieldAsDouble("area_m2");
    }
    CHECK(sum == Approx(test::labelled_area(t.dem, t.pixels)).epsilon(5e-6));

    // Same bytes on a rewrite; refused without overwrite.
    const auto first = test::file_bytes(path);
    CHECK_THROWS_AS(io::write_region_polygons(t.dem, t.pixels, t.graph, path, false), Error);
    io::write_region_polygons(t.dem, t.pixels, t.graph, path, true);
    CHECK(test::file_bytes(path) == first);
    CHECK(first.find("\"crs\"") != std::string::npos);
}

TEST_CASE("regions.geojson on Earth is RFC 7946 lon/lat", "[write_region_polygons][shared]") {
    const auto source = test::shared_data("earth/bigtujunga_srtm30m_utm11.tif");
    REQUIRE(source.has_value());  // CI always has ../shared beside the project
    const Dem srtm = test::crop(io::read_dem(*source), 500, 300, 36, 30);
    const auto t = test::segment_tile(srtm, designed_labels(srtm));
    const auto dir = test::scratch_dir("write_region_polygons_earth");
    const auto path = (dir / "regions.geojson").string();
    io::write_region_polygons(t.dem, t.pixels, t.graph, path, false);
    const auto text = test::file_bytes(path);
    CHECK(text.find("\"crs\"") == std::string::npos);
    const auto r = read_features(path);
    const OGRSpatialReference* srs = r.layer->GetSpatialRef();
    REQUIRE(srs);
    OGRSpatialReference wgs84;
    wgs84.importFromEPSG(4326);
    CHECK(same_crs(*srs, wgs84));
    OGRSpatialReference utm;
    utm.SetFromUserInput(t.dem.crs_wkt.c_str());
    utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    std::unique_ptr<OGRCoordinateTransformation> ct(
        OGRCreateCoordinateTransformation(&utm, &wgs84));
    check_features(r, t, [&](double x, double y) {
        ct->Transform(1, &x, &y);
        CHECK(x == Approx(-118.2).margin(0.3));  // lon first
        return std::array<double, 2>{x, y};
    });
    // Exterior rings counter-clockwise (RFC 7946).
    for (const auto& f : r.features) {
        const OGRGeometry* g = f->GetGeometryRef();
        const OGRPolygon* p = wkbFlatten(g->getGeometryType()) == wkbPolygon
                                  ? g->toPolygon()
                                  : g->toMultiPolygon()->getGeometryRef(0);
        CHECK_FALSE(p->getExteriorRing()->isClockwise());
    }
    const GeographicLib::Geodesic geodesic(srtm.body.semi_major_axis, srtm.body.flattening);
    double sum = 0;
    for (const auto& f : r.features) {
        CHECK(geodesic_area(*f->GetGeometryRef(), geodesic) ==
              Approx(f->GetFieldAsDouble("area_m2")).epsilon(1e-6));
        sum += f->GetFieldAsDouble("area_m2");
    }
    CHECK(sum == Approx(test::labelled_area(t.dem, t.pixels)).epsilon(1e-8));
}

TEST_CASE("regions.geojson without CRS is in the DEM's map coordinates",
          "[write_region_polygons]") {
    const Dem mars = io::read_dem(test::sample("mars_hirise_crop.tif"));
    const auto t = test::segment_tile(mars, designed_labels(mars));
    const auto dir = test::scratch_dir("write_region_polygons_mars");
    const auto path = (dir / "regions.geojson").string();
    io::write_region_polygons(t.dem, t.pixels, t.graph, path, false);
    // A local engineering CRS is named, so that no reader takes the metres for WGS 84.
    CHECK(test::file_bytes(path).find("\"crs\"") != std::string::npos);
    const auto r = read_features(path);
    const OGRSpatialReference* srs = r.layer->GetSpatialRef();
    REQUIRE(srs);
    CHECK(srs->IsLocal());
    CHECK_FALSE(srs->IsGeographic());
    check_features(r, t, [](double x, double y) { return std::array<double, 2>{x, y}; });
    double sum = 0;
    for (const auto& f : r.features) {
        const OGRGeometry* g = f->GetGeometryRef();
        const double area = wkbFlatten(g->getGeometryType()) == wkbPolygon
                                ? g->toPolygon()->get_Area()
                                : g->toMultiPolygon()->get_Area();
        CHECK(area == Approx(f->GetFieldAsDouble("area_m2")).epsilon(1e-9));
        sum += area;
    }
    CHECK(sum == Approx(70 * 120 * 1.01 * 1.01).epsilon(1e-9));
}

TEST_CASE("regions.gpkg keeps the DEM's full CRS, the same bytes every run",
          "[write_region_polygons]") {
    const Dem vesta =
        test::crop(io::read_dem(test::sample("vesta_hamo_tile.lbl")), 300, 300, 36, 30);
    const auto t = test::segment_tile(vesta, designed_labels(vesta));
    const auto dir = test::scratch_dir("write_region_polygons_gpkg");
    const auto path = (dir / "regions.gpkg").string();
    io::RegionPolygonOptions options;
    options.driver = "GPKG";
    io::write_region_polygons(t.dem, t.pixels, t.graph, path, false, options);
    {
        const auto r = read_features(path);
        // The DEM's projection on Vesta's IAU_2015 sphere (the same radius).
        OGRSpatialReference dem_srs, iau_vesta;
        dem_srs.SetFromUserInput(t.dem.crs_wkt.c_str());
        REQUIRE(iau_vesta.SetFromUserInput("IAU_2015:200000400") == OGRERR_NONE);
        REQUIRE(dem_srs.CopyGeogCSFrom(&iau_vesta) == OGRERR_NONE);
        const OGRSpatialReference* srs = r.layer->GetSpatialRef();
        REQUIRE(srs);
        CHECK(srs->IsProjected());
        CHECK(srs->IsSame(&dem_srs));
        CHECK(std::string(srs->GetAuthorityCode("GEOGCS")) == "200000400");
        // QGIS's default style of the layer: one layer_styles row.
        OGRLayer* styles = r.ds->GetLayerByName("layer_styles");
        REQUIRE(styles);
        CHECK(styles->GetFeatureCount() == 1);
        check_features(r, t, [](double x, double y) { return std::array<double, 2>{x, y}; });
        for (const auto& f : r.features)
            CHECK(wkbFlatten(f->GetGeometryRef()->getGeometryType()) == wkbMultiPolygon);
    }
    const auto first = test::file_bytes(path);
    io::write_region_polygons(t.dem, t.pixels, t.graph, path, true, options);
    CHECK(test::file_bytes(path) == first);
    std::size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
        ++files;
        CHECK(e.path().filename() == "regions.gpkg");
    }
    CHECK(files == 1);
    // Polygonized once, written twice: the same bytes as the direct writes, and the shared
    // polygons are left as they were (GeoJSON moves its copy to lon/lat).
    const auto shared = io::polygonize_regions(t.dem, t.pixels, t.graph.regions.size());
    CHECK(shared.region_count() == t.graph.regions.size());
    const auto direct_json = (dir / "direct.geojson").string();
    io::write_region_polygons(t.dem, t.pixels, t.graph, direct_json, false);
    const auto shared_json = (dir / "shared.geojson").string();
    io::write_region_polygons(t.dem, shared, t.graph, shared_json, false);
    CHECK(test::file_bytes(shared_json) == test::file_bytes(direct_json));
    const auto shared_gpkg = (dir / "shared.gpkg").string();
    io::write_region_polygons(t.dem, shared, t.graph, shared_gpkg, false, options);
    CHECK(test::file_bytes(shared_gpkg) == first);
    std::filesystem::remove(direct_json);
    std::filesystem::remove(shared_json);
    std::filesystem::remove(shared_gpkg);
    const auto fewer = io::polygonize_regions(t.dem, t.pixels, t.graph.regions.size() - 1);
    CHECK_THROWS_AS(io::write_region_polygons(t.dem, fewer, t.graph, shared_json, false), Error);
    // A shapefile: its .dbf header carries a fixed date (2000-01-01), not today's.
    options.driver = "ESRI Shapefile";
    const auto shp = (dir / "regions.shp").string();
    io::write_region_polygons(t.dem, t.pixels, t.graph, shp, false, options);
    const auto dbf = test::file_bytes((dir / "regions.dbf").string());
    REQUIRE(dbf.size() > 4);
    CHECK(static_cast<int>(dbf[1]) == 100);  // years since 1900
    CHECK(static_cast<int>(dbf[2]) == 1);
    CHECK(static_cast<int>(dbf[3]) == 1);
    CHECK(read_features(shp).features.size() == t.graph.regions.size());
    options.driver = "NoSuchDriver";
    CHECK_THROWS_AS(io::write_region_polygons(t.dem, t.pixels, t.graph, (dir / "x.shp").string(),
                                              false, options),
                    Error);
}
