// terrain synth -o OUT.lbl: a synthetic cratered Vesta tile written as a PDS3 DEM in the layout
// of the Dawn HAMO DTM (the sample examples/data/vesta_hamo_tile.lbl is made this way).
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <string>

#include "cli.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/write_pds3_dem.hpp"
#include "terrain/synth/crater_field.hpp"

namespace terrain::cli {
namespace {

// The tile's crater population as CSV, centres in pixels of the tile ((0,0) the top-left
// corner), diameters on the ground and in pixels along a row, depths from the rim crest to
// the floor as made (before later craters and the roughness changed them).
void write_crater_list(const synth::VestaTileOptions& tile, const Dem& dem, const std::string& path,
                       bool overwrite) {
    if (!overwrite && std::ifstream(path))
        throw Error("synth", path + " exists (--overwrite replaces it)");
    std::ofstream out(path);
    if (!out) throw Error("synth", "cannot write " + path);
    const double pixel = std::abs(dem.transform[1]);
    out << "id,col,row,diameter_m,diameter_px,degradation,age,depth_m\n";
    out.precision(10);
    std::size_t id = 0;
    for (const auto& c : synth::vesta_crater_population(tile))
        out << ++id << ',' << c.col << ',' << c.row << ',' << c.diameter << ','
            << c.diameter / pixel << ',' << c.degradation << ',' << c.age << ','
            << tile.depth_ratio * c.diameter * (1 - c.degradation) << '\n';
    if (!out.flush()) throw Error("synth", "cannot write " + path);
}

}  // namespace

int run_synth(int argc, char** argv) {
    return guarded("synth", [&] {
        synth::VestaTileOptions tile;
        std::string output, craters_csv;
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
            "craters", po::value(&craters_csv),
            "also write the generated craters as CSV (id, col, row in pixels of the tile, "
            "diameter_m, diameter_px, degradation, age), oldest first: the truth the crater "
            "benchmarks score against")("overwrite", po::bool_switch(&overwrite),
                                        "replace existing files")(
            "quiet,q", po::bool_switch(&quiet), "no progress output");
        po::positional_options_description positional;
        po::variables_map vm;
        if (!parse(argc, argv,
                   "terrain synth -o OUT.lbl [--width 512] [--height 512] [--seed N] [--lon DEG] "
                   "[--lat DEG] [--craters CSV] [--overwrite] [-q]",
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
        if (!craters_csv.empty()) write_crater_list(tile, dem, craters_csv, overwrite);
        report_progress(progress, 1.0, "write");
        std::cout << "Wrote " << output << " (PDS3 label) and " << io::pds3_image_path(output)
                  << " (" << dem.width << " x " << dem.height
                  << " MSB Int16, radius = DN * 2 + 255000 m)\n";
        return 0;
    });
}

}  // namespace terrain::cli
