#pragma once
// Private: the shape of one simple crater and how it degrades.
#include "deterministic.hpp"

#include "terrain/synth/crater_field.hpp"
#include "tile_grid.hpp"

namespace terrain::synth {

// Ejecta reach, in crater radii: the (r/R)^-3 blanket is tapered to zero between 2 R and 3 R
// (the continuous ejecta blanket ends about one radius beyond the rim; Melosh 1989, ch. 6).
inline constexpr double kReach = 3.0;
inline constexpr double kTaperStart = 2.0;

// Fraction of the relief a crater of diameter `d` has lost after `age` (fraction of the
// surface age): topographic diffusion degrades a crater on a time scale proportional to D^2
// (Soderblom 1970; Fassett & Thomson 2014), so 1 - exp(-ln2 * age * (D_half / D)^2).
double degradation(double d, double age, double d_half);

// Rim-to-floor depth and rim height over diameter of a fresh crater.
struct Shape {
    double depth_ratio, rim_ratio;
};

// Adds one simple crater to the surface. Heights relative to the pre-impact surface, with
// s = r / R (R the rim-crest radius):
//  - bowl: a paraboloid, rim-to-floor depth H = 0.2 D for fresh simple craters (Pike 1977,
//    d = 0.196 D for lunar simple craters; Vincent et al. 2014 find 0.15-0.2 on Vesta; every
//    crater of this tile is simple, Vesta's simple-to-complex transition being near 30 km);
//  - rim crest at height h = 0.04 D (Pike 1977: h = 0.036 D^1.014), rounded over a width
//    growing with degradation;
//  - ejecta blanket beyond the rim, thickness h (r/R)^-3 (McGetchin, Settle & Head 1973:
//    t = 0.14 R^0.74 (r/R)^-3.0), tapered to zero between 2 R and 3 R.
// Inside the rim the crater replaces the old surface (a plane fitted on the old rim) rather than
// adding to it, so that young craters cut cleanly into old ones; ejecta add to what is there.
// Degradation q in [0,1) scales the depth by (1-q) and the rim by (1-q)^1.5 (rims and ejecta
// soften first) and widens the rounding of the rim crest.
void add_crater(Grid& grid, const Geometry& geo, const Crater& c, const Shape& shape);

}  // namespace terrain::synth
