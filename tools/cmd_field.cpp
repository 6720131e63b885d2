// terrain field INPUT --field shape-index|height -o OUT.tif|OUT.ply: the scalar field, as a
// Float32 raster on the DEM's grid or as a per-vertex PLY property.
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "cli.hpp"
#include "input.hpp"
#include "terrain/field/vertex_field.hpp"
#include "terrain/io/mesh_files.hpp"
#include "terrain/io/output_file.hpp"
#include "terrain/io/write_raster.hpp"

namespace terrain::cli {

void add_field_options(po::options_description& options, std::string& field_name,
                       field::ShapeIndexOptions& shape_index) {
    options.add_options()("field", po::value(&field_name)->default_value("shape-index"),
                          "shape-index (x100, in [0,100]) or height (metres above the reference)")(
        "rings", po::value(&shape_index.rings)->default_value(2),
        "shape index: fit over the vertices within N mesh edges")(
        "radius", po::value(&shape_index.radius)->default_value(0.0),
        "shape index: fit over the vertices within M metres instead of rings");
}

int run_field(int argc, char** argv) {
    return guarded("field", [&] {
        std::string input_path, output, field_name;
        bool quiet = false, overwrite = false;
        InputOptionValues input_values;
        field::FieldOptions field_options;
        po::options_description options("terrain field options");
        options.add_options()("input", po::value(&input_path)->required(),
                              "a DEM or a mesh (.off, .ply, .obj)")(
            "output,o", po::value(&output)->required(),
            "OUT.tif (DEM input: Float32 on the DEM's grid) or OUT.ply (per-vertex property)")(
            "overwrite", po::bool_switch(&overwrite), "replace an existing output")(
            "quiet,q", po::bool_switch(&quiet), "no progress output");
        add_field_options(options, field_name, field_options.shape_index);
        add_input_options(options, input_values);
        po::positional_options_description positional;
        positional.add("input", 1);
        po::variables_map vm;
        if (!parse(argc, argv, "terrain field INPUT --field shape-index|height -o OUT.tif|OUT.ply",
                   options, positional, vm))
            return 0;
        if (field_name == "sdf")
            throw UsageError("--field sdf is not available yet; use shape-index or height");
        field_options.kind = field::parse_field_kind(field_name);
        if (vm["rings"].defaulted() == false && field_options.shape_index.radius > 0)
            throw UsageError("give --rings or --radius, not both");
        const bool to_ply = io::is_mesh_file(output);
        const std::string ext = std::filesystem::path(output).extension().string();
        if (!to_ply && ext != ".tif" && ext != ".tiff")
            throw UsageError("the output must end in .tif or .ply");
        io::check_output_path(output, overwrite);

        const auto progress = terminal_progress(quiet);
        const Input input = load_input(input_path, input_values, scaled_progress(progress, 0, 0.4));
        const auto values = field::vertex_field(input.mesh, input.dem ? &*input.dem : nullptr,
                                                field_options, scaled_progress(progress, 0.4, 1));
        const std::string name = field_name == "height" ? "height" : "shape_index";
        if (to_ply) {
            io::write_ply(input.mesh, output, overwrite, {{name, &values}});
        } else {
            if (!input.dem) throw UsageError("a mesh input gives a .ply output, not a raster");
            io::write_float_raster(*input.dem,
                                   field::field_to_pixels(input.mesh, *input.dem, values), output,
                                   overwrite, name);
        }
        const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
        std::printf("%s: %s on %zu vertices, range %.6g .. %.6g\n", output.c_str(), name.c_str(),
                    values.size(), double(*lo), double(*hi));
        return 0;
    });
}

}  // namespace terrain::cli
