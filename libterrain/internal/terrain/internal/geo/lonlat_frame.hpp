#pragma once
// Private: longitude/latitude coordinates for the outputs of a georeferenced DEM (not
// installed). Earth goes to EPSG:4326 (RFC 7946); other bodies to the geographic CRS of the
// DEM's CRS, on the same body. Longitudes are kept within 180 degrees of the tile's centre so
// that a tile across the CRS's antimeridian stays in one piece (a global 0..360 grid keeps
// 0..360). GridGeoref::output_lonlat is the thread-safe form of it.

#include <ogr_spatialref.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "terrain/core/dem.hpp"

namespace terrain::geo {

class LonLatFrame {
  public:
    // Throws terrain::Error(stage) when the DEM has no CRS or it cannot be transformed.
    LonLatFrame(const Dem& dem, const char* stage);
    // The same from the CRS text, whether the body is Earth and the map point of the centre.
    LonLatFrame(const std::string& crs_wkt, bool earth, std::array<double, 2> centre,
                const char* stage);

    bool earth() const { return earth_; }
    const OGRSpatialReference& srs() const { return *target_; }
    std::string wkt() const;  // single-line WKT2

    // Map coordinates of the DEM's CRS to lon, lat in place; false if a point failed.
    bool transform(std::size_t count, double* x, double* y) const;
    // The same, with ok[i] = 1 for each point that has a finite lon, lat and 0 otherwise.
    bool transform(std::size_t count, double* x, double* y, std::uint8_t* ok) const;

  private:
    std::unique_ptr<OGRSpatialReference> source_, target_;
    std::unique_ptr<OGRCoordinateTransformation> to_lonlat_;
    bool earth_ = false;
    double centre_lon_ = 0;
};

// What GeoJSON's (2008) "crs" member names for lon/lat in `wkt`: nothing for EPSG:4326 (RFC
// 7946) or an empty/unreadable CRS, "urn:ogc:def:crs:AUTH::CODE" when the CRS has an authority
// code, the WKT otherwise (GDAL's GeoJSON reader takes both).
std::string geojson_crs_name(const std::string& wkt);

}  // namespace terrain::geo
