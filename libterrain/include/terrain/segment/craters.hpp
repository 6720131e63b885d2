#pragma once
// Craters read from the regions (docs/craters.md): a crater is a concave floor region ringed
// by convex rim regions. The table is a reading of a segmentation; the regions are unchanged.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::segment {

struct Crater {
    std::uint32_t id = 0;  // 1..N, by floor region id
    // The rim circle's centre: lon, lat in degrees (planetocentric, east-positive) on a body
    // frame or a DEM with a CRS; map x, y without one.
    double lon = 0, lat = 0;
    double col = 0, row = 0;   // the centre on the DEM's grid (0, 0: its top-left corner)
    double diameter_m = 0;     // rim crest to rim crest: the fitted circle's diameter
    double depth_m = 0;        // mean rim crest height minus the floor's lowest height
    double rim_height_m = 0;   // mean rim crest height minus the mean height 1.5-2 R out
    double circularity = 0;    // of the floor region: 4 pi area / perimeter^2
    double rim_fraction = 0;   // share of the directions with a rim crest on the circle
    double fit_rms_m = 0;      // the crest points' RMS distance to the circle
    double field_scale_m = 0;  // the floor region's field scale (0 without one)
    std::uint32_t floor_region = 0;
    std::vector<std::uint32_t> rim_regions;  // the convex regions the crest was found in
    // In [0, 1]: crater_confidence(), rim fraction x fit quality x roundness x concavity x
    // level.
    double confidence = 0;
    // The rim circle as a closed ring of kRimPoints + 1 points, in the centre's coordinates
    // (lon, lat, longitudes kept within 180 degrees of the centre's; or map x, y).
    std::vector<std::array<double, 2>> rim;
};
constexpr int kRimPoints = 72;

struct CraterTable {
    std::vector<Crater> craters;
    bool lonlat = false;  // lon/lat (else map x, y)
    std::string lonlat_crs_wkt;
};

struct CraterOptions {
    double concave_below = 50;  // a floor's mean field (shape index x 100) is below this
    double convex_above = 50;   // a rim region's mean field is above this
    double min_rim_fraction = 0.5;
    double min_confidence = 0.2;
    // A floor this round (4 pi area / perimeter^2) or rounder takes its whole confidence; a
    // less round one, in proportion.
    double round_floor = 0.4;
    // A floor whose mean field is this low or lower (the top of Koenderink's concave classes:
    // shape index -1/8) takes its whole confidence; one between this and concave_below, in
    // proportion to how far below concave_below it is.
    double concave_full = 43.75;
    // A rim whose heights spread (their standard deviation round the circle) this much of the
    // crater's depth keeps half its confidence (a level rim all of it).
    double level_spread = 1.0;

    // The rim crest is looked for between these multiples of the floor's radius (of a disk
    // of its area) from its centroid.
    double crest_from = 0.8, crest_to = 1.4;
};

// What a crater's confidence is made of (CraterOptions for the constants):
struct CraterEvidence {
    double rim_fraction = 0;  // share of the directions with a crest point on the circle
    double fit_rms_m = 0;     // the crest points' RMS distance to the circle
    double radius_m = 0;      // the circle's
    double pixel_m = 0;       // the grid's spacing at the floor (square root of a vertex's area)
    double circularity = 0;   // the floor's, 4 pi area / perimeter^2
    double floor_mean = 0;    // the floor's mean field (shape index x 100)
    double rim_spread = 0;    // the rim's heights' standard deviation over the crater's depth
};
// rim fraction x fit quality x roundness x concavity x level, in [0, 1]:
// - fit quality 1 - 4 misfit / radius (at least 0), the misfit being the RMS beyond what the
//   grid explains: a crest point is a vertex, up to half a pixel off the crest it samples, so
//   misfit^2 = max(0, rms^2 - (pixel / 2)^2);
// - roundness min(1, circularity / round_floor);
// - concavity (concave_below - floor_mean) / (concave_below - concave_full), within [0, 1];
// - level 1 / (1 + (rim_spread / level_spread)^2): a crater's rim is about level round its
//   circle, a low between the rims of other craters is not.
double crater_confidence(const CraterEvidence& evidence, const CraterOptions& options = {});

// The craters of a DEM's segmentation: `labels` per mesh vertex (1..regions), `graph` its
// region graph (segment::region_graph), `dem` the DEM the mesh was made from. A floor is a
// concave region with convex neighbours, two adjacent concave regions of comparable areas
// rounder together than one of them (a floor the segmentation cut in two), or a group of
// three to twelve adjacent concave regions grown from its largest by the neighbour that
// leaves the union roundest, the roundest union met when it is rounder than the largest
// alone (a floor cut in several pieces); the crater names the largest as floor_region. For
// each floor: the highest vertex of its convex neighbours in each
// of 36 directions (fewer on a small floor: one a pixel of the circle of its radius, at least
// 12) from the floor's centroid (between crest_from and crest_to floor radii) is a rim
// crest point; a circle is fitted to them (twice, dropping points more than a quarter radius off);
// kept when crest points are found in half the directions or more, the radius is between
// 0.8 crest_from and crest_to floor radii, the floor within the circle (its RMS distance from
// the centre at most the radius), the depth positive and the confidence at least
// min_confidence. Of two craters
// whose centres are within half the larger radius and whose radii are within 1.5x, the more
// confident stays. Deterministic. Throws terrain::Error (stage "craters") on sizes that do
// not match.
CraterTable find_craters(const TriangleMesh& mesh, const Dem& dem,
                         const std::vector<std::uint32_t>& labels, const RegionGraph& graph,
                         const CraterOptions& options = {});

}  // namespace terrain::segment
