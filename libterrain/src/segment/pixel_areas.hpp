#pragma once
// Private: the area on the body of each DEM pixel's footprint (not installed).

#include <vector>

#include "terrain/core/dem.hpp"

namespace terrain::segment {

// Footprint areas in m^2 on the body's ellipsoid (docs/outputs.md, "Areas"):
// - no CRS: the planar pixel area |det| of the geotransform (metres assumed);
// - rows along parallels and columns along meridians (geographic grids, equirectangular,
//   Mercator, any cylindrical projection, no rotation): exact, per row, from the authalic
//   latitudes of the row's edges (GeographicLib Ellipsoid);
// - any other projection: the geodesic polygon of the pixel's corners (GeographicLib
//   PolygonArea) every 16th row and column, interpolated bilinearly between (the areal
//   scale of a projection varies smoothly: below 1e-9 relative error for UTM).
class PixelAreas {
  public:
    explicit PixelAreas(const Dem& dem);  // throws terrain::Error (stage "segment")
    double operator()(int col, int row) const {
        switch (mode_) {
            case Mode::constant:
                return constant_;
            case Mode::per_row:
                return rows_[static_cast<std::size_t>(row)];
            default:
                return interpolate(col, row);
        }
    }

  private:
    enum class Mode { constant, per_row, lattice };
    double interpolate(int col, int row) const;

    Mode mode_ = Mode::constant;
    double constant_ = 0;
    std::vector<double> rows_;
    // Lattice: node columns/rows, the area at each node (row-major), and for each pixel
    // column/row its segment and weight.
    std::vector<int> node_cols_, node_rows_;
    std::vector<double> node_areas_;
    std::vector<int> col_segment_, row_segment_;
    std::vector<double> col_weight_, row_weight_;
};

}  // namespace terrain::segment
