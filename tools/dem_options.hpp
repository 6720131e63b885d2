#pragma once
// The DEM input options shared by every subcommand that reads a DEM.

#include "cli.hpp"
#include "terrain/io/read_dem.hpp"

namespace terrain::cli {

struct DemOptionValues {
    int band = 1;
    std::string elevation = "auto";
    bool nan_nodata = false;
    double pixel_size = 0;
    std::string max_memory;  // --max-memory, empty: none
};

// Adds --band, --elevation, --nan-nodata, --pixel-size bound to `values`.
void add_dem_options(po::options_description& options, DemOptionValues& values);

// Converts the parsed values; throws UsageError for an unknown --elevation.
io::ReadDemOptions to_read_options(const DemOptionValues& values);

}  // namespace terrain::cli
