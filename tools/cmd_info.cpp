// terrain info DEM [--json]: what the DEM is, on which body, and how terrain will read it.
#include <cstdio>
#include <iostream>

#include "cli.hpp"
#include "dem_options.hpp"
#include "terrain/core/json_writer.hpp"
#include "terrain/io/describe_dem.hpp"
#include "terrain/io/read_dem.hpp"

namespace terrain::cli {
namespace {

void write_json(std::ostream& out, const io::DemDescription& d, const Dem& dem) {
    JsonWriter j(out);
    j.begin_object();
    j.field("file", dem.source).field("band", dem.band);
    j.key("size").begin_array().value(d.width).value(d.height).end_array();
    j.key("pixel_size_m").begin_array().value(d.pixel_width_m).value(d.pixel_height_m).end_array();
    j.key("geotransform");
    if (dem.has_transform) {
        j.begin_array();
        for (double v : dem.transform) j.value(v);
        j.end_array();
    } else {
        j.null();
    }
    j.key("crs");
    if (d.crs_wkt.empty())
        j.null();
    else
        j.begin_object().field("name", d.crs_name).field("wkt", d.crs_wkt).end_object();
    j.key("body").begin_object();
    j.field("name", d.body.name)
        .field("semi_major_axis", d.body.semi_major_axis)
        .field("flattening", d.body.flattening)
        .field("local_grid", d.body.is_local_grid());
    j.end_object();
    j.key("elevation").begin_object();
    j.field("kind", to_string(d.elevation)).field("detected", d.elevation_detected);
    j.field("min", d.min_value).field("max", d.max_value);
    j.field("min_height", d.min_height).field("max_height", d.max_height);
    j.end_object();
    j.field("valid_pixels", d.valid_pixels).field("nodata_fraction", d.nodata_fraction);
    j.key("extent");
    if (d.has_geographic_extent) {
        j.begin_object();
        j.field("lon_min", d.lon_min).field("lon_max", d.lon_max);
        j.field("lat_min", d.lat_min).field("lat_max", d.lat_max);
        j.field("lon_span", d.lon_span).field("global_longitude", d.global_longitude);
        j.end_object();
    } else {
        j.null();
    }
    j.end_object();
}

void write_text(std::ostream& out, const io::DemDescription& d, const Dem& dem) {
    char line[256];
    out << "File:        " << dem.source << " (band " << dem.band << ")\n";
    std::snprintf(line, sizeof line, "Size:        %d x %d pixels\n", d.width, d.height);
    out << line;
    std::snprintf(line, sizeof line, "Pixel size:  %.6g x %.6g m%s\n", d.pixel_width_m,
                  d.pixel_height_m, dem.has_transform ? "" : " (no geotransform: assumed)");
    out << line;
    out << "CRS:         " << (d.crs_wkt.empty() ? "none (local metric grid)" : d.crs_name) << "\n";
    if (d.body.is_local_grid()) {
        out << "Body:        none (local metric grid)\n";
    } else {
        std::snprintf(line, sizeof line,
                      "Body:        %s, semi-major axis %.10g m, flattening %.10g%s\n",
                      d.body.name.c_str(), d.body.semi_major_axis, d.body.flattening,
                      d.body.flattening > 0 ? "" : " (sphere)");
        out << line;
    }
    std::snprintf(line, sizeof line, "Elevation:   %s (%s), values %.10g .. %.10g m\n",
                  to_string(d.elevation), d.elevation_detected ? "detected" : "as requested",
                  d.min_value, d.max_value);
    out << line;
    if (d.elevation == ElevationKind::radius) {
        std::snprintf(line, sizeof line, "             heights %.10g .. %.10g m above %.10g m\n",
                      d.min_height, d.max_height, d.body.semi_major_axis);
        out << line;
    }
    std::snprintf(line, sizeof line, "NoData:      %.4g%% of pixels (%zu valid)\n",
                  100.0 * d.nodata_fraction, d.valid_pixels);
    out << line;
    if (d.has_geographic_extent) {
        std::snprintf(line, sizeof line,
                      "Extent:      lon %.6f .. %.6f, lat %.6f .. %.6f degrees%s\n", d.lon_min,
                      d.lon_max, d.lat_min, d.lat_max,
                      d.global_longitude ? " (global in longitude: the seam closes)" : "");
        out << line;
    }
}

}  // namespace

int run_info(int argc, char** argv) {
    return guarded("info", [&] {
        std::string path;
        bool json = false, quiet = false;
        DemOptionValues dem_values;
        po::options_description options("terrain info options");
        options.add_options()("dem", po::value(&path)->required(),
                              "the DEM (any raster GDAL opens)")("json", po::bool_switch(&json),
                                                                 "print JSON instead of text")(
            "quiet,q", po::bool_switch(&quiet), "no progress output");
        add_dem_options(options, dem_values);
        po::positional_options_description positional;
        positional.add("dem", 1);
        po::variables_map vm;
        if (!parse(argc, argv, "terrain info DEM [--json] [options]", options, positional, vm))
            return 0;
        // The values are summarised row by row, not kept: describing a large or sparse
        // raster costs the memory of one row.
        io::DemValueSummary summary;
        const Dem dem = io::read_dem_summary(path, summary, to_read_options(dem_values),
                                             terminal_progress(true));
        auto description = io::describe_dem(dem);
        const double reference =
            dem.elevation == ElevationKind::radius ? dem.body.semi_major_axis : 0;
        description.min_value = summary.min_value;
        description.max_value = summary.max_value;
        description.min_height = summary.min_value - reference;
        description.max_height = summary.max_value - reference;
        description.valid_pixels = summary.valid_pixels;
        description.nodata_fraction =
            1.0 - double(summary.valid_pixels) / (double(dem.width) * double(dem.height));
        if (json)
            write_json(std::cout, description, dem);
        else
            write_text(std::cout, description, dem);
        return 0;
    });
}

}  // namespace terrain::cli
