#pragma once
// A synthetic DEM tile of the asteroid 4 Vesta in the layout of the Dawn HAMO DTM: radii in
// metres on the 2 m DN grid of the HAMO products (radius = DN * 2 + 255000, DN an int16),
// 64 pixels per degree on the 255 km reference sphere (about 69.54 m per pixel), in an
// equirectangular projection. The surface is a cratered plain: a regional tilt and
// long-wavelength undulation, fractal roughness, and a power-law population of simple craters
// added oldest first, the older ones degraded. Same options, same bytes: our own PRNG (no
// std:: distributions), single-threaded, no fused multiply-adds.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"

namespace terrain::synth {

// Vesta's reference sphere and the HAMO DTM grid (Preusker et al., Dawn HAMO DTM, PDS
// data set DAWN-A-FC2-5-VESTADTMSPG-V1.0).
inline constexpr double kVestaRadius = 255000.0;      // metres
inline constexpr double kHamoPixelsPerDegree = 64.0;  // about 69.54 m per pixel
inline constexpr double kHamoScalingFactor = 2.0;     // metres per DN
inline constexpr double kHamoOffset = 255000.0;       // radius at DN 0, metres

// One simple crater. Centres are in pixels of the tile: (0,0) is the top-left corner of the
// top-left pixel, (col+0.5,row+0.5) the centre of pixel (col,row); they may lie outside the
// tile (craters whose rim or ejecta reach into it).
struct Crater {
    double col = 0, row = 0;
    double diameter = 1000;  // rim crest to rim crest, metres on the ground
    double degradation = 0;  // 0 fresh .. towards 1 nearly erased
    double age = 0;          // fraction of the surface age since it formed, in (0,1]
};

struct VestaTileOptions {
    int width = 512;                // pixels
    int height = 512;               // pixels
    std::uint64_t seed = 20110716;  // Dawn entered orbit around Vesta on 16 July 2011

    // Tile centre, degrees (planetocentric latitude, east longitude). Default: the southern
    // mid-latitudes, on the rim region of the Rheasilvia basin.
    double center_lon = 150.0;
    double center_lat = -30.0;
    double pixels_per_degree = kHamoPixelsPerDegree;  // along a meridian
    // Latitude of true scale of the equirectangular projection (PDS CENTER_LATITUDE); unset:
    // the tile centre's, so that pixels are about square on the ground over the tile.
    std::optional<double> standard_parallel;

    // Crater population: cumulative N(>=D) = crater_density * (D / 1 km)^-size_exponent per
    // km^2, for diameters in [min_diameter, max_diameter]. 0.05 km^-2 at 1 km is a heavily
    // cratered surface, about a third of the empirical saturation of small craters (Hartmann
    // 1984: N(>=D) = 0.15 D^-2 km^-2).
    double crater_density = 0.05;
    double size_exponent = 2.0;
    double min_diameter = 300.0;    // metres (about 4 pixels)
    double max_diameter = 15000.0;  // metres
    // Simple-crater shape (Pike 1977): rim-to-floor depth and rim height over diameter.
    double depth_ratio = 0.2;
    double rim_ratio = 0.04;
    // Degradation by diffusive erosion: a crater of this diameter as old as the surface has
    // lost half of its relief; smaller or older craters more, larger or younger ones less.
    double degradation_diameter = 2000.0;  // metres

    // Regional relief, metres: mean height above the 255 km sphere, a planar tilt (rise over
    // run, random azimuth), long-wavelength undulation (20-80 km wavelengths) and fractal
    // roughness (amplitude at 5 km wavelength, falling as wavelength^hurst to 2 pixels).
    double base_height = 0.0;
    double regional_slope = 0.05;
    double undulation_amplitude = 2000.0;
    double roughness_amplitude = 40.0;
    double hurst = 0.8;

    // Craters added after the random population, youngest last (their `age` is ignored).
    std::vector<Crater> craters;
};

// The random crater population of a tile in formation order (oldest first), including the
// craters centred outside the tile whose rims or ejecta reach into it. Throws terrain::Error
// (stage "synth") on invalid options.
std::vector<Crater> vesta_crater_population(const VestaTileOptions& options = {});

// The tile: radii in metres on the HAMO DN grid, ElevationKind::radius, the geotransform of
// the equirectangular projection in metres and its CRS (a 255000 m sphere named for Vesta,
// vesta_equirectangular_wkt), body Vesta. Throws terrain::Error (stage "synth") on
// invalid options, "progress" when the callback cancels.
Dem generate_vesta_tile(const VestaTileOptions& options = {}, const ProgressFn& progress = {});

}  // namespace terrain::synth
