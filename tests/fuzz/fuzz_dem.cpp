// libFuzzer target: a raster opened by GDAL from memory, then terrain's checks, the grid and
// its description (read_dem, describe_dem). With TERRAIN_FUZZ_PDS the input is a PDS3 label
// beside a fixed 16x16 MSB Int16 image; otherwise it is a whole file (GeoTIFF seeds).
#include <cpl_vsi.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/error.hpp"
#include "terrain/io/describe_dem.hpp"
#include "terrain/io/read_dem.hpp"

namespace {

void write_memory_file(const std::string& path, const std::uint8_t* data, std::size_t size) {
    VSILFILE* f = VSIFOpenL(path.c_str(), "wb");
    if (!f) return;
    VSIFWriteL(data, 1, size, f);
    VSIFCloseL(f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
#ifdef TERRAIN_FUZZ_PDS
    static const bool image_written = [] {
        std::vector<std::uint8_t> image(16 * 16 * 2);
        for (std::size_t i = 0; i < image.size(); i += 2) {
            image[i] = static_cast<std::uint8_t>((i / 2) % 7);
            image[i + 1] = static_cast<std::uint8_t>(i % 251);
        }
        write_memory_file("/vsimem/fuzz/tile.img", image.data(), image.size());
        return true;
    }();
    (void)image_written;
    const std::string path = "/vsimem/fuzz/tile.lbl";
#else
    const std::string path = "/vsimem/fuzz/input.tif";
#endif
    write_memory_file(path, data, size);
    for (bool nan_as_nodata : {false, true}) {
        try {
            terrain::io::ReadDemOptions options;
            options.nan_as_nodata = nan_as_nodata;
            const terrain::Dem dem = terrain::io::read_dem(path, options);
            (void)terrain::io::describe_dem(dem);
        } catch (const terrain::Error&) {
        }
    }
    VSIUnlink(path.c_str());
    return 0;
}
