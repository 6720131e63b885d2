#pragma once
// Koenderink's shape index on mesh vertices (Koenderink & van Doorn 1992), from principal
// curvatures of a quadric fitted in each vertex's tangent frame; mapped to [0,1] as Dorai &
// Jain (1997) do and scaled by 100, the units of the paper's thresholds (METHOD.md s.2).
// Sign convention fixed by behaviour: cap +1 (100), cup -1 (0), ridge +0.5 (75),
// valley -0.5 (25), saddle and plane 0 (50).

#include <cstdint>
#include <vector>

#include "terrain/core/names.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::field {

// How the neighbourhood sums are made. mesh: per vertex over its gathered neighbours (cost
// grows with their number). grid (meshes made from a DEM, with a radius): from sums of the
// pixels' moments over tiles of the grid, summed-area tables for the disk window and row sums
// for the ball (docs/field.md). automatic: grid when it applies, else mesh.
enum class ShapeIndexMethod { automatic, mesh, grid };

// The window of a --radius neighbourhood on a mesh made from a DEM (meshes read from files
// always take the ball). disk: the pixels whose ground offset from the vertex, lifted onto its
// tangent plane, is within the radius (a disk on flat ground), drawn on the grid as six bands
// of rows, with a Monge fit over the horizontal plane; by the grid method its sums come from
// summed-area tables at a cost that does not grow with the radius. ball: the vertices within
// the radius in 3-D, reached through vertices within it, with the tangent-frame fit
// (docs/field.md, "Windows and methods").
enum class ShapeIndexWindow { disk, ball };

// The windows' names (--window, run.json).
inline constexpr Named<ShapeIndexWindow> kShapeIndexWindowNames[] = {
    {"disk", ShapeIndexWindow::disk},
    {"ball", ShapeIndexWindow::ball},
};
inline const char* to_string(ShapeIndexWindow window) {
    return name_of(kShapeIndexWindowNames, window);
}

struct ShapeIndexOptions {
    int rings = 2;      // neighbourhood: vertices within this many mesh edges
    double radius = 0;  // > 0: vertices within this distance in metres instead of rings
    // Curvedness times the mean neighbour distance below this is a planar point (SI 0).
    double planar_curvedness = 1e-4;
    ShapeIndexMethod method = ShapeIndexMethod::automatic;
    ShapeIndexWindow window = ShapeIndexWindow::disk;
    // The analysis scale chosen per vertex (`--radius auto`, DEM meshes only; docs/field.md,
    // "Scale chosen per vertex"): the disk window's fit is made over every radius of `radii`
    // (metres, increasing; empty: field::default_radii of the mesh), each vertex's
    // curvatures taken relative to the body's sphere as the fit sees it
    // (sphere_curvature_in_fit), and its scale-normalised curvedness c
    // (curvedness x radius) followed up the ladder. Each local maximum of c over the ladder
    // is a peak; a vertex takes its first significant peak (c >= contrast_curvedness) unless
    // a later one is peak_dominance times as strong, or its strongest peak when none is
    // significant; a rise to the ladder's top (or to the last rung whose window the tables
    // hold) is no peak (the landform is wider than the ladder: a quarter of that rung's
    // contrast, nearly planar). The field is 50 + 50 SI w, the
    // shape index of the chosen radius with its contrast w = c^2 / (c^2 + contrast_curvedness^2):
    // shapes too weak to be seen at any scale read as planar. c is the part the DEM's pixel
    // noise does not explain: sqrt(max(0, c^2 - (3 s)^2)), s the spread of curvedness that
    // noise alone gives the fit (pixel_noise; docs/field.md, "Pixel noise").
    // rings and radius are ignored.
    bool auto_scale = false;
    std::vector<double> radii;
    double contrast_curvedness = 0.14;
    double peak_dominance = 2.0;
    // A vertex whose window reaches beyond the grid method's tables (the disk near a pole)
    // gets no fit instead of the mesh path's (scale_selected_shape_index sets it above its
    // first radius, where the window's cost would grow with the radius).
    bool skip_wide = false;
    // The largest angle on the body (radians) a tile of the disk window's sums spans; each
    // tile's fits are made in the frame of its first vertex. scale_selected_shape_index widens
    // it, so that its large radii do not pay for margins many times a small tile's area.
    double disk_tile_angle = 0.05;
    // With the disk window on a DEM's grid, only the vertices of every sample_stride-th pixel
    // column and row (and of the grid's last column and row) are fitted; the others get no
    // call. scale_selected_shape_index sets it on its wide rungs, whose field varies over
    // their radius, and interpolates between the fitted vertices.
    int sample_stride = 1;
    // On a DEM's grid (the grid method and the disk window), the pixel rows [first_row,
    // end_row) whose vertices must get their value; the others may be left with any value
    // (the rows of tiles that hold none of them are not fitted). A part of a grid's field made
    // so is the whole field's, bit for bit, on those rows: the field split over processes
    // or tiles. Meshes not made from a DEM take every vertex.
    int first_row = 0;
    int end_row = INT32_MAX;
};

// The method shape_index_field takes for this mesh and these options: "grid" or "mesh".
// Throws terrain::Error when `grid` is asked for a mesh not made from a DEM.
const char* shape_index_method(const TriangleMesh& mesh, const ShapeIndexOptions& options);

// The neighbourhood shape_index_field takes: "rings", "disk" or "ball".
const char* shape_index_window(const TriangleMesh& mesh, const ShapeIndexOptions& options);

struct PrincipalCurvatures {
    double k1 = 0, k2 = 0;  // k1 >= k2, positive where the surface is convex (a cap)
    // The standard deviation of the curvedness that white noise of unit standard deviation
    // in the heights alone would give this fit (in the units of k1 and k2 per unit height;
    // from the fit's normal equations, slopes neglected); 0 where the fit does not say.
    double noise = 0;
};

// Shape index in [-1, 1] of principal curvatures (k1 >= k2, convex positive); 0 when both
// vanish.
double shape_index(double k1, double k2);

// Per-vertex principal curvatures (convex positive, normals outwards/up) in 1/m, and their
// noise factor in 1/m per metre of height noise.
std::vector<PrincipalCurvatures> principal_curvatures(const TriangleMesh& mesh,
                                                      const ShapeIndexOptions& options = {},
                                                      const ProgressFn& progress = {});

// Per-vertex shape index mapped to [0, 100]: 50 * (SI + 1). Multi-threaded, deterministic.
// With options.auto_scale, the scale-selected field (scale_selected_shape_index's).
std::vector<float> shape_index_field(const TriangleMesh& mesh,
                                     const ShapeIndexOptions& options = {},
                                     const ProgressFn& progress = {});

// The ladder of radii `--radius auto` takes on a DEM mesh: 2, 4, 8, ..., 128 times the
// mesh's pixel spacing (the square root of its mean vertex area), the largest kept below
// half the grid's smaller side and, on a body, half the body's radius (a landform wider than
// the ladder's top reads nearly planar). Throws terrain::Error for a mesh not made from a DEM.
std::vector<double> default_radii(const TriangleMesh& mesh);

// The mean curvature (1/m) the disk window's fit of radius `window_radius` gives a sphere of
// radius `sphere_radius`: 1/r and the bias of a quadratic fitted over a disk to the sphere's
// quartic term, 1/r (1 + k (R/r)^2), k = 0.14 as measured on the grid (3/16 for a disk
// uniform in angle; docs/field.md, "Scale chosen per vertex").
double sphere_curvature_in_fit(double sphere_radius, double window_radius);

struct ScaleSelectedField {
    std::vector<float> field;         // per vertex, in [0, 100] as shape_index_field's
    std::vector<std::uint8_t> scale;  // per vertex, the index in `radii` of its radius
    std::vector<double> radii;        // the ladder, metres
    double pixel_noise_m = 0;         // the DEM's pixel noise (pixel_noise)
};

// The standard deviation of a DEM mesh's pixel noise in metres (Immerkaer's estimator, made
// robust): the 3 x 3 product of the second differences along columns and along rows, which
// vanishes on any quadric (a slope, a bowl, the body's own curvature), applied to the heights
// of each pixel's neighbours above its tangent plane; sigma = median |response| / (6 x
// 0.6745), over up to 2^20 pixels taken on a fixed stride. 0 when fewer than 9 pixels have
// their whole 3 x 3 block. Deterministic.
double pixel_noise(const TriangleMesh& mesh);

// The scale-selected shape index of options.auto_scale (options.radii, or default_radii).
// Throws terrain::Error (stage "field") for a mesh not made from a DEM, a ladder that is
// not increasing and positive, or more than 16 radii.
ScaleSelectedField scale_selected_shape_index(const TriangleMesh& mesh,
                                              const ShapeIndexOptions& options,
                                              const ProgressFn& progress = {});

}  // namespace terrain::field
