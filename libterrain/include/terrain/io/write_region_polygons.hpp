#pragma once
// regions.geojson (or another OGR vector format): one polygon per region (docs/outputs.md).
// Like every writer of io/: atomic, refuses an existing file unless `overwrite`, throws one
// terrain::Error (stage "write") on failure, and writes the same bytes for the same input.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

struct RegionPolygonOptions {
    std::string driver = "GeoJSON";  // or any OGR vector driver that creates files ("GPKG")
    // GeoJSON is always lon/lat (EPSG:4326 on Earth, the body's geographic CRS elsewhere);
    // other drivers keep the DEM's own CRS unless this is set.
    bool lonlat = false;
    std::string layer = "regions";  // the layer's name (drivers other than GeoJSON)
    // Add the layer to `path` if it exists (GPKG with one layer per scale), writing in place:
    // the caller makes the outputs atomic (terrain sweep writes into a temporary directory).
    bool append_layer = false;
};

// Refuses (terrain::Error, stage "write", one line naming the format to use) a driver that
// cannot hold the DEM's coordinates: KML, LIBKML and GPX store WGS 84 longitude/latitude
// only, so a DEM on another body, or without CRS, cannot be written to them (their readers
// would take the body's coordinates, or local metres, for Earth's). Earth DEMs are
// reprojected to WGS 84 by those drivers. Called by write_region_polygons; callers check it
// before long work.
void check_polygon_format(const Dem& dem, const std::string& driver);

// One feature per region (Polygon, MultiPolygon where its pixels touch only at corners; null
// when it has no pixel) made with GDALPolygonize, with the region's properties. Written
// feature by feature: GDALPolygonize's pieces wait in an unlinked temporary file beside
// `path`, and each region's outline is read back, written and freed in turn. `pixels`:
// segment::label_pixels() of the DEM (row-major, 0 = no region). A DEM without CRS gives its
// map (geotransform) coordinates.
// `progress` ("write", 0 to 1): GDALPolygonize's, then each region written; a callback that
// cancels stops it with terrain::Error and leaves no file.
void write_region_polygons(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                           const segment::RegionGraph& graph, const std::string& path,
                           bool overwrite, const RegionPolygonOptions& options = {},
                           const ProgressFn& progress = {});

// The region polygons of one labelling (GDALPolygonize, in the DEM's map coordinates), made
// once to be written to several files: terrain sweep writes each scale to a GeoPackage layer
// and to GeoJSON. They wait in an unlinked temporary file in `temp_dir` (the system's
// temporary directory when empty) and are read back one region at a time, so several
// writers may read one set at once and no writer holds every outline.
class RegionPolygons {
  public:
    RegionPolygons();
    ~RegionPolygons();
    RegionPolygons(RegionPolygons&&) noexcept;
    RegionPolygons& operator=(RegionPolygons&&) noexcept;
    std::size_t region_count() const;

    struct Impl;
    const Impl& impl() const { return *impl_; }

  private:
    explicit RegionPolygons(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
    friend RegionPolygons polygonize_regions(const Dem&, const std::vector<std::uint32_t>&,
                                             std::size_t, const std::string&);
};
RegionPolygons polygonize_regions(const Dem& dem, const std::vector<std::uint32_t>& pixels,
                                  std::size_t region_count, const std::string& temp_dir = "");
// write_region_polygons from polygons made before (for the labelling the graph describes).
void write_region_polygons(const Dem& dem, const RegionPolygons& polygons,
                           const segment::RegionGraph& graph, const std::string& path,
                           bool overwrite, const RegionPolygonOptions& options = {});

}  // namespace terrain::io
