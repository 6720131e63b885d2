// terrain field INPUT --field shape-index|sdf|height -o OUT.tif|OUT.ply: the scalar field, as
// a Float32 raster on the DEM's grid or as a per-vertex PLY property.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cli.hpp"
#include "field_options.hpp"
#include "input.hpp"
#include "ranks.hpp"
#include "terrain/core/error.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_raster.hpp"

namespace terrain::cli {

// What the SDF met, for the summary: degenerate faces, faces without a value, orientation.
void print_sdf_notes(const field::SdfResult& sdf) {
    std::printf("sdf: vertex diameters %.6g .. %.6g mapped to 0 .. 100", sdf.min_diameter,
                sdf.max_diameter);
    if (sdf.degenerate_faces > 0)
        std::printf(
            "; %zu degenerate (zero-area) faces got no rays and took their neighbours' "
            "value",
            sdf.degenerate_faces);
    if (sdf.faces_without_value > 0)
        std::printf("; %zu faces whose rays met no inner surface took their neighbours' value",
                    sdf.faces_without_value);
    if (sdf.reoriented) std::printf("; the faces point inwards, rays were cast the other way");
    if (sdf.boundary_edges + sdf.nonmanifold_edges > 0)
        std::printf("; open mesh (%zu boundary, %zu non-manifold edges): rays through holes lost",
                    sdf.boundary_edges, sdf.nonmanifold_edges);
    std::printf("\n");
}

int run_field(int argc, char** argv) {
    return guarded("field", [&] {
        std::string input_path, output;
        bool quiet = false, overwrite = false;
        InputOptionValues input_values;
        FieldOptionValues field_values;
        po::options_description options("terrain field options");
        options.add_options()("input", po::value(&input_path)->required(),
                              "a DEM or a mesh (.off, .ply, .obj)")(
            "output,o", po::value(&output)->required(),
            "OUT.tif (DEM input: Float32 on the DEM's grid) or OUT.ply (per-vertex property)")(
            "overwrite", po::bool_switch(&overwrite), "replace an existing output")(
            "quiet,q", po::bool_switch(&quiet), "no progress output");
        add_field_options(options, field_values);
        add_input_options(options, input_values);
        po::positional_options_description positional;
        positional.add("input", 1);
        po::variables_map vm;
        if (!parse(argc, argv,
                   "terrain field INPUT --field shape-index|sdf|height -o OUT.tif|OUT.ply", options,
                   positional, vm))
            return 0;
        const field::FieldOptions field_options = to_field_options(field_values, vm);
        const bool to_ply = io::is_mesh_file(output);
        const std::string ext = std::filesystem::path(output).extension().string();
        if (!to_ply && ext != ".tif" && ext != ".tiff")
            throw UsageError("the output must end in .tif or .ply");
        if (!to_ply && io::is_mesh_file(input_path))
            throw UsageError("a mesh input gives a .ply output, not a raster");
        // Under mpirun the ranks make the ladder's field by bands of rows together, rank 0
        // writes (docs/scale.md, "Ranks"); any other field is made by rank 0 alone.
        const RankedCommand ranked;
        if (ranked.writer()) io::check_output_path(output, overwrite);

        const auto progress = terminal_progress(quiet || !ranked.writer());
        ranked.reading();
        const Input input = load_input(input_path, input_values, field_options.kind,
                                       scaled_progress(progress, 0, 0.4));
        const auto field_progress = scaled_progress(progress, 0.4, 1);
        std::vector<float> values;
        std::optional<field::SdfResult> sdf;
        // With --radius auto on a DEM, the radius each pixel took goes to <stem>_radius.tif.
        const bool scales = field_options.kind == field::FieldKind::shape_index &&
                            field_options.shape_index.auto_scale && !to_ply;
        const std::string radius_path =
            (std::filesystem::path(output).parent_path() /
             (std::filesystem::path(output).stem().string() + "_radius.tif"))
                .string();
        if (scales && ranked.writer()) io::check_output_path(radius_path, overwrite);
        ranked.read();
        pipeline::FieldShare share;
        if (!ranked.take_part(share, scales && input.dem.has_value())) return 0;
        std::vector<float> radius;
        if (field_options.kind == field::FieldKind::sdf) {
            const std::size_t open = input.dem && !field_options.sdf.allow_open
                                         ? mesh_topology(input.mesh).boundary_edges
                                         : 0;
            if (open > 0)
                throw Error("sdf", "a DEM tile is an open surface (" + std::to_string(open) +
                                       " boundary edges; only a global DEM closes) and the SDF "
                                       "needs a closed one; use --field shape-index, or "
                                       "--allow-open to compute it anyway");
            sdf = field::shape_diameter_function(input.mesh, field_options.sdf, field_progress);
            values = std::move(sdf->values);
        } else {
            check_field_limits(field_options, input.mesh);
            if (scales) {
                auto selected = pipeline::shared_scale_selected_field(
                    input.mesh, field_options.shape_index, share, field_progress);
                if (!ranked.writer()) return 0;
                values = std::move(selected.field);
                radius.reserve(selected.scale.size());
                for (const auto k : selected.scale) radius.push_back(float(selected.radii[k]));
            } else {
                values = field::vertex_field(input.mesh, input.dem ? &*input.dem : nullptr,
                                             field_options, field_progress);
            }
        }
        std::string name = field::to_string(field_options.kind);  // shape-index -> shape_index
        std::replace(name.begin(), name.end(), '-', '_');
        if (to_ply) {
            io::write_ply(input.mesh, output, overwrite, {{name, &values}});
        } else {
            io::write_float_raster(*input.dem,
                                   field::field_to_pixels(input.mesh, *input.dem, values), output,
                                   overwrite, name);
            if (scales)
                io::write_float_raster(*input.dem,
                                       field::field_to_pixels(input.mesh, *input.dem, radius),
                                       radius_path, overwrite, "radius_m");
        }
        const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
        std::printf("%s: %s on %zu vertices, range %.6g .. %.6g\n", output.c_str(), name.c_str(),
                    values.size(), double(*lo), double(*hi));
        if (sdf) print_sdf_notes(*sdf);
        if (scales) std::printf("%s: the radius each pixel took, metres\n", radius_path.c_str());
        return 0;
    });
}

}  // namespace terrain::cli
