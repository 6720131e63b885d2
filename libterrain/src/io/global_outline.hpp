#pragma once
// Private: the outlines of a global grid's regions in the outputs' longitude/latitude (not
// installed). A grid whose rows go 360 degrees round (GridGeoref::global_longitude) has its
// seam at its west and east edges; its pixel corners there, and on a pole row, are where
// rounding in the map scale would otherwise put a vertex on the wrong side of the seam or
// beyond a pole. See docs/outputs.md, "Global grids".

#include <ogr_geometry.h>
#include <ogr_spatialref.h>

#include <memory>
#include <vector>

#include "lonlat_frame.hpp"
#include "terrain/core/dem.hpp"

namespace terrain::io {

class GlobalOutline {
  public:
    // For a DEM with global_longitude and the frame of its outputs.
    GlobalOutline(const Dem& dem, const LonLatFrame& frame);

    // True for a DEM whose polygons need it: a CRS, and rows that go round the body.
    static bool applies(const Dem& dem);

    // The longitude of the grid's west edge: the outputs' longitudes run from it to 360
    // degrees east of it (the grid's own range, centred on its centre meridian).
    double west() const { return west_; }

    // One ring of pixel corners in the DEM's map coordinates to lon/lat, in place: a vertex at
    // every pixel corner along the rows (parallels, which a straight or geodesic edge would
    // cut short), the west and east edges at west() and west() + 360 exactly, latitudes
    // within +-90 and a pole row's outer edge at the pole.
    void to_lonlat(OGRLinearRing& ring) const;

    // The same ring kept in the DEM's map coordinates: the seam columns and the pole rows
    // move onto the seam (a nanodegree inside it in a projected CRS, whose inverse would put
    // the seam itself at either end) and onto the pole; in a geographic CRS, whose map
    // coordinates are lon/lat, the rows get a vertex at every pixel corner as there.
    void to_map(OGRLinearRing& ring) const;

  private:
    struct Corners {
        std::vector<double> col, row, lon, lat;
    };
    // The ring's vertices as pixel corners (with every corner along a row when `densify`),
    // their lon/lat on the seam and within +-90.
    Corners corners(const OGRLinearRing& ring, bool densify) const;

    const Dem& dem_;
    const LonLatFrame& frame_;
    double inverse_[6] = {};
    double west_ = 0;
    bool geographic_ = false;
    std::unique_ptr<OGRSpatialReference> map_srs_;
    std::unique_ptr<OGRCoordinateTransformation> to_map_;  // lon/lat -> a projected CRS
};

}  // namespace terrain::io
