#include <cstdio>

#include "terrain/core/version.hpp"
#include "terrain/io/read_dem.hpp"

int main(int argc, char** argv) {
    if (argc < 2) return 2;
    const terrain::Dem dem = terrain::io::read_dem(argv[1]);
    std::printf("terrain %s read %dx%d on %s\n", terrain::version().c_str(), dem.width, dem.height,
                dem.body.name.c_str());
    return dem.body.name == "Moon" ? 0 : 1;
}
