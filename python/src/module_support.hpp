#pragma once
// What the bindings of terrain._terrain (module.cpp) share: Python progress callables, the
// GIL released around library calls, arrays and columns made from the library's results,
// the sources and options the Python calls take (module_support.cpp).
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

namespace terrain::python {

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
std::string crs_to_wkt(const std::string& text);
std::optional<ElevationKind> parse_elevation(const std::string& name);
Dem dem_from_array(py::array_t<double, py::array::c_style | py::array::forcecast> values,
                   std::optional<std::vector<double>> geotransform, const std::string& crs,
                   const std::string& elevation);
py::tuple transform_tuple(const Dem& dem);
py::dict region_columns(const segment::RegionGraph& graph);
py::dict crater_columns(const segment::CraterTable& table);
py::dict edge_columns(const segment::RegionGraph& graph);
const char* point_frame_name(segment::PointFrame f);

// A call's source: a path, or a Dem made in Python.
struct Source {
    std::optional<std::string> path;
    std::optional<Dem> dem;
};
Source to_source(const py::object& source);
pipeline::Input load(const Source& s, const pipeline::InputOptions& options,
                     const ProgressFn& progress);
// max_memory: None, a number of bytes, or a size as the command line's --max-memory takes
// it ("512M", "4G").
std::uint64_t memory_limit_argument(const py::object& max_memory);
// The input options, with the memory plan of computing `field` (pipeline::memory_plan).
pipeline::InputOptions input_options(int band, const std::string& elevation, bool nan_nodata,
                                     std::optional<double> pixel_size, const std::string& frame,
                                     bool repair, const py::object& max_memory,
                                     field::FieldKind field, bool segment = false);
py::object labels_array(const pipeline::Input& input, const std::vector<std::uint32_t>& labels);
void write_polygons(const pipeline::Input& input, const std::vector<std::uint32_t>& labels,
                    const segment::RegionGraph& regions, const std::string& path,
                    const std::string& driver, const std::string& layer);

}  // namespace terrain::python
