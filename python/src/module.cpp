// terrain._terrain: the pybind11 extension behind the Python package `terrain`
// (python/terrain/__init__.py wraps it; docs/python.md). Every long call releases the GIL;
// progress goes to an optional Python callable, called with the GIL held.
#include <ogr_spatialref.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "terrain/core/error.hpp"
#include "terrain/core/huge_pages.hpp"
#include "terrain/core/memory_budget.hpp"
#include "terrain/core/version.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/geo/georeference.hpp"
#include "terrain/io/read_dem.hpp"
#include "terrain/io/write_region_polygons.hpp"
#include "terrain/pipeline/segment.hpp"
#include "terrain/pipeline/sweep.hpp"
#include "terrain/reeb/simplify.hpp"

namespace py = pybind11;
using namespace terrain;

namespace {

// A Python progress callable as a ProgressFn. The callable gets (fraction, message); a
// return of False cancels. A Python exception raised in it (KeyboardInterrupt included) also
// cancels, and is raised again once the library call has returned.
class PythonProgress {
  public:
    explicit PythonProgress(py::object callable) : callable_(std::move(callable)) {}

    ProgressFn function() {
        return [this](double fraction, std::string_view message) {
            py::gil_scoped_acquire gil;
            std::lock_guard<std::mutex> lock(mutex_);
            if (error_) return false;
            if (PyErr_CheckSignals() != 0) {
                error_ = std::make_unique<py::error_already_set>();
                return false;
            }
            if (callable_.is_none()) return true;
            try {
                const py::object r = callable_(fraction, std::string(message));
                return r.is_none() || r.cast<bool>();
            } catch (py::error_already_set& e) {
                error_ = std::make_unique<py::error_already_set>(std::move(e));
                return false;
            }
        };
    }
    // Raises the callable's exception, if there was one.
    void rethrow() {
        if (error_) {
            auto e = std::move(error_);
            throw std::move(*e);
        }
    }

  private:
    py::object callable_;
    std::mutex mutex_;
    std::unique_ptr<py::error_already_set> error_;
};

// Runs f without the GIL, forwarding progress to `progress` (a callable or None).
template <class F>
auto run(const py::object& progress, F&& f) {
    PythonProgress p(progress);
    const ProgressFn fn = p.function();
    try {
        py::gil_scoped_release release;
        return f(fn);
    } catch (const Error&) {
        p.rethrow();
        throw;
    }
}

template <class T>
py::array_t<T> array_2d(const std::vector<T>& v, int height, int width) {
    py::array_t<T> a({static_cast<py::ssize_t>(height), static_cast<py::ssize_t>(width)});
    std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
    return a;
}

template <class T>
py::array_t<T> array_1d(const std::vector<T>& v) {
    py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
    if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
    return a;
}

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
    if (name == "height") return ElevationKind::height;
    if (name == "radius") return ElevationKind::radius;
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

struct Source {
    std::optional<std::string> path;
    std::optional<Dem> dem;
};

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
                                     const std::string& field, bool segment = false) {
    pipeline::InputOptions o;
    o.planned_field = field;
    o.planned_segment = segment;  // pipeline::segment's own plan
    o.max_memory = memory_limit_argument(max_memory);
    o.dem.band = band;
    o.dem.elevation = parse_elevation(elevation);
    o.dem.nan_as_nodata = nan_nodata;
    o.dem.pixel_size = pixel_size;
    o.frame = frame;
    o.repair = repair;
    pipeline::parse_frame(frame);
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

}  // namespace

PYBIND11_MODULE(_terrain, m) {
    m.doc() = "terrain's C++ library (use the package `terrain`, which wraps it)";
    static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Error& e) {
            error(e.what());
        }
    });
    m.attr("__version__") = version();

    py::class_<Dem>(m, "Dem", "A DEM grid: values in metres (NaN = NoData), geotransform, CRS.")
        .def_property_readonly("width", [](const Dem& d) { return d.width; })
        .def_property_readonly("height", [](const Dem& d) { return d.height; })
        .def_property_readonly("shape",
                               [](const Dem& d) { return py::make_tuple(d.height, d.width); })
        .def_property_readonly(
            "values", [](const Dem& d) { return array_2d(d.values, d.height, d.width); },
            "The elevations as a (rows, columns) float64 array, NaN where NoData (a copy).")
        .def_property_readonly(
            "geotransform",
            [](const Dem& d) -> py::object {
                return d.has_transform ? py::object(transform_tuple(d)) : py::object(py::none());
            },
            "GDAL's six geotransform numbers, or None for a raster without one.")
        .def_property_readonly(
            "crs", [](const Dem& d) { return d.crs_wkt; }, "The CRS as WKT ('' for none).")
        .def_property_readonly("body", [](const Dem& d) { return d.body.name; })
        .def_property_readonly("elevation",
                               [](const Dem& d) { return std::string(to_string(d.elevation)); })
        .def_property_readonly("source", [](const Dem& d) { return d.source; })
        .def_property_readonly("band", [](const Dem& d) { return d.band; })
        .def("__repr__", [](const Dem& d) {
            return "<terrain.Dem " + std::to_string(d.width) + "x" + std::to_string(d.height) +
                   " " + d.body.name + " (" + to_string(d.elevation) + ") from " + d.source + ">";
        });

    m.def(
        "read_dem",
        [](const std::string& path, int band, const std::string& elevation, bool nan_nodata,
           std::optional<double> pixel_size) {
            io::ReadDemOptions o;
            o.band = band;
            o.elevation = parse_elevation(elevation);
            o.nan_as_nodata = nan_nodata;
            o.pixel_size = pixel_size;
            py::gil_scoped_release release;
            return io::read_dem(path, o);
        },
        py::arg("path"), py::arg("band") = 1, py::arg("elevation") = "auto",
        py::arg("nan_nodata") = false, py::arg("pixel_size") = py::none());
    m.def("page_use", &huge_page_use,
          "How this process's large arrays are paged: 'huge' (transparent huge pages: the kernel "
          "gives them to every large mapping, or Python was started with "
          "GLIBC_TUNABLES=glibc.malloc.hugetlb=1) or 'normal'. Speed only: results are the same.");
    m.def("dem_from_array", &dem_from_array, py::arg("values"),
          py::arg("geotransform") = py::none(), py::arg("crs") = "", py::arg("elevation") = "auto");

    py::class_<pipeline::SegmentOptions>(m, "SegmentOptions")
        .def(py::init<>())
        .def_readwrite("field", &pipeline::SegmentOptions::field)
        .def_property(
            "rings", [](const pipeline::SegmentOptions& o) { return o.shape_index.rings; },
            [](pipeline::SegmentOptions& o, int v) { o.shape_index.rings = v; })
        .def_property(
            "radius",
            [](const pipeline::SegmentOptions& o) -> py::object {
                if (o.shape_index.auto_scale) return py::str("auto");
                return py::float_(o.shape_index.radius);
            },
            [](pipeline::SegmentOptions& o, const py::object& v) {
                // Metres, or "auto": the radius chosen per vertex (docs/field.md).
                if (py::isinstance<py::str>(v)) {
                    if (v.cast<std::string>() != "auto")
                        throw Error("options", "radius takes metres or \"auto\", not '" +
                                                   v.cast<std::string>() + "'");
                    o.shape_index.auto_scale = true;
                    return;
                }
                o.shape_index.auto_scale = false;
                o.shape_index.radius = v.cast<double>();
            })
        .def_property(
            "radii", [](const pipeline::SegmentOptions& o) { return o.shape_index.radii; },
            [](pipeline::SegmentOptions& o, const std::vector<double>& v) {
                o.shape_index.radii = v;
            })
        .def_readwrite("landform_defaults", &pipeline::SegmentOptions::landform_defaults)
        .def_property(
            "window",
            [](const pipeline::SegmentOptions& o) {
                return o.shape_index.window == field::ShapeIndexWindow::disk ? "disk" : "ball";
            },
            [](pipeline::SegmentOptions& o, const std::string& v) {
                if (v != "disk" && v != "ball")
                    throw Error("options", "window must be disk or ball, not '" + v + "'");
                o.shape_index.window =
                    v == "disk" ? field::ShapeIndexWindow::disk : field::ShapeIndexWindow::ball;
            })
        .def_readwrite("rays", &pipeline::SegmentOptions::rays)
        .def_readwrite("cone_angle", &pipeline::SegmentOptions::cone_angle_degrees)
        .def_readwrite("postprocess", &pipeline::SegmentOptions::postprocess)
        .def_readwrite("allow_open", &pipeline::SegmentOptions::allow_open)
        .def_property(
            "persistence", [](const pipeline::SegmentOptions& o) { return o.simplify.persistence; },
            [](pipeline::SegmentOptions& o, double v) { o.simplify.persistence = v; })
        .def_property(
            "area_ratio", [](const pipeline::SegmentOptions& o) { return o.simplify.area_ratio; },
            [](pipeline::SegmentOptions& o, double v) { o.simplify.area_ratio = v; })
        .def_property(
            "min_area", [](const pipeline::SegmentOptions& o) { return o.min_area; },
            [](pipeline::SegmentOptions& o, const py::object& v) {
                // An area as text ("5km2") or a number of m^2; None clears it.
                if (v.is_none())
                    o.min_area.clear();
                else if (py::isinstance<py::str>(v))
                    o.min_area = v.cast<std::string>();
                else
                    o.min_area = py::str(py::float_(v)).cast<std::string>();
            })
        .def_readwrite("cost", &pipeline::SegmentOptions::cost)
        .def_readwrite("saddle_penalty", &pipeline::SegmentOptions::saddle_penalty)
        .def_readwrite("absorbed", &pipeline::SegmentOptions::absorbed)
        .def_readwrite("format", &pipeline::SegmentOptions::format)
        .def_readwrite("craters", &pipeline::SegmentOptions::craters)
        .def("check", &pipeline::check_options);

    py::class_<pipeline::SegmentResult>(m, "SegmentResult")
        .def_property_readonly("labels",
                               [](const pipeline::SegmentResult& r) {
                                   return labels_array(r.input, r.segmentation.labels);
                               })
        .def_property_readonly(
            "vertex_labels",
            [](const pipeline::SegmentResult& r) { return array_1d(r.segmentation.labels); })
        .def_property_readonly("field",
                               [](const pipeline::SegmentResult& r) -> py::object {
                                   if (!r.input.dem) return array_1d(r.field);
                                   return array_2d(
                                       field::field_to_pixels(r.input.mesh, *r.input.dem, r.field),
                                       r.input.dem->height, r.input.dem->width);
                               })
        .def_property_readonly(
            "region_count",
            [](const pipeline::SegmentResult& r) { return r.segmentation.region_count; })
        .def_property_readonly("critical_before",
                               [](const pipeline::SegmentResult& r) { return r.critical_before; })
        .def_property_readonly("critical_after",
                               [](const pipeline::SegmentResult& r) { return r.after.critical; })
        .def_property_readonly(
            "relaxed_nodes",
            [](const pipeline::SegmentResult& r) { return r.segmentation.relaxed_nodes; })
        .def_property_readonly(
            "vertex_count",
            [](const pipeline::SegmentResult& r) { return r.input.mesh.vertex_count(); })
        .def_property_readonly(
            "region_columns",
            [](const pipeline::SegmentResult& r) { return region_columns(r.regions); })
        .def_property_readonly(
            "edge_columns",
            [](const pipeline::SegmentResult& r) { return edge_columns(r.regions); })
        .def_property_readonly("point_frame",
                               [](const pipeline::SegmentResult& r) {
                                   return point_frame_name(r.regions.point_frame);
                               })
        .def_property_readonly(
            "point_crs", [](const pipeline::SegmentResult& r) { return r.regions.point_crs_wkt; })
        .def_property_readonly("crater_columns",
                               [](const pipeline::SegmentResult& r) -> py::object {
                                   if (!r.craters) return py::none();
                                   return crater_columns(*r.craters);
                               })
        .def_property_readonly("crater_crs",
                               [](const pipeline::SegmentResult& r) -> py::object {
                                   if (!r.craters || !r.craters->lonlat) return py::none();
                                   return py::str(r.craters->lonlat_crs_wkt);
                               })
        .def_property_readonly("dem",
                               [](const pipeline::SegmentResult& r) -> py::object {
                                   if (!r.input.dem) return py::none();
                                   return py::cast(*r.input.dem);
                               })
        .def_property_readonly("timings",
                               [](const pipeline::SegmentResult& r) {
                                   py::dict d;
                                   for (const auto& t : r.timings) d[py::str(t.name)] = t.seconds;
                                   return d;
                               })
        .def(
            "write_polygons",
            [](const pipeline::SegmentResult& r, const std::string& path, const std::string& driver,
               const std::string& layer) {
                py::gil_scoped_release release;
                write_polygons(r.input, r.segmentation.labels, r.regions, path, driver, layer);
            },
            py::arg("path"), py::arg("driver") = "GPKG", py::arg("layer") = "regions")
        .def(
            "write",
            [](pipeline::SegmentResult& r, const pipeline::SegmentOptions& options,
               const std::string& dir, bool overwrite, const std::string& input_path,
               const py::object& progress) {
                return run(progress, [&](const ProgressFn& fn) {
                    pipeline::OutputDirectory out(dir, overwrite);
                    auto files = pipeline::write_segment_directory(r, options, input_path,
                                                                   out.temp_path(), {}, fn);
                    out.commit();
                    return files;
                });
            },
            py::arg("options"), py::arg("dir"), py::arg("overwrite"), py::arg("input_path"),
            py::arg("progress") = py::none());

    m.def(
        "segment",
        [](const py::object& source, const pipeline::SegmentOptions& options, int band,
           const std::string& elevation, bool nan_nodata, std::optional<double> pixel_size,
           const std::string& frame, bool repair, const py::object& progress,
           const py::object& max_memory) {
            pipeline::check_options(options);
            const auto in = input_options(band, elevation, nan_nodata, pixel_size, frame, repair,
                                          max_memory, options.field, true);
            const Source s = to_source(source);
            return run(progress, [&](const ProgressFn& fn) {
                auto input = load(s, in, scaled_progress(fn, 0, 0.2));
                return pipeline::segment(std::move(input), options, scaled_progress(fn, 0.2, 1));
            });
        },
        py::arg("source"), py::arg("options"), py::arg("band") = 1, py::arg("elevation") = "auto",
        py::arg("nan_nodata") = false, py::arg("pixel_size") = py::none(),
        py::arg("frame") = "auto", py::arg("repair") = false, py::arg("progress") = py::none(),
        py::arg("max_memory") = py::none());

    py::class_<pipeline::SweepResult>(m, "SweepResult")
        .def_property_readonly("ratios",
                               [](const pipeline::SweepResult& r) {
                                   std::vector<double> v;
                                   for (const auto& s : r.scales) v.push_back(s.ratio);
                                   return v;
                               })
        .def_property_readonly("min_areas",
                               [](const pipeline::SweepResult& r) {
                                   // m^2 of each scale of a sweep over areas; 0 otherwise
                                   std::vector<double> v;
                                   for (const auto& s : r.scales) v.push_back(s.min_area_m2);
                                   return v;
                               })
        .def_property_readonly(
            "critical_before",
            [](const pipeline::SweepResult& r) { return r.base.critical_before; })
        .def("scale_count", [](const pipeline::SweepResult& r) { return r.scales.size(); })
        .def("labels",
             [](const pipeline::SweepResult& r, std::size_t i) {
                 return labels_array(r.base.input, r.scales.at(i).segmentation.labels);
             })
        .def("vertex_labels",
             [](const pipeline::SweepResult& r, std::size_t i) {
                 return array_1d(r.scales.at(i).segmentation.labels);
             })
        .def("region_count", [](const pipeline::SweepResult& r,
                                std::size_t i) { return r.scales.at(i).segmentation.region_count; })
        .def("critical_after", [](const pipeline::SweepResult& r,
                                  std::size_t i) { return r.scales.at(i).after.critical; })
        .def("region_columns", [](const pipeline::SweepResult& r,
                                  std::size_t i) { return region_columns(r.scales.at(i).regions); })
        .def("edge_columns", [](const pipeline::SweepResult& r,
                                std::size_t i) { return edge_columns(r.scales.at(i).regions); })
        .def("lineage",
             [](const pipeline::SweepResult& r, std::size_t i) {
                 // Columns: one row per (region of scale i, overlapped region of scale i+1).
                 std::vector<std::uint32_t> from, to;
                 std::vector<double> area, fraction;
                 for (const auto& reg : r.lineage.at(i))
                     for (const auto& o : reg.overlaps) {
                         from.push_back(reg.region);
                         to.push_back(o.region);
                         area.push_back(o.area_m2);
                         fraction.push_back(o.fraction);
                     }
                 py::dict d;
                 d["from_region"] = array_1d(from);
                 d["to_region"] = array_1d(to);
                 d["area_m2"] = array_1d(area);
                 d["fraction"] = array_1d(fraction);
                 return d;
             })
        .def(
            "write_polygons",
            [](const pipeline::SweepResult& r, std::size_t i, const std::string& path,
               const std::string& driver, const std::string& layer) {
                const auto& s = r.scales.at(i);
                py::gil_scoped_release release;
                write_polygons(r.base.input, s.segmentation.labels, s.regions, path, driver, layer);
            },
            py::arg("index"), py::arg("path"), py::arg("driver") = "GPKG",
            py::arg("layer") = "regions")
        .def(
            "write",
            [](pipeline::SweepResult& r, const pipeline::SegmentOptions& options,
               const std::string& dir, bool overwrite, const std::string& input_path,
               const py::object& progress) {
                return run(progress, [&](const ProgressFn& fn) {
                    pipeline::OutputDirectory out(dir, overwrite);
                    auto files = pipeline::write_sweep_directory(r, options, input_path,
                                                                 out.temp_path(), fn);
                    out.commit();
                    return files;
                });
            },
            py::arg("options"), py::arg("dir"), py::arg("overwrite"), py::arg("input_path"),
            py::arg("progress") = py::none());

    m.def(
        "sweep",
        [](const py::object& source, const std::vector<double>& ratios,
           const pipeline::SegmentOptions& options, int band, const std::string& elevation,
           bool nan_nodata, std::optional<double> pixel_size, const std::string& frame, bool repair,
           const py::object& progress, const std::vector<std::string>& min_areas,
           const py::object& max_memory) {
            pipeline::check_options(options);
            // A sweep over areas when min_areas is given (ratios are then ignored).
            std::vector<pipeline::AreaThreshold> areas;
            for (const auto& a : min_areas)
                areas.push_back({a, pipeline::parse_area(a, "min_areas")});
            const auto in = input_options(band, elevation, nan_nodata, pixel_size, frame, repair,
                                          max_memory, options.field);
            const Source s = to_source(source);
            return run(progress, [&](const ProgressFn& fn) {
                auto input = load(s, in, scaled_progress(fn, 0, 0.2));
                if (!areas.empty())
                    return pipeline::sweep(std::move(input), areas, options,
                                           scaled_progress(fn, 0.2, 1));
                return pipeline::sweep(std::move(input), ratios, options,
                                       scaled_progress(fn, 0.2, 1));
            });
        },
        py::arg("source"), py::arg("ratios"), py::arg("options"), py::arg("band") = 1,
        py::arg("elevation") = "auto", py::arg("nan_nodata") = false,
        py::arg("pixel_size") = py::none(), py::arg("frame") = "auto", py::arg("repair") = false,
        py::arg("progress") = py::none(), py::arg("min_areas") = std::vector<std::string>{},
        py::arg("max_memory") = py::none());

    m.def(
        "field",
        [](const py::object& source, const pipeline::SegmentOptions& options, int band,
           const std::string& elevation, bool nan_nodata, std::optional<double> pixel_size,
           const std::string& frame, bool repair, const py::object& progress,
           const py::object& max_memory) -> py::object {
            const auto in = input_options(band, elevation, nan_nodata, pixel_size, frame, repair,
                                          max_memory, options.field);
            const Source s = to_source(source);
            pipeline::SegmentResult r;
            run(progress, [&](const ProgressFn& fn) {
                r.input = load(s, in, scaled_progress(fn, 0, 0.3));
                pipeline::compute_field(r, options, scaled_progress(fn, 0.3, 1));
                return 0;
            });
            if (!r.input.dem) return array_1d(r.field);
            return array_2d(field::field_to_pixels(r.input.mesh, *r.input.dem, r.field),
                            r.input.dem->height, r.input.dem->width);
        },
        py::arg("source"), py::arg("options"), py::arg("band") = 1, py::arg("elevation") = "auto",
        py::arg("nan_nodata") = false, py::arg("pixel_size") = py::none(),
        py::arg("frame") = "auto", py::arg("repair") = false, py::arg("progress") = py::none(),
        py::arg("max_memory") = py::none());

    m.def(
        "reeb_graph",
        [](const py::object& source, const pipeline::SegmentOptions& options, int band,
           const std::string& elevation, bool nan_nodata, std::optional<double> pixel_size,
           const std::string& frame, bool repair, const py::object& progress,
           const py::object& max_memory) {
            const auto in = input_options(band, elevation, nan_nodata, pixel_size, frame, repair,
                                          max_memory, options.field);
            const Source s = to_source(source);
            pipeline::SegmentResult r;
            reeb::ReebGraph graph;
            run(progress, [&](const ProgressFn& fn) {
                r.input = load(s, in, scaled_progress(fn, 0, 0.2));
                pipeline::compute_field(r, options, scaled_progress(fn, 0.2, 0.6));
                graph = pipeline::compute_reeb(r, scaled_progress(fn, 0.6, 0.8));
                const auto thresholds = pipeline::simplify_options(options, r.input.mesh);
                if (thresholds.persistence > 0 || thresholds.area_ratio > 0)
                    graph = reeb::simplify(r.input.mesh, std::move(graph), thresholds,
                                           scaled_progress(fn, 0.8, 1))
                                .graph;
                return 0;
            });
            // Critical nodes only, renumbered 0..n-1; arcs between them.
            std::vector<std::int32_t> index(graph.node_count(), -1);
            std::vector<std::int64_t> node_id, first_vertex, col, row, vertex_count;
            std::vector<float> value;
            py::list kinds;
            for (std::size_t n = 0; n < graph.node_count(); ++n) {
                if (graph.node_kinds[n] == reeb::NodeKind::regular) continue;
                index[n] = static_cast<std::int32_t>(node_id.size());
                node_id.push_back(static_cast<std::int64_t>(n));
                value.push_back(graph.node_values[n]);
                kinds.append(reeb::to_string(graph.node_kinds[n]));
                const auto v =
                    graph.node_vertices[static_cast<std::size_t>(graph.node_vertex_offsets[n])];
                first_vertex.push_back(v);
                vertex_count.push_back(graph.node_vertex_offsets[n + 1] -
                                       graph.node_vertex_offsets[n]);
                std::int64_t c = -1, rw = -1;
                if (r.input.dem && !r.input.mesh.vertex_pixel.empty()) {
                    const auto p = r.input.mesh.vertex_pixel[static_cast<std::size_t>(v)];
                    if (p >= 0) {
                        c = p % r.input.dem->width;
                        rw = p / r.input.dem->width;
                    }
                }
                col.push_back(c);
                row.push_back(rw);
            }
            std::vector<std::int32_t> lower, upper, regular;
            for (std::size_t a = 0; a < graph.arc_count(); ++a) {
                lower.push_back(index[static_cast<std::size_t>(graph.arcs[a][0])]);
                upper.push_back(index[static_cast<std::size_t>(graph.arcs[a][1])]);
                regular.push_back(graph.arc_offsets[a + 1] - graph.arc_offsets[a]);
            }
            py::dict nodes, arcs;
            nodes["node"] = array_1d(node_id);
            nodes["value"] = array_1d(value);
            nodes["kind"] = py::module_::import("numpy").attr("array")(kinds);
            nodes["vertex"] = array_1d(first_vertex);
            nodes["vertex_count"] = array_1d(vertex_count);
            nodes["col"] = array_1d(col);
            nodes["row"] = array_1d(row);
            arcs["lower"] = array_1d(lower);
            arcs["upper"] = array_1d(upper);
            arcs["regular_nodes"] = array_1d(regular);
            return py::make_tuple(nodes, arcs, r.critical_before);
        },
        py::arg("source"), py::arg("options"), py::arg("band") = 1, py::arg("elevation") = "auto",
        py::arg("nan_nodata") = false, py::arg("pixel_size") = py::none(),
        py::arg("frame") = "auto", py::arg("repair") = false, py::arg("progress") = py::none(),
        py::arg("max_memory") = py::none());
}
