// Reads a DEM with the library and prints the body, elevation kind and coverage.
//   describe_dem examples/data/vesta_hamo_tile.lbl
#include <cstdio>

#include "terrain/core/error.hpp"
#include "terrain/io/describe_dem.hpp"
#include "terrain/io/read_dem.hpp"

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: describe_dem DEM\n");
        return 2;
    }
    try {
        const terrain::Dem dem = terrain::io::read_dem(argv[1]);
        const auto d = terrain::io::describe_dem(dem);
        std::printf("%s: %dx%d pixels of %.1f m on %s (a = %.0f m), %s values %.1f..%.1f m\n",
                    argv[1], d.width, d.height, d.pixel_width_m, d.body.name.c_str(),
                    d.body.semi_major_axis, terrain::to_string(d.elevation), d.min_value,
                    d.max_value);
        if (d.global_longitude) std::printf("covers all longitudes: the mesh closes its seam\n");
    } catch (const terrain::Error& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
