#pragma once
// The crater table as files (docs/craters.md). Like every writer of io/: atomic, refuses an
// existing file unless `overwrite`, throws one terrain::Error (stage "write") on failure, and
// writes the same bytes for the same input.

#include <string>

#include "terrain/core/body.hpp"
#include "terrain/segment/craters.hpp"

namespace terrain::io {

// craters.csv: one row per crater, id, lon, lat (x, y without lon/lat), col, row, diameter_m,
// depth_m, rim_height_m, circularity, rim_fraction, fit_rms_m, field_scale_m, floor_region,
// rim_regions (space-separated ids), confidence.
void write_craters_csv(const segment::CraterTable& table, const std::string& path, bool overwrite);

// craters.geojson: per crater a Point at its centre and a Polygon, its rim circle, each with
// the crater's columns and `kind` ("centre" or "rim"), in the CRS handling of regions.geojson
// (the body's geographic CRS named; a local grid's CRS without one).
void write_craters_geojson(const segment::CraterTable& table, const std::string& path,
                           bool overwrite);

// The craters as two layers added to an existing GeoPackage (regions.gpkg of --format
// GPKG): "craters", a point per crater at its centre, and "crater_rims", its rim circle as a
// polygon, both with the table's columns, in the body's geographic CRS (a local grid's CRS
// without one), recorded in WKT2 as regions.gpkg's own. Writes in place: the caller makes
// the directory atomic (terrain segment writes into a temporary one).
void add_crater_layers(const segment::CraterTable& table, const std::string& gpkg_path);

// craters.png: a quick look at the table, two log-log panels: depth / diameter against the
// diameter (one dot per crater), and the cumulative size-frequency distribution (craters at
// least D across per km^2 of `area_m2`, the DEM's valid area) against D.
void write_craters_plot(const segment::CraterTable& table, double area_m2, const std::string& path,
                        bool overwrite);

// craters.scc: craterstats' spatial crater count: the body's axes, the counted area
// (`area_m2`, the DEM's valid area on the body) and the craters' diameters (km) and centres.
// Throws terrain::Error (stage "write") for a table without lon/lat.
void write_craters_scc(const segment::CraterTable& table, const Body& body, double area_m2,
                       const std::string& path, bool overwrite);

}  // namespace terrain::io
