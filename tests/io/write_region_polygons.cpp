#include <gdal_priv.h>
#include <ogrsf_frmts.h>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include "support/segment_support.hpp"
#include "support/test_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/geo/georeference.hpp"
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

TEST_CASE("regions.geojson on Earth is RFC 7946 lon/lat", "[write_region_polygons][real_data]") {
    const auto source = test::real_data("earth/bigtujunga_srtm30m_utm11.tif");
    REQUIRE(source.has_value());  // tests/data is in the repository
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

TEST_CASE("Region polygons wait in an unlinked temporary file and are read back region by region",
          "[write_region_polygons]") {
    // The outlines are never all in memory: GDALPolygonize's pieces go to a temporary file
    // beside the output, unlinked from the start, so nothing is left behind.
    const Dem mars = io::read_dem(test::sample("mars_hirise_crop.tif"));
    const auto t = test::segment_tile(mars, designed_labels(mars));
    const auto dir = test::scratch_dir("write_region_polygons_spill");
    const auto path = (dir / "regions.geojson").string();
    io::write_region_polygons(t.dem, t.pixels, t.graph, path, false);
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        names.push_back(e.path().filename().string());
    CHECK(names == std::vector<std::string>{"regions.geojson"});
    // Polygons made once are read by several writers at once (terrain sweep): the same
    // features as the direct writer, from each of four threads.
    const auto made = io::polygonize_regions(t.dem, t.pixels, t.graph.regions.size(), dir.string());
    CHECK(made.region_count() == t.graph.regions.size());
    std::vector<std::thread> writers;
    for (int k = 0; k < 4; ++k)
        writers.emplace_back([&, k] {
            io::write_region_polygons(t.dem, made, t.graph,
                                      (dir / ("copy" + std::to_string(k) + ".geojson")).string(),
                                      false);
        });
    for (auto& w : writers) w.join();
    for (int k = 0; k < 4; ++k)
        CHECK(test::file_bytes((dir / ("copy" + std::to_string(k) + ".geojson")).string()) ==
              test::file_bytes(path));
    check_features(read_features((dir / "copy3.geojson").string()), t, [](double x, double y) {
        return std::array<double, 2>{x, y};
    });
    // Progress: GDALPolygonize's rows, then each region written; a cancel leaves no file.
    std::vector<double> seen;
    const auto reported = (dir / "reported.geojson").string();
    io::write_region_polygons(t.dem, t.pixels, t.graph, reported, false, {},
                              [&](double f, std::string_view message) {
                                  CHECK(message == "write");
                                  seen.push_back(f);
                                  return true;
                              });
    CHECK(test::file_bytes(reported) == test::file_bytes(path));
    CHECK(seen.size() > t.graph.regions.size());
    CHECK(std::is_sorted(seen.begin(), seen.end()));
    CHECK(seen.back() > 0.9);
    const auto cancelled = (dir / "cancelled.gpkg").string();
    io::RegionPolygonOptions gpkg;
    gpkg.driver = "GPKG";
    for (const double at : {0.3, 0.9}) {  // in GDALPolygonize, then among the regions
        CHECK_THROWS_AS(
            io::write_region_polygons(t.dem, t.pixels, t.graph, cancelled, false, gpkg,
                                      [&](double f, std::string_view) { return f < at; }),
            Error);
        CHECK_FALSE(std::filesystem::exists(cancelled));
    }
    for (const auto& e : std::filesystem::directory_iterator(dir))
        CHECK(e.path().filename().string()[0] != '.');  // no temporary file left
    // A temporary directory that cannot take the pieces: one line naming it.
    CHECK_THROWS_WITH(
        io::polygonize_regions(t.dem, t.pixels, t.graph.regions.size(), (dir / "missing").string()),
        Catch::Contains("cannot create a temporary file in") && Catch::Contains("missing"));
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
        // QGIS's default style of the layer and one by landform: two layer_styles rows.
        OGRLayer* styles = r.ds->GetLayerByName("layer_styles");
        REQUIRE(styles);
        CHECK(styles->GetFeatureCount() == 2);
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

namespace {

// A 1-degree global Moon grid (360 x 180, smooth relief) in `crs` with the geotransform `t`.
Dem global_grid(const std::string& crs, const GeoTransform& t) {
    Dem dem;
    dem.width = 360;
    dem.height = 180;
    dem.crs_wkt = crs;
    dem.transform = t;
    dem.has_transform = true;
    geo::georeference(dem);
    for (int r = 0; r < dem.height; ++r)
        for (int c = 0; c < dem.width; ++c)
            dem.values.push_back(1000 * std::sin(c * 0.05) * std::cos(r * 0.07));
    return dem;
}

// Regions that cross the seam (between the last and first column), the middle column, both
// poles, with pieces touching across the seam at a corner, a hole at the seam, Voronoi
// cells elsewhere.
// (Given in 1-degree cells of column and row; a finer grid scales them.)
std::function<std::uint32_t(int, int)> global_labels(const Dem& dem) {
    const auto cells = test::voronoi_cells(dem, 6, 3);
    const int w = dem.width, h = dem.height;
    return [cells, w, h](int x, int y) -> std::uint32_t {
        const int col = x * 360 / w, row = y * 180 / h;
        if (row < 10) return 1;                                 // north cap, all the way round
        if (row >= 170) return col >= 20 && col < 190 ? 2 : 3;  // south: 3 crosses the seam
        if (row >= 40 && row < 60 && (col >= 350 || col < 10)) return 4;  // across the seam
        if (row >= 40 && row < 60 && col >= 170 && col < 190) return 5;   // across column 180
        if (row >= 100 && row < 130 && (col >= 340 || col < 20))
            return row >= 110 && row < 120 && (col >= 355 || col < 5) ? 6 : 7;  // 6 in 7
        if ((col == 359 && row == 80) || (col == 0 && row == 81)) return 8;     // corner pieces
        return 8 + cells(x, y);
    };
}

// Every ring of a lon/lat geometry.
void for_each_ring(const OGRGeometry& g, const std::function<void(const OGRLinearRing&)>& fn) {
    auto polygon = [&](const OGRPolygon& p) {
        fn(*p.getExteriorRing());
        for (int k = 0; k < p.getNumInteriorRings(); ++k) fn(*p.getInteriorRing(k));
    };
    if (wkbFlatten(g.getGeometryType()) == wkbPolygon)
        polygon(*g.toPolygon());
    else
        for (const auto* p : *g.toMultiPolygon()) polygon(*p);
}

// The geodesic area of a lon/lat geometry from its own vertices (as a client computes it),
// the sum of its rings' signed areas. Known modulo the body's area only (a region round
// both poles reads as minus what it leaves out): resolved to the value nearest `expected`.
double geodesic_area_near(const OGRGeometry& g, const GeographicLib::Geodesic& geodesic,
                          double expected) {
    double sum = 0;
    for_each_ring(g, [&](const OGRLinearRing& ring) {
        GeographicLib::PolygonArea polygon(geodesic);
        for (int i = 0; i + 1 < ring.getNumPoints(); ++i)
            polygon.AddPoint(ring.getY(i), ring.getX(i));
        double perimeter = 0, area = 0;
        polygon.Compute(false, true, perimeter, area);
        sum += area;
    });
    const double whole = geodesic.EllipsoidArea();
    return sum + whole * std::round((expected - sum) / whole);
}

// The area of each label's pixels on the body, a sphere here: the pixels of a global grid
// as it means them, rows of 180/height degrees from pole to pole, of 360/width degrees each.
std::vector<double> pixel_areas_by_label(const test::SegmentedTile& t) {
    const double R = t.dem.body.semi_major_axis, degree = std::acos(-1.0) / 180;
    std::vector<double> area(t.region_count + 1, 0.0);
    for (int row = 0; row < t.dem.height; ++row) {
        const double north = 90 - row * 180.0 / t.dem.height;
        const double south = 90 - (row + 1) * 180.0 / t.dem.height;
        const double pixel = R * R * (360.0 / t.dem.width * degree) *
                             (std::sin(north * degree) - std::sin(south * degree));
        for (int col = 0; col < t.dem.width; ++col) area[t.pixels[t.dem.index(col, row)]] += pixel;
    }
    return area;
}

// The checks every global grid's polygons must pass: valid, within the longitude range
// [west, west + 360] and +-90, no piece wider than 180 degrees but a pole cap, areas on the
// body those of the pixels (together the body's), and each pixel centre in its region.
void check_global(const Read& r, const test::SegmentedTile& t, double west, int stride = 1) {
    REQUIRE(r.features.size() == t.region_count);
    const GeographicLib::Geodesic geodesic(t.dem.body.semi_major_axis, 0);
    const auto expected = pixel_areas_by_label(t);
    double sum = 0;
    int invalid = 0, out_of_range = 0, wide = 0, area_off = 0;
    for (std::size_t i = 0; i < r.features.size(); ++i) {
        const OGRGeometry* g = r.features[i]->GetGeometryRef();
        REQUIRE(g);
        if (!g->IsValid()) ++invalid;
        const auto* multi =
            wkbFlatten(g->getGeometryType()) == wkbMultiPolygon ? g->toMultiPolygon() : nullptr;
        const int parts = multi ? multi->getNumGeometries() : 1;
        for (int k = 0; k < parts; ++k) {
            const OGRGeometry* part = multi ? multi->getGeometryRef(k) : g;
            OGREnvelope e;
            part->getEnvelope(&e);
            if (e.MinX < west || e.MaxX > west + 360 || e.MinY < -90 || e.MaxY > 90) ++out_of_range;
            const bool pole = e.MaxY == 90 || e.MinY == -90;
            if (e.MaxX - e.MinX > 180 && !pole) ++wide;
        }
        const auto id = static_cast<std::uint32_t>(t.graph.regions[i].id);
        const double pixels = expected[id];
        const double area = geodesic_area_near(*g, geodesic, pixels);
        if (std::abs(area - pixels) > 1e-3 * pixels) {
            ++area_off;
            UNSCOPED_INFO("region " << id << ": " << area << " m2 on the body, pixels " << pixels);
        }
        sum += area;
    }
    CHECK(invalid == 0);
    CHECK(out_of_range == 0);
    CHECK(wide == 0);
    CHECK(area_off == 0);
    const double body = geodesic.EllipsoidArea();
    CHECK(std::abs(sum - body) < 0.005 * body);
    // Every pixel centre (every `stride`th) lies in its own region, at its longitude in the
    // output range.
    std::vector<std::unique_ptr<OGRPreparedGeometry, void (*)(OGRPreparedGeometry*)>> prepared;
    for (const auto& f : r.features)
        prepared.emplace_back(OGRCreatePreparedGeometry(f->GetGeometryRef()),
                              OGRDestroyPreparedGeometry);
    int misplaced = 0;
    for (int row = 0; row < t.dem.height; row += stride)
        for (int col = 0; col < t.dem.width; col += stride) {
            const auto label = t.pixels[t.dem.index(col, row)];
            OGRPoint centre(west + (col + 0.5) * 360.0 / t.dem.width,
                            90 - (row + 0.5) * 180.0 / t.dem.height);
            if (label == 0 || !OGRPreparedGeometryContains(prepared[label - 1].get(),
                                                           OGRGeometry::ToHandle(&centre)))
                ++misplaced;
        }
    CHECK(misplaced == 0);
}

}  // namespace

TEST_CASE("regions.geojson of a global grid: split at the seam, poles closed, areas add up",
          "[write_region_polygons][global]") {
    const double R = 1737400;
    // A lon/lat grid 0..360 and one -180..180; an equirectangular grid centred on 180 E whose
    // rounded map scale (as in LDEM_4's label) overshoots 360 x 180 degrees a little.
    const double overshoot = 1 + 3e-7, step = 2 * std::acos(-1.0) * R / 360 * overshoot;
    const std::string moon_eqc =
        "+proj=eqc +lon_0=180 +R=" + std::to_string(R) + " +units=m +no_defs +type=crs";
    struct Case {
        std::string name, crs;
        GeoTransform t;
        double west;
    };
    const Case cases[] = {
        {"lonlat_0_360", "IAU_2015:30100", {0, 1, 0, 90, 0, -1}, 0},
        {"lonlat_180", "IAU_2015:30100", {-180, 1, 0, 90, 0, -1}, -180},
        {"eqc_180", moon_eqc, {-180 * step, step, 0, 90 * step, 0, -step}, 0},
    };
    for (const auto& c : cases) {
        SECTION(c.name) {
            const Dem dem = global_grid(c.crs, c.t);
            REQUIRE(dem.georef.global_longitude);
            const auto t = test::segment_tile(dem, global_labels(dem));
            REQUIRE(t.region_count > 12);
            const auto dir = test::scratch_dir("write_region_polygons_global_" + c.name);
            const auto path = (dir / "regions.geojson").string();
            io::write_region_polygons(t.dem, t.pixels, t.graph, path, true);
            const auto r = read_features(path);
            check_global(r, t, c.west);
            // Region 4 crosses the seam: two pieces, one at each end of the range.
            const OGRGeometry* across = r.features[3]->GetGeometryRef();
            REQUIRE(wkbFlatten(across->getGeometryType()) == wkbMultiPolygon);
            CHECK(across->toMultiPolygon()->getNumGeometries() == 2);
            OGREnvelope e;
            across->getEnvelope(&e);
            CHECK(e.MinX == c.west);
            CHECK(e.MaxX == c.west + 360);
            // The north cap goes all the way round, up to the pole.
            r.features[0]->GetGeometryRef()->getEnvelope(&e);
            CHECK(e.MinX == c.west);
            CHECK(e.MaxX == c.west + 360);
            CHECK(e.MaxY == 90);
            CHECK(e.MinY == Approx(80).margin(1e-6));

            // A GeoPackage in the DEM's own CRS: lon/lat for a lon/lat grid, else taken to
            // lon/lat by a client that keeps the grid's longitude range (PROJ's +lon_wrap)
            // and puts a vertex every pixel along the edges first: the same checks pass.
            io::RegionPolygonOptions gpkg;
            gpkg.driver = "GPKG";
            const auto gpkg_path = (dir / "regions.gpkg").string();
            io::write_region_polygons(t.dem, t.pixels, t.graph, gpkg_path, true, gpkg);
            auto map = read_features(gpkg_path);
            if (!map.layer->GetSpatialRef()->IsGeographic()) {
                OGRSpatialReference lonlat;
                lonlat.SetFromUserInput(("+proj=longlat +R=" + std::to_string(R) + " +lon_wrap=" +
                                         std::to_string(c.west + 180) + " +no_defs +type=crs")
                                            .c_str());
                lonlat.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
                std::unique_ptr<OGRCoordinateTransformation> ct(
                    OGRCreateCoordinateTransformation(map.layer->GetSpatialRef(), &lonlat));
                REQUIRE(ct);
                for (auto& f : map.features) {
                    f->GetGeometryRef()->segmentize(step);
                    REQUIRE(f->GetGeometryRef()->transform(ct.get()) == 0);
                }
            }
            check_global(map, t, c.west);
        }
    }
}

TEST_CASE("regions.geojson of LDEM_4 (0..360): valid, within range, areas add up",
          "[write_region_polygons][global][real_data]") {
    const auto source = test::real_data("moon_lola_ldem4/LDEM_4.LBL");
    REQUIRE(source.has_value());
    const Dem ldem = io::read_dem(*source);
    REQUIRE(ldem.georef.global_longitude);
    const auto t = test::segment_tile(ldem, global_labels(ldem));
    const auto dir = test::scratch_dir("write_region_polygons_ldem4");
    const auto path = (dir / "regions.geojson").string();
    io::write_region_polygons(t.dem, t.pixels, t.graph, path, true);
    check_global(read_features(path), t, 0, 3);
}
