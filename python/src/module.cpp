// terrain._terrain: the pybind11 extension behind the Python package `terrain`
// (python/terrain/__init__.py wraps it; docs/python.md). Every long call releases the GIL;
// progress goes to an optional Python callable, called with the GIL held. The conversions
// the bindings share: module_support.hpp.
#include "module_support.hpp"

using namespace terrain;
using namespace terrain::python;

namespace {

// The module's error, its version, the Dem class and the calls that read or make one.
void bind_dem(py::module_& m) {
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
}

// pipeline::SegmentOptions, every option of the segment job. The options the library holds as
// values are given and read back as the command line's names (terrain/pipeline/options.hpp),
// each read once, when it is set.
void bind_segment_options(py::module_& m) {
    py::class_<pipeline::SegmentOptions>(m, "SegmentOptions")
        .def(py::init<>())
        .def_property(
            "field", [](const pipeline::SegmentOptions& o) { return field::to_string(o.field); },
            [](pipeline::SegmentOptions& o, const std::string& v) {
                o.field = field::parse_field_kind(v);
            })
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
                return field::to_string(o.shape_index.window);
            },
            [](pipeline::SegmentOptions& o, const std::string& v) {
                o.shape_index.window = pipeline::parse_window(v, "window");
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
            "min_area",
            [](const pipeline::SegmentOptions& o) { return pipeline::to_string(o.min_area); },
            [](pipeline::SegmentOptions& o, const py::object& v) {
                // An area as text ("5km2", "auto") or a number of m^2 (kept as Python writes
                // it, "150000000.0"); None clears it.
                if (v.is_none())
                    o.min_area = {};
                else if (py::isinstance<py::str>(v))
                    o.min_area = pipeline::parse_min_area(v.cast<std::string>());
                else
                    o.min_area =
                        pipeline::parse_min_area(py::str(py::float_(v)).cast<std::string>());
            })
        .def_property(
            "cost",
            [](const pipeline::SegmentOptions& o) { return pipeline::name_or_auto(o.cost); },
            [](pipeline::SegmentOptions& o, const std::string& v) {
                o.cost = pipeline::parse_cost(v);
            })
        .def_readwrite("saddle_penalty", &pipeline::SegmentOptions::saddle_penalty)
        .def_property(
            "absorbed",
            [](const pipeline::SegmentOptions& o) { return pipeline::name_or_auto(o.absorbed); },
            [](pipeline::SegmentOptions& o, const std::string& v) {
                o.absorbed = pipeline::parse_absorbed(v);
            })
        .def_readwrite("format", &pipeline::SegmentOptions::format)
        .def_readwrite("craters", &pipeline::SegmentOptions::craters)
        .def("check", &pipeline::check_options);
}

// pipeline::SegmentResult and the segment call.
void bind_segment(py::module_& m) {
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
}

// pipeline::SweepResult and the sweep call.
void bind_sweep(py::module_& m) {
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
}

// The stages alone: the field and the Reeb graph of a source.
void bind_stages(py::module_& m) {
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

}  // namespace

PYBIND11_MODULE(_terrain, m) {
    bind_dem(m);
    bind_segment_options(m);
    bind_segment(m);
    bind_sweep(m);
    bind_stages(m);
}
