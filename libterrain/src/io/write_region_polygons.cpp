#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <variant>

#include "dataset_files.hpp"
#include "gdal_support.hpp"
#include "geojson_file.hpp"
#include "lonlat_frame.hpp"
#include "region_attributes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_region_polygons.hpp"

namespace terrain::io {
namespace {

using Geometry = std::unique_ptr<OGRGeometry>;

// The region polygons in the DEM's map coordinates, indexed by id - 1: GDALPolygonize
// (4-connected pixels, label 0 masked out) gives one polygon per connected piece; the pieces
// of a region touch at most at corners, so collecting them is their union (valid
// MultiPolygon).
std::vector<Geometry> polygonize(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                                 std::size_t region_count, const GdalErrorCapture& errors) {
    GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
    std::unique_ptr<GDALDataset> raster(
        mem->Create("", dem.width, dem.height, 1, GDT_UInt32, nullptr));
    GDALDriver* memory = GetGDALDriverManager()->GetDriverByName("Memory");
    std::unique_ptr<GDALDataset> vector(memory ? memory->Create("", 0, 0, 0, GDT_Unknown, nullptr)
                                               : nullptr);
    if (!raster || !vector) throw Error("write", "GDAL's in-memory drivers are missing");
    GeoTransform t = dem.transform;
    raster->SetGeoTransform(t.data());
    GDALRasterBand* band = raster->GetRasterBand(1);
    if (band->RasterIO(GF_Write, 0, 0, dem.width, dem.height,
                       const_cast<std::uint32_t*>(pixels.data()), dem.width, dem.height, GDT_UInt32,
                       0, 0) != CE_None)
        throw Error("write", "cannot fill the label raster to polygonize" + errors.suffix());
    OGRLayer* layer = vector->CreateLayer("regions", nullptr, wkbPolygon, nullptr);
    OGRFieldDefn id("id", OFTInteger);
    if (!layer || layer->CreateField(&id) != OGRERR_NONE)
        throw Error("write", "cannot create the polygon layer" + errors.suffix());
    if (GDALPolygonize(band, band, layer, 0, nullptr, nullptr, nullptr) != CE_None)
        throw Error("write", "GDALPolygonize failed" + errors.suffix());

    std::vector<Geometry> out(region_count);
    layer->ResetReading();
    for (std::unique_ptr<OGRFeature> f(layer->GetNextFeature()); f;
         f.reset(layer->GetNextFeature())) {
        const auto label = static_cast<std::size_t>(f->GetFieldAsInteger(0));
        if (label == 0 || label > region_count) continue;
        Geometry piece(f->StealGeometry());
        auto& g = out[label - 1];
        if (!g) {
            g = std::move(piece);
        } else {
            if (wkbFlatten(g->getGeometryType()) == wkbPolygon) {
                auto multi = std::make_unique<OGRMultiPolygon>();
                multi->addGeometryDirectly(g.release());
                g = std::move(multi);
            }
            g->toMultiPolygon()->addGeometryDirectly(piece.release());
        }
    }
    return out;
}

// Every ring to lon/lat (when `frame`), exterior rings counter-clockwise and holes clockwise
// (RFC 7946).
void prepare_rings(OGRGeometry& g, const LonLatFrame* frame) {
    auto polygon_rings = [&](OGRPolygon& polygon) {
        for (int k = 0; k < polygon.getNumInteriorRings() + 1; ++k) {
            OGRLinearRing* ring =
                k == 0 ? polygon.getExteriorRing() : polygon.getInteriorRing(k - 1);
            if (frame) {
                const int n = ring->getNumPoints();
                std::vector<double> x(static_cast<std::size_t>(n)), y(x.size());
                ring->getPoints(x.data(), sizeof(double), y.data(), sizeof(double));
                if (!frame->transform(x.size(), x.data(), y.data()))
                    throw Error("write", "a region's outline has no longitude/latitude");
                ring->setPoints(n, x.data(), y.data());
            }
            if (ring->isClockwise() == (k == 0)) ring->reverseWindingOrder();
        }
    };
    if (wkbFlatten(g.getGeometryType()) == wkbPolygon) {
        polygon_rings(*g.toPolygon());
    } else {
        for (auto* part : *g.toMultiPolygon()) polygon_rings(*part);
    }
}

void write_ring(JsonWriter& json, const GeoJsonFile& file, const OGRLinearRing& ring) {
    json.begin_array();
    for (int i = 0; i < ring.getNumPoints(); ++i) file.position(json, ring.getX(i), ring.getY(i));
    json.end_array();
}

void write_polygon(JsonWriter& json, const GeoJsonFile& file, const OGRPolygon& polygon) {
    json.begin_array();
    write_ring(json, file, *polygon.getExteriorRing());
    for (int k = 0; k < polygon.getNumInteriorRings(); ++k)
        write_ring(json, file, *polygon.getInteriorRing(k));
    json.end_array();
}

void write_geojson(std::ostream& out, const std::vector<Geometry>& polygons,
                   const segment::RegionGraph& graph, const std::string& crs_name, int decimals) {
    GeoJsonFile file(out, "regions", crs_name, decimals);
    for (std::size_t i = 0; i < graph.regions.size(); ++i) {
        const auto& region = graph.regions[i];
        file.feature(region.id, region_attributes(graph, region), [&](JsonWriter& json) {
            const OGRGeometry* g = polygons[i].get();
            if (!g) {
                json.null();
            } else if (wkbFlatten(g->getGeometryType()) == wkbPolygon) {
                json.begin_object().field("type", "Polygon").key("coordinates");
                write_polygon(json, file, *g->toPolygon());
                json.end_object();
            } else {
                json.begin_object().field("type", "MultiPolygon").key("coordinates");
                json.begin_array();
                for (const auto* part : *g->toMultiPolygon()) write_polygon(json, file, *part);
                json.end_array().end_object();
            }
        });
    }
    file.finish();
}

// Any other OGR driver: one layer "regions", MultiPolygon features, every attribute a field.
std::vector<std::string> write_ogr(GDALDriver& driver, const std::string& temp,
                                   const std::string& path, std::vector<Geometry>& polygons,
                                   const segment::RegionGraph& graph,
                                   const OGRSpatialReference* srs, const GdalErrorCapture& errors,
                                   const std::string& layer_name, bool append) {
    // GeoPackage stamps the current time unless told a fixed one: same bytes every run.
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", "2000-01-01T00:00:00.000Z");
    std::unique_ptr<GDALDataset> ds(
        append && std::filesystem::exists(temp)
            ? GDALDataset::Open(temp.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE)
            : driver.Create(temp.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", nullptr);
    if (!ds) throw Error("write", "cannot create '" + path + "'" + errors.suffix());
    // A shapefile's .dbf header holds a date, today's unless given: a fixed one keeps the
    // bytes the same run to run.
    CPLStringList layer_options;
    if (std::string(driver.GetDescription()) == "ESRI Shapefile")
        layer_options.SetNameValue("DBF_DATE_LAST_UPDATE", "2000-01-01");
    OGRLayer* layer = ds->CreateLayer(layer_name.c_str(), const_cast<OGRSpatialReference*>(srs),
                                      wkbMultiPolygon, layer_options.List());
    if (!layer) throw Error("write", "cannot create a layer in '" + path + "'" + errors.suffix());
    if (graph.regions.empty()) return dataset_files(ds.get());
    for (const auto& [name, value] : region_attributes(graph, graph.regions.front())) {
        const OGRFieldType type =
            std::holds_alternative<std::int64_t>(value)
                ? OFTInteger64
                : (std::holds_alternative<double>(value) ? OFTReal : OFTString);
        OGRFieldDefn field(name.c_str(), type);
        if (layer->CreateField(&field) != OGRERR_NONE)
            throw Error("write",
                        "cannot create field '" + name + "' in '" + path + "'" + errors.suffix());
    }
    const bool transaction = ds->StartTransaction() == OGRERR_NONE;
    for (std::size_t i = 0; i < graph.regions.size(); ++i) {
        OGRFeature feature(layer->GetLayerDefn());
        int k = 0;
        for (const auto& [name, value] : region_attributes(graph, graph.regions[i])) {
            if (const auto* n = std::get_if<std::int64_t>(&value))
                feature.SetField(k, static_cast<GIntBig>(*n));
            else if (const auto* d = std::get_if<double>(&value))
                feature.SetField(k, *d);
            else
                feature.SetField(k, std::get<std::string>(value).c_str());
            ++k;
        }
        if (polygons[i])
            feature.SetGeometryDirectly(
                OGRGeometryFactory::forceToMultiPolygon(polygons[i].release()));
        if (layer->CreateFeature(&feature) != OGRERR_NONE)
            throw Error("write", "cannot write region " + std::to_string(graph.regions[i].id) +
                                     " to '" + path + "'" + errors.suffix());
    }
    if (transaction && ds->CommitTransaction() != OGRERR_NONE)
        throw Error("write", "writing '" + path + "' failed" + errors.suffix());
    auto files = dataset_files(ds.get());
    CPLErrorReset();
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", "2000-01-01T00:00:00.000Z");
    ds.reset();
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", nullptr);
    if (CPLGetLastErrorType() >= CE_Failure)
        throw Error("write", "closing '" + path + "' failed" + errors.suffix());
    return files;
}

// The driver for `options` (nullptr for GeoJSON, written by hand), after the checks made
// before any work: a vector driver that creates files, one layer for GeoJSON, the path.
GDALDriver* polygon_driver(const std::string& path, bool overwrite,
                           const RegionPolygonOptions& options) {
    ensure_gdal_registered();
    const bool geojson = options.driver == "GeoJSON";
    GDALDriver* driver = nullptr;
    if (!geojson) {
        driver = GetGDALDriverManager()->GetDriverByName(options.driver.c_str());
        if (!driver || !driver->GetMetadataItem(GDAL_DCAP_VECTOR) ||
            !driver->GetMetadataItem(GDAL_DCAP_CREATE))
            throw Error("write", "'" + options.driver +
                                     "' is not an OGR vector driver that creates files; try "
                                     "GeoJSON or GPKG");
    }
    if (options.append_layer && geojson)
        throw Error("write", "GeoJSON holds one layer; use GPKG for one layer per scale");
    if (!options.append_layer || !std::filesystem::exists(path)) check_output_path(path, overwrite);
    return driver;
}

// Writes the polygons (taken: their rings are changed in place).
void write_polygons(const Dem& dem, std::vector<Geometry> polygons,
                    const segment::RegionGraph& graph, const std::string& path, bool overwrite,
                    const RegionPolygonOptions& options, GDALDriver* driver,
                    const GdalErrorCapture& errors) {
    const bool geojson = driver == nullptr;
    std::optional<LonLatFrame> frame;
    if (!dem.crs_wkt.empty() && (geojson || options.lonlat)) frame.emplace(dem, "write");
    for (auto& g : polygons)
        if (g) prepare_rings(*g, frame ? &*frame : nullptr);

    if (geojson) {
        // Lon/lat to 1e-9 degree (0.1 mm on Earth); metres to 1e-6.
        const std::string crs = frame ? geojson_crs_name(frame->wkt()) : "";
        write_file_atomically(path, overwrite, [&](std::ostream& out) {
            write_geojson(out, polygons, graph, crs, frame ? 9 : 6);
        });
        return;
    }
    {
        std::unique_ptr<OGRSpatialReference> srs;
        if (frame) {
            srs.reset(frame->srs().Clone());
        } else if (!dem.crs_wkt.empty()) {
            srs = std::make_unique<OGRSpatialReference>();
            srs->SetFromUserInput(dem.crs_wkt.c_str());
            srs->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
        }
        if (options.append_layer) {  // the caller makes the whole directory atomic
            write_ogr(*driver, path, path, polygons, graph, srs.get(), errors, options.layer, true);
            return;
        }
        AtomicOutput output(path, overwrite);
        TemporaryFiles temporary(output);
        const auto files = write_ogr(*driver, output.temp_path(), path, polygons, graph, srs.get(),
                                     errors, options.layer, false);
        commit_dataset(output, files, overwrite);
        temporary.release();
    }
}

}  // namespace

struct RegionPolygons::Impl {
    std::vector<Geometry> geometries;  // by region id - 1; null for a region with no pixel
};
RegionPolygons::RegionPolygons() : impl_(std::make_unique<Impl>()) {}
RegionPolygons::RegionPolygons(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RegionPolygons::~RegionPolygons() = default;
RegionPolygons::RegionPolygons(RegionPolygons&&) noexcept = default;
RegionPolygons& RegionPolygons::operator=(RegionPolygons&&) noexcept = default;
std::size_t RegionPolygons::region_count() const {
    return impl_->geometries.size();
}

RegionPolygons polygonize_regions(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                                  std::size_t region_count) {
    check_grid_size(dem, pixels.size());
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    auto impl = std::make_unique<RegionPolygons::Impl>();
    impl->geometries = polygonize(dem, pixels, region_count, errors);
    return RegionPolygons(std::move(impl));
}

void write_region_polygons(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                           const segment::RegionGraph& graph, const std::string& path,
                           bool overwrite, const RegionPolygonOptions& options) {
    check_grid_size(dem, pixels.size());
    GDALDriver* driver = polygon_driver(path, overwrite, options);
    const GdalErrorCapture errors;
    write_polygons(dem, polygonize(dem, pixels, graph.regions.size(), errors), graph, path,
                   overwrite, options, driver, errors);
}

void write_region_polygons(const Dem& dem, const RegionPolygons& polygons,
                           const segment::RegionGraph& graph, const std::string& path,
                           bool overwrite, const RegionPolygonOptions& options) {
    if (polygons.region_count() != graph.regions.size())
        throw Error("write", "the polygons were made for " +
                                 std::to_string(polygons.region_count()) +
                                 " regions, the graph has " + std::to_string(graph.regions.size()));
    GDALDriver* driver = polygon_driver(path, overwrite, options);
    const GdalErrorCapture errors;
    std::vector<Geometry> copy;
    copy.reserve(polygons.region_count());
    for (const auto& g : polygons.impl().geometries) copy.emplace_back(g ? g->clone() : nullptr);
    write_polygons(dem, std::move(copy), graph, path, overwrite, options, driver, errors);
}

}  // namespace terrain::io
