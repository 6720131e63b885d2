#pragma once
// Every file `terrain segment` writes for one segmentation, in one call (METHOD.md section 6,
// docs/outputs.md); each goes through its own writer (write_label_raster.hpp,
// write_region_polygons.hpp, write_adjacency.hpp, write_preview.hpp, write_mesh_labels.hpp).

#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/core/progress.hpp"
#include "terrain/io/write_preview.hpp"
#include "terrain/io/write_region_polygons.hpp"
#include "terrain/mesh/triangle_mesh.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::io {

struct SegmentOutputOptions {
    bool overwrite = false;
    RegionPolygonOptions polygons;     // regions.<extension of the driver>
    std::string field_name = "field";  // the field's name in labels.ply
    // When set, preview.png is rendered into *deferred_preview instead of written; the caller
    // writes it with write_preview_image (to the path returned for it) once it has freed what
    // it no longer needs.
    PreviewImage* deferred_preview = nullptr;
    // preview.png's caption (its region count, when 0, is the graph's).
    PreviewCaption preview_caption;
};

// Everything for one segmentation into the existing directory `dir`: for a DEM (dem !=
// nullptr) labels.tif, regions.geojson, adjacency.{json,graphml,geojson}, preview.png; for a
// mesh read from a file labels.ply, faces.seg and the three adjacency files. Every path is
// checked before anything is written. Returns the paths written, in that order.
std::vector<std::string> write_segment_outputs(const std::string& dir, const TriangleMesh& mesh,
                                               const std::vector<float>& field,
                                               const std::vector<std::uint32_t>& labels,
                                               const segment::RegionGraph& graph, const Dem* dem,
                                               const SegmentOutputOptions& options = {},
                                               const ProgressFn& progress = {});

}  // namespace terrain::io
