// The conversions of terrain._terrain's bindings (module_support.hpp): DEMs from arrays,
// the library's results as columns, the sources and options of the Python calls.
#include "module_support.hpp"

#include <ogr_spatialref.h>

namespace terrain::python {

// The CRS text (WKT or anything SetFromUserInput takes, "IAU_2015:30100", "EPSG:32611") as
// WKT2, as read_dem stores it.
std::string crs_to_wkt(const std::string& text) {
    if (text.empty()) return {};
    OGRSpatialReference srs;
    if (srs.SetFromUserInput(text.c_str()) != OGRERR_NONE)
        throw Error("crs", "'" + text + "' is not a CRS GDAL knows (WKT, EPSG:n, IAU_2015:n, ...)");
    char* wkt = nullptr;
    const char* options[] = {"FORMAT=WKT2_2019", nullptr};
    std::string out;
    if (srs.exportToWkt(&wkt, options) == OGRERR_NONE && wkt) out = wkt;
    CPLFree(wkt);
    return out;
}

std::optional<ElevationKind> parse_elevation(const std::string& name) {
    if (name == "auto") return std::nullopt;
    if (const auto kind = value_named(kElevationNames, name)) return *kind;
    throw Error("read", "elevation must be auto, height or radius, not '" + name + "'");
}

Dem dem_from_array(py::array_t<double, py::array::c_style | py::array::forcecast> values,
                   std::optional<std::vector<double>> geotransform, const std::string& crs,
                   const std::string& elevation) {
    if (values.ndim() != 2)
        throw Error("read", "the DEM must be a 2-D array (rows, columns), not " +
                                std::to_string(values.ndim()) + "-D");
    Dem dem;
    dem.height = static_cast<int>(values.shape(0));
    dem.width = static_cast<int>(values.shape(1));
    if (dem.width < 2 || dem.height < 2)
        throw Error("read", "the array is " + std::to_string(dem.width) + "x" +
                                std::to_string(dem.height) +
                                " pixels; a surface needs at least 2x2 pixels");
    if (geotransform) {
        if (geotransform->size() != 6)
            throw Error("read", "a geotransform has 6 numbers (GDAL's order), not " +
                                    std::to_string(geotransform->size()));
        std::copy(geotransform->begin(), geotransform->end(), dem.transform.begin());
        dem.has_transform = true;
    }
    dem.crs_wkt = crs_to_wkt(crs);
    dem.source = "<array>";
    dem.values.assign(values.data(), values.data() + values.size());
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    std::size_t valid = 0;
    for (double& v : dem.values) {
        if (!std::isfinite(v)) {
            v = std::numeric_limits<double>::quiet_NaN();
            continue;
        }
        lo = std::min(lo, v);
        hi = std::max(hi, v);
        ++valid;
    }
    if (valid < 3)
        throw Error("read", "the array has " + std::to_string(valid) +
                                " valid pixel(s); a surface needs at least three");
    geo::georeference(dem);
    const auto kind = parse_elevation(elevation);
    if (kind) {
        dem.elevation = *kind;
        dem.elevation_detected = false;
        if (dem.elevation == ElevationKind::radius && !dem.body.has_crs)
            throw Error("read",
                        "the array has no CRS, so its values cannot be radii of a body; use "
                        "elevation='height'");
    } else {
        dem.elevation = io::detect_elevation_kind(dem.body, lo, hi);
    }
    io::check_dem_on_body(dem);  // issue 53: on its body, as io::read_dem checks
    return dem;
}

py::tuple transform_tuple(const Dem& dem) {
    const auto& t = dem.transform;
    return py::make_tuple(t[0], t[1], t[2], t[3], t[4], t[5]);
}

// The region table as numpy columns.
py::dict region_columns(const segment::RegionGraph& graph) {
    const auto& r = graph.regions;
    const std::size_t n = r.size();
    py::array_t<std::uint32_t> id(n);
    py::array_t<std::int64_t> vertices(n), pixels(n), rep(n), neighbors(n);
    py::array_t<double> area(n), surface(n), mean(n), lo(n), hi(n), px(n), py_(n), pz(n);
    py::list landform;
    for (std::size_t i = 0; i < n; ++i) {
        id.mutable_at(i) = r[i].id;
        vertices.mutable_at(i) = static_cast<std::int64_t>(r[i].vertex_count);
        pixels.mutable_at(i) = static_cast<std::int64_t>(r[i].pixel_count);
        rep.mutable_at(i) = r[i].representative_vertex;
        neighbors.mutable_at(i) = static_cast<std::int64_t>(r[i].neighbor_count);
        area.mutable_at(i) = r[i].area_m2;
        surface.mutable_at(i) = r[i].surface_area_m2;
        mean.mutable_at(i) = r[i].field_mean;
        lo.mutable_at(i) = r[i].field_min;
        hi.mutable_at(i) = r[i].field_max;
        px.mutable_at(i) = r[i].point[0];
        py_.mutable_at(i) = r[i].point[1];
        pz.mutable_at(i) = r[i].point[2];
        landform.append(segment::to_string(r[i].landform));
    }
    py::dict d;
    d["id"] = id;
    d["vertex_count"] = vertices;
    d["pixel_count"] = pixels;
    d["area_m2"] = area;
    d["surface_area_m2"] = surface;
    d["field_mean"] = mean;
    d["field_min"] = lo;
    d["field_max"] = hi;
    d["landform"] = py::module_::import("numpy").attr("array")(landform);
    d["representative_vertex"] = rep;
    d["point_x"] = px;
    d["point_y"] = py_;
    d["point_z"] = pz;
    d["neighbor_count"] = neighbors;
    if (graph.has_field_scale) {  // the radius chosen per pixel (--radius auto)
        py::array_t<double> scale(n);
        for (std::size_t i = 0; i < n; ++i) scale.mutable_at(i) = r[i].field_scale_m;
        d["field_scale_m"] = scale;
    }
    if (graph.has_area_range) {  // the area thresholds each region lives over (--min-area auto)
        py::array_t<double> from(n), to(n);
        for (std::size_t i = 0; i < n; ++i) {
            from.mutable_at(i) = r[i].min_area_from_m2;
            to.mutable_at(i) = r[i].min_area_to_m2;
        }
        d["min_area_from_m2"] = from;
        d["min_area_to_m2"] = to;
    }
    return d;
}

// The crater table as numpy columns (docs/craters.md); lon, lat are map x, y without a CRS.
py::dict crater_columns(const segment::CraterTable& table) {
    const auto& k = table.craters;
    const std::size_t n = k.size();
    py::dict d;
    const auto column = [&](const char* name, auto get) {
        py::array_t<double> a(n);
        for (std::size_t i = 0; i < n; ++i) a.mutable_at(i) = get(k[i]);
        d[name] = a;
    };
    py::array_t<std::uint32_t> id(n), floor(n);
    py::list rims;
    for (std::size_t i = 0; i < n; ++i) {
        id.mutable_at(i) = k[i].id;
        floor.mutable_at(i) = k[i].floor_region;
        rims.append(py::cast(k[i].rim_regions));
    }
    d["id"] = id;
    column(table.lonlat ? "lon" : "x", [](const segment::Crater& c) { return c.lon; });
    column(table.lonlat ? "lat" : "y", [](const segment::Crater& c) { return c.lat; });
    column("col", [](const segment::Crater& c) { return c.col; });
    column("row", [](const segment::Crater& c) { return c.row; });
    column("diameter_m", [](const segment::Crater& c) { return c.diameter_m; });
    column("depth_m", [](const segment::Crater& c) { return c.depth_m; });
    column("rim_height_m", [](const segment::Crater& c) { return c.rim_height_m; });
    column("circularity", [](const segment::Crater& c) { return c.circularity; });
    column("rim_fraction", [](const segment::Crater& c) { return c.rim_fraction; });
    column("fit_rms_m", [](const segment::Crater& c) { return c.fit_rms_m; });
    column("field_scale_m", [](const segment::Crater& c) { return c.field_scale_m; });
    d["floor_region"] = floor;
    d["rim_regions"] = rims;
    column("confidence", [](const segment::Crater& c) { return c.confidence; });
    return d;
}

py::dict edge_columns(const segment::RegionGraph& graph) {
    const auto& e = graph.edges;
    const std::size_t n = e.size();
    py::array_t<std::uint32_t> a(n), b(n);
    py::array_t<double> length(n), contrast(n);
    py::array_t<std::int64_t> mesh_edges(n);
    for (std::size_t i = 0; i < n; ++i) {
        a.mutable_at(i) = e[i].a;
        b.mutable_at(i) = e[i].b;
        length.mutable_at(i) = e[i].boundary_length_m;
        contrast.mutable_at(i) = e[i].contrast;
        mesh_edges.mutable_at(i) = static_cast<std::int64_t>(e[i].mesh_edges);
    }
    py::dict d;
    d["a"] = a;
    d["b"] = b;
    d["boundary_length_m"] = length;
    d["contrast"] = contrast;
    d["mesh_edges"] = mesh_edges;
    return d;
}

const char* point_frame_name(segment::PointFrame f) {
    switch (f) {
        case segment::PointFrame::lonlat:
            return "lonlat";
        case segment::PointFrame::map:
            return "map";
        case segment::PointFrame::mesh:
            return "mesh";
    }
    return "mesh";
}

Source to_source(const py::object& source) {
    Source s;
    if (py::isinstance<Dem>(source))
        s.dem = source.cast<Dem>();
    else
        s.path = py::str(source).cast<std::string>();
    return s;
}

pipeline::Input load(const Source& s, const pipeline::InputOptions& options,
                     const ProgressFn& progress) {
    if (s.dem) {
        Dem copy = *s.dem;
        return pipeline::input_from_dem(std::move(copy), options.frame, progress);
    }
    return pipeline::load_input(*s.path, options, progress);
}

// max_memory: None, a number of bytes, or a size as the command line's --max-memory takes
// it ("512M", "4G").
std::uint64_t memory_limit_argument(const py::object& max_memory) {
    if (max_memory.is_none()) return 0;
    return parse_memory_size(py::str(max_memory).cast<std::string>());
}

// The input options, with the memory plan of computing `field` (pipeline::memory_plan).
pipeline::InputOptions input_options(int band, const std::string& elevation, bool nan_nodata,
                                     std::optional<double> pixel_size, const std::string& frame,
                                     bool repair, const py::object& max_memory,
                                     field::FieldKind field, bool segment) {
    pipeline::InputOptions o;
    o.planned_field = field;
    o.planned_segment = segment;  // pipeline::segment's own plan
    o.max_memory = memory_limit_argument(max_memory);
    o.dem.band = band;
    o.dem.elevation = parse_elevation(elevation);
    o.dem.nan_as_nodata = nan_nodata;
    o.dem.pixel_size = pixel_size;
    o.frame = pipeline::parse_frame(frame);
    o.repair = repair;
    return o;
}

py::object labels_array(const pipeline::Input& input, const std::vector<std::uint32_t>& labels) {
    if (!input.dem) return py::none();
    const auto px = segment::label_pixels(input.mesh, *input.dem, labels);
    return array_2d(px, input.dem->height, input.dem->width);
}

void write_polygons(const pipeline::Input& input, const std::vector<std::uint32_t>& labels,
                    const segment::RegionGraph& regions, const std::string& path,
                    const std::string& driver, const std::string& layer) {
    if (!input.dem) throw Error("write", "region polygons need a DEM; this input is a mesh file");
    const auto px = segment::label_pixels(input.mesh, *input.dem, labels);
    io::RegionPolygonOptions o;
    o.driver = driver;
    o.layer = layer;
    io::write_region_polygons(*input.dem, px, regions, path, true, o);
}

}  // namespace terrain::python
