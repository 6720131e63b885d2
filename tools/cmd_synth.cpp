// terrain synth -o OUT.lbl: a synthetic cratered Vesta tile written as a PDS3 DEM in the layout
// of the Dawn HAMO DTM (the sample examples/data/vesta_hamo_tile.lbl is made this way).
#include <cstdint>
#include <iostream>
#include <string>

#include "cli.hpp"
#include "terrain/io/write_pds3_dem.hpp"
#include "terrain/synth/crater_field.hpp"

namespace terrain::cli {

int run_synth(int argc, char** argv) {
    return guarded("synth", [&] {
        synth::VestaTileOptions tile;
        std::string output;
        std::uint64_t seed = tile.seed;
        bool overwrite = false, quiet = false;
        po::options_description options("terrain synth options");
        options.add_options()("output,o", po::value(&output)->required(),
                              "the PDS3 label to write (*.lbl); the image goes beside it (*.img)")(
            "width", po::value(&tile.width)->default_value(tile.width), "tile width, pixels")(
            "height", po::value(&tile.height)->default_value(tile.height), "tile height, pixels")(
            "seed", po::value(&seed)->default_value(seed),
            "random seed: the same seed gives the same bytes")(
            "lon", po::value(&tile.center_lon)->default_value(tile.center_lon),
            "longitude of the tile centre, degrees east")(
            "lat", po::value(&tile.center_lat)->default_value(tile.center_lat),
            "latitude of the tile centre, degrees (within +-80)")(
            "overwrite", po::bool_switch(&overwrite), "replace existing files")(
            "quiet,q", po::bool_switch(&quiet), "no progress output");
        po::positional_options_description positional;
        po::variables_map vm;
        if (!parse(argc, argv,
                   "terrain synth -o OUT.lbl [--width 512] [--height 512] [--seed N] [--lon DEG] "
                   "[--lat DEG] [--overwrite] [-q]",
                   options, positional, vm))
            return 0;
        tile.seed = seed;
        const ProgressFn progress = terminal_progress(quiet);
        const Dem dem = synth::generate_vesta_tile(tile, scaled_progress(progress, 0.0, 0.9));
        io::Pds3DemOptions pds;
        pds.scaling_factor = synth::kHamoScalingFactor;
        pds.offset = synth::kHamoOffset;
        pds.overwrite = overwrite;
        pds.target_name = "VESTA";
        pds.description =
            "Synthetic digital terrain model of 4 Vesta made by terrain synth (seed " +
            std::to_string(tile.seed) +
            ") in the layout of the Dawn FC2 HAMO DTM: planetary radius = DN * 2 + 255000 m, "
            "64 pixels per degree. Not real data.";
        io::write_pds3_dem(dem, output, pds);
        report_progress(progress, 1.0, "write");
        std::cout << "Wrote " << output << " (PDS3 label) and " << io::pds3_image_path(output)
                  << " (" << dem.width << " x " << dem.height
                  << " MSB Int16, radius = DN * 2 + 255000 m)\n";
        return 0;
    });
}

}  // namespace terrain::cli
