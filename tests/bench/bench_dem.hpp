#pragma once
// The benchmarks' DEM: an n x n UTM 11N grid of 30 m pixels with hills (200 m) and a fine
// ripple (30 m), the same for every benchmark so their figures add up.

#include <cmath>

#include "terrain/core/dem.hpp"
#include "terrain/geo/georeference.hpp"

namespace terrain::bench {

inline Dem utm_hills(int n) {
    Dem dem;
    dem.width = dem.height = n;
    dem.crs_wkt = "EPSG:32611";
    dem.transform = {400000, 30, 0, 3800000, 0, -30};
    dem.has_transform = true;
    geo::georeference(dem);
    dem.values.resize(std::size_t(n) * n);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            dem.values[std::size_t(r) * n + c] =
                200 * std::sin(c * 0.05) * std::cos(r * 0.037) + 30 * std::sin(c * 0.9 + r * 1.3);
    return dem;
}

}  // namespace terrain::bench
