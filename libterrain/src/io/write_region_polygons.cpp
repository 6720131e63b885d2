#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <variant>

#include "dataset_files.hpp"
#include "gdal_support.hpp"
#include "geojson_file.hpp"
#include "global_outline.hpp"
#include "gpkg_support.hpp"
#include "label_style.hpp"
#include "lonlat_frame.hpp"
#include "polygon_style.hpp"
#include "region_attributes.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/region_colour.hpp"
#include "terrain/io/write_region_polygons.hpp"

namespace terrain::io {
namespace {

using Geometry = std::unique_ptr<OGRGeometry>;

// GDALPolygonize's pieces (one polygon per 4-connected piece of a region, label 0 masked
// out), spilled as WKB to an unlinked temporary file as they come, then read back region by
// region: the outlines are never all in memory (on a 265 M pixel global grid they are
// hundreds of MB). Only 16 bytes a piece stay. The pieces of a region touch at most at
// corners, so collecting them is their union (a valid MultiPolygon); they are collected in
// the order GDALPolygonize gave them.
class PieceFile {
  public:
    explicit PieceFile(std::filesystem::path dir) {
        if (dir.empty()) dir = std::filesystem::temp_directory_path();
        dir_ = dir.string();
        std::string name = (dir / ".terrain-polygons-XXXXXX").string();
        fd_ = ::mkstemp(name.data());
        if (fd_ < 0)
            throw Error("write", "cannot create a temporary file in '" + dir_ +
                                     "': " + std::strerror(errno));
        ::unlink(name.c_str());  // gone with the descriptor, whatever happens
    }
    ~PieceFile() {
        if (fd_ >= 0) ::close(fd_);
    }
    PieceFile(const PieceFile&) = delete;
    PieceFile& operator=(const PieceFile&) = delete;

    void add(std::uint32_t label, const OGRGeometry& g) {
        const std::size_t bytes = g.WkbSize();
        if (bytes > std::numeric_limits<std::uint32_t>::max())
            throw Error("write", "a region's polygon piece is larger than 4 GB");
        const std::size_t at = buffer_.size();
        buffer_.resize(at + bytes);
        if (g.exportToWkb(wkbNDR, buffer_.data() + at) != OGRERR_NONE)
            throw Error("write", "cannot encode a region's polygon");
        pieces_.push_back({size_, static_cast<std::uint32_t>(bytes), label});
        size_ += bytes;
        if (buffer_.size() >= kBuffer) flush();
    }

    // After the last piece: flushed, and the pieces grouped by label (1..region_count).
    void finish(std::size_t region_count) {
        flush();
        std::vector<unsigned char>().swap(buffer_);
        first_.assign(region_count + 1, 0);
        for (const Piece& p : pieces_) ++first_[p.label];
        for (std::size_t i = 1; i < first_.size(); ++i) first_[i] += first_[i - 1];
        std::vector<std::uint64_t> at(first_.begin(), first_.end() - 1);
        order_.resize(pieces_.size());
        for (std::size_t k = 0; k < pieces_.size(); ++k)
            order_[at[pieces_[k].label - 1]++] = static_cast<std::uint32_t>(k);
    }
    std::size_t region_count() const { return first_.empty() ? 0 : first_.size() - 1; }

    // The polygon of region index i (id i + 1): a Polygon, a MultiPolygon, or null when the
    // region has no pixel. Safe to call from several threads at once.
    Geometry region(std::size_t i) const {
        Geometry g;
        std::vector<unsigned char> wkb;
        for (std::uint64_t k = first_[i]; k < first_[i + 1]; ++k) {
            const Piece& p = pieces_[order_[k]];
            wkb.resize(p.bytes);
            read_at(p.offset, wkb.data(), p.bytes);
            OGRGeometry* raw = nullptr;
            if (OGRGeometryFactory::createFromWkb(wkb.data(), nullptr, &raw, p.bytes) !=
                    OGRERR_NONE ||
                !raw)
                throw Error("write", "cannot read back a region's polygon from '" + dir_ + "'");
            Geometry piece(raw);
            if (!g) {
                g = std::move(piece);
                continue;
            }
            if (wkbFlatten(g->getGeometryType()) == wkbPolygon) {
                auto multi = std::make_unique<OGRMultiPolygon>();
                multi->addGeometryDirectly(g.release());
                g = std::move(multi);
            }
            g->toMultiPolygon()->addGeometryDirectly(piece.release());
        }
        return g;
    }

  private:
    static constexpr std::size_t kBuffer = std::size_t{4} << 20;
    struct Piece {
        std::uint64_t offset;
        std::uint32_t bytes;
        std::uint32_t label;
    };
    void flush() {
        const unsigned char* data = buffer_.data();
        std::size_t left = buffer_.size();
        while (left > 0) {
            const ssize_t n = ::write(fd_, data, left);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0)
                throw Error("write", "cannot write the region polygons' temporary file in '" +
                                         dir_ + "': " + std::strerror(n < 0 ? errno : ENOSPC));
            data += n;
            left -= static_cast<std::size_t>(n);
        }
        buffer_.clear();
    }
    void read_at(std::uint64_t offset, unsigned char* data, std::size_t bytes) const {
        while (bytes > 0) {
            const ssize_t n = ::pread(fd_, data, bytes, static_cast<off_t>(offset));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0)
                throw Error("write",
                            "cannot read the region polygons' temporary file in '" + dir_ + "'");
            data += n;
            bytes -= static_cast<std::size_t>(n);
            offset += static_cast<std::uint64_t>(n);
        }
    }

    int fd_ = -1;
    std::string dir_;
    std::vector<unsigned char> buffer_;
    std::uint64_t size_ = 0;
    std::vector<Piece> pieces_;
    std::vector<std::uint64_t> first_;  // by region index: its first entry in order_
    std::vector<std::uint32_t> order_;  // pieces grouped by label, each group in given order
};

// The layer GDALPolygonize writes into: each feature goes to the piece file.
class PieceLayer final : public OGRLayer {
  public:
    PieceLayer(PieceFile& file, std::size_t region_count)
        : file_(file), region_count_(region_count), defn_(new OGRFeatureDefn("regions")) {
        defn_->Reference();
        defn_->SetGeomType(wkbPolygon);
        OGRFieldDefn id("id", OFTInteger);
        defn_->AddFieldDefn(&id);
    }
    ~PieceLayer() override { defn_->Release(); }
    OGRFeatureDefn* GetLayerDefn() override { return defn_; }
    void ResetReading() override {}
    OGRFeature* GetNextFeature() override { return nullptr; }
    int TestCapability(const char* capability) override {
        return EQUAL(capability, OLCSequentialWrite);
    }
    const std::string& failure() const { return failure_; }

  protected:
    OGRErr ICreateFeature(OGRFeature* feature) override {
        const auto label = static_cast<std::size_t>(feature->GetFieldAsInteger(0));
        const OGRGeometry* g = feature->GetGeometryRef();
        if (label == 0 || label > region_count_ || !g) return OGRERR_NONE;
        try {
            file_.add(static_cast<std::uint32_t>(label), *g);
        } catch (const Error& e) {
            failure_ = e.what();
            return OGRERR_FAILURE;
        }
        return OGRERR_NONE;
    }

  private:
    PieceFile& file_;
    std::size_t region_count_;
    OGRFeatureDefn* defn_;
    std::string failure_;
};

// The pieces of every region of `pixels`, in the DEM's map coordinates, spilled to a
// temporary file in `dir` (the system's temporary directory when empty).
std::unique_ptr<PieceFile> polygonize(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                                      std::size_t region_count, const std::filesystem::path& dir,
                                      const GdalErrorCapture& errors,
                                      const ProgressFn& progress = {}) {
    // A band over the labels themselves, not a copy (4 bytes a pixel less).
    const auto raster = labels_in_place(dem, {&pixels}, dir.string(), errors);
    GDALRasterBand* band = raster->GetRasterBand(1);
    auto file = std::make_unique<PieceFile>(dir);
    PieceLayer layer(*file, region_count);
    GdalProgress reported{progress};
    const CPLErr done = GDALPolygonize(band, band, OGRLayer::ToHandle(&layer), 0, nullptr,
                                       GdalProgress::call, &reported);
    reported.rethrow_if_stopped();
    if (done != CE_None)
        throw Error("write", layer.failure().empty() ? "GDALPolygonize failed" + errors.suffix()
                                                     : layer.failure());
    file->finish(region_count);
    return file;
}

// Every ring to lon/lat (when `frame`), through `global` for a global grid (its seam and
// poles also in map coordinates), exterior rings counter-clockwise and holes clockwise
// (RFC 7946).
void prepare_rings(OGRGeometry& g, const LonLatFrame* frame, const GlobalOutline* global) {
    auto polygon_rings = [&](OGRPolygon& polygon) {
        for (int k = 0; k < polygon.getNumInteriorRings() + 1; ++k) {
            OGRLinearRing* ring =
                k == 0 ? polygon.getExteriorRing() : polygon.getInteriorRing(k - 1);
            if (global) {
                if (frame)
                    global->to_lonlat(*ring);
                else
                    global->to_map(*ring);
            } else if (frame) {
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

// The polygon of region index i, made when asked for: a region's outline is written and
// freed before the next one is made.
using RegionSource = std::function<Geometry(std::size_t)>;

void write_geojson(std::ostream& out, const RegionSource& polygon,
                   const segment::RegionGraph& graph, const std::string& crs_name, int decimals) {
    GeoJsonFile file(out, "regions", crs_name, decimals);
    for (std::size_t i = 0; i < graph.regions.size(); ++i) {
        const auto& region = graph.regions[i];
        const Geometry made = polygon(i);
        file.feature(region.id, region_attributes(graph, region), [&](JsonWriter& json) {
            const OGRGeometry* g = made.get();
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
                                   const std::string& path, const RegionSource& polygon,
                                   const segment::RegionGraph& graph,
                                   const OGRSpatialReference* srs, const GdalErrorCapture& errors,
                                   const std::string& layer_name, bool append) {
    // GeoPackage stamps the current time (on creation, on SQL that changes a table, on close)
    // unless told a fixed one: same bytes every run.
    const FixedGpkgDate fixed_date;
    std::unique_ptr<GDALDataset> ds(
        append && std::filesystem::exists(temp)
            ? GDALDataset::Open(temp.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE)
            : driver.Create(temp.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!ds) throw Error("write", "cannot create '" + path + "'" + errors.suffix());
    // A shapefile's .dbf header holds a date, today's unless given: a fixed one keeps the
    // bytes the same run to run.
    CPLStringList layer_options;
    if (std::string(driver.GetDescription()) == "ESRI Shapefile")
        layer_options.SetNameValue("DBF_DATE_LAST_UPDATE", "2000-01-01");
    OGRLayer* layer = ds->CreateLayer(layer_name.c_str(), const_cast<OGRSpatialReference*>(srs),
                                      wkbMultiPolygon, layer_options.List());
    if (!layer) throw Error("write", "cannot create a layer in '" + path + "'" + errors.suffix());
    const bool gpkg = std::string(driver.GetDescription()) == "GPKG";
    if (graph.regions.empty()) {
        if (gpkg) add_wkt2_definitions(*ds, srs, path, errors);
        return dataset_files(ds.get());
    }
    create_attribute_fields(*layer, region_attributes(graph, graph.regions.front()), path, errors);
    const bool transaction = ds->StartTransaction() == OGRERR_NONE;
    for (std::size_t i = 0; i < graph.regions.size(); ++i) {
        OGRFeature feature(layer->GetLayerDefn());
        set_attribute_fields(feature, region_attributes(graph, graph.regions[i]));
        if (Geometry g = polygon(i))
            feature.SetGeometryDirectly(OGRGeometryFactory::forceToMultiPolygon(g.release()));
        if (layer->CreateFeature(&feature) != OGRERR_NONE)
            throw Error("write", "cannot write region " + std::to_string(graph.regions[i].id) +
                                     " to '" + path + "'" + errors.suffix());
    }
    if (transaction && ds->CommitTransaction() != OGRERR_NONE)
        throw Error("write", "writing '" + path + "' failed" + errors.suffix());
    if (gpkg) {
        add_layer_style(*ds, layer_name, layer_name, true, "region colours (terrain)",
                        polygon_style_qml(graph), path, errors);
        add_layer_style(*ds, layer_name, layer_name + " by landform", false,
                        "landform classes of the shape index (terrain)", landform_style_qml(), path,
                        errors);
        add_wkt2_definitions(*ds, srs, path, errors);
    }
    auto files = dataset_files(ds.get());
    CPLErrorReset();
    ds.reset();
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

// Writes the polygons of `made` (in the DEM's map coordinates), region by region, reporting
// each region made (0 to 1 of `progress`).
void write_polygons(const Dem& dem, const RegionSource& made, const segment::RegionGraph& graph,
                    const std::string& path, bool overwrite, const RegionPolygonOptions& options,
                    GDALDriver* driver, const GdalErrorCapture& errors,
                    const ProgressFn& progress = {}) {
    const bool geojson = driver == nullptr;
    std::optional<LonLatFrame> frame;
    if (!dem.crs_wkt.empty() && (geojson || options.lonlat)) frame.emplace(dem, "write");
    // A global grid's seam and poles, in lon/lat or in the DEM's map coordinates.
    std::optional<LonLatFrame> global_frame;
    std::optional<GlobalOutline> global;
    if (GlobalOutline::applies(dem)) {
        if (!frame) global_frame.emplace(dem, "write");
        global.emplace(dem, frame ? *frame : *global_frame);
    }
    const RegionSource polygons = [&](std::size_t i) {
        report_progress(
            progress, double(i) / double(std::max<std::size_t>(1, graph.regions.size())), "write");
        Geometry g = made(i);
        if (g) prepare_rings(*g, frame ? &*frame : nullptr, global ? &*global : nullptr);
        return g;
    };

    if (geojson) {
        // Lon/lat to 1e-9 degree (0.1 mm on Earth); metres to 1e-6.
        // A DEM without CRS names a local grid, so that no reader takes it for WGS 84.
        const std::string crs =
            frame ? geojson_crs_name(geo::output_crs_wkt(frame->wkt())) : local_grid_crs_wkt();
        write_file_atomically(path, overwrite, [&](std::ostream& out) {
            write_geojson(out, polygons, graph, crs, frame ? 9 : 6);
        });
        return;
    }
    {
        std::unique_ptr<OGRSpatialReference> srs;
        // A planetary CRS as the IAU_2015 CRS of its body, when PROJ holds it.
        if (frame) {
            srs = std::make_unique<OGRSpatialReference>();
            srs->SetFromUserInput(geo::output_crs_wkt(frame->wkt()).c_str());
            srs->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
        } else if (!dem.crs_wkt.empty()) {
            srs = std::make_unique<OGRSpatialReference>();
            srs->SetFromUserInput(geo::output_crs_wkt(dem.crs_wkt).c_str());
            srs->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
        } else {
            // No CRS: a local engineering CRS rather than none (GeoPackage's undefined SRS
            // 0 is a geographic one).
            srs = std::make_unique<OGRSpatialReference>();
            srs->SetFromUserInput(local_grid_crs_wkt().c_str());
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

void check_polygon_format(const Dem& dem, const std::string& driver) {
    if (driver != "KML" && driver != "LIBKML" && driver != "GPX") return;
    if (!dem.crs_wkt.empty() && dem.body.name == "Earth") return;
    const std::string where =
        dem.crs_wkt.empty()
            ? std::string("the local metres of a DEM without CRS")
            : "coordinates on " +
                  (dem.body.name == "unknown" ? std::string("another body") : dem.body.name);
    throw Error("write", driver + " holds Earth's WGS 84 longitude/latitude only, not " + where +
                             ": use --format GPKG (or GeoJSON)");
}

struct RegionPolygons::Impl {
    std::unique_ptr<PieceFile> pieces;  // read back region by region
};
RegionPolygons::RegionPolygons() : impl_(std::make_unique<Impl>()) {}
RegionPolygons::RegionPolygons(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RegionPolygons::~RegionPolygons() = default;
RegionPolygons::RegionPolygons(RegionPolygons&&) noexcept = default;
RegionPolygons& RegionPolygons::operator=(RegionPolygons&&) noexcept = default;
std::size_t RegionPolygons::region_count() const {
    return impl_->pieces ? impl_->pieces->region_count() : 0;
}

RegionPolygons polygonize_regions(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                                  std::size_t region_count, const std::string& temp_dir) {
    check_grid_size(dem, pixels.size());
    ensure_gdal_registered();
    const GdalErrorCapture errors;
    auto impl = std::make_unique<RegionPolygons::Impl>();
    impl->pieces = polygonize(dem, pixels, region_count, temp_dir, errors);
    return RegionPolygons(std::move(impl));
}

void write_region_polygons(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                           const segment::RegionGraph& graph, const std::string& path,
                           bool overwrite, const RegionPolygonOptions& options,
                           const ProgressFn& progress) {
    check_grid_size(dem, pixels.size());
    check_polygon_format(dem, options.driver);
    GDALDriver* driver = polygon_driver(path, overwrite, options);
    const GdalErrorCapture errors;
    // The temporary pieces beside the output: on the same disk, as large as it will be.
    // GDALPolygonize 0 to 0.8 of the progress, the regions written to 1.
    const auto pieces =
        polygonize(dem, pixels, graph.regions.size(), std::filesystem::absolute(path).parent_path(),
                   errors, scaled_progress(progress, 0, 0.8));
    write_polygons(
        dem, [&](std::size_t i) { return pieces->region(i); }, graph, path, overwrite, options,
        driver, errors, scaled_progress(progress, 0.8, 1));
}

void write_region_polygons(const Dem& dem, const RegionPolygons& polygons,
                           const segment::RegionGraph& graph, const std::string& path,
                           bool overwrite, const RegionPolygonOptions& options) {
    if (polygons.region_count() != graph.regions.size())
        throw Error("write", "the polygons were made for " +
                                 std::to_string(polygons.region_count()) +
                                 " regions, the graph has " + std::to_string(graph.regions.size()));
    check_polygon_format(dem, options.driver);
    GDALDriver* driver = polygon_driver(path, overwrite, options);
    const GdalErrorCapture errors;
    const PieceFile& pieces = *polygons.impl().pieces;
    write_polygons(
        dem, [&](std::size_t i) { return pieces.region(i); }, graph, path, overwrite, options,
        driver, errors);
}

}  // namespace terrain::io
