// libFuzzer target: a raster opened by GDAL from memory, then terrain's checks, the grid and
// its description (read_dem, describe_dem). With TERRAIN_FUZZ_PDS the input is a PDS3 label
// beside a fixed 16x16 MSB Int16 image; otherwise it is a whole file (small GeoTIFF, ASCII
// grid and attached-label PDS3 seeds). Only the GDAL drivers of those formats stay
// registered: the target tests terrain's checks on what they give, not GDAL's other
// drivers, and probing some 200 of them on every input made each run ten times slower.
#include <cpl_conv.h>
#include <cpl_vsi.h>
#include <gdal_priv.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
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

extern "C" int LLVMFuzzerInitialize(int*, char***) {
#ifdef TERRAIN_FUZZ_PDS
    const std::set<std::string> kept = {"PDS"};
#else
    const std::set<std::string> kept = {"GTiff", "PDS", "AAIGrid"};
#endif
    // GDAL_SKIP is applied by every GDALAllRegister, including the library's own.
    GDALAllRegister();
    auto* manager = GetGDALDriverManager();
    std::string skip;
    for (int i = 0; i < manager->GetDriverCount(); ++i) {
        const std::string name = manager->GetDriver(i)->GetDescription();
        if (!kept.count(name)) skip += (skip.empty() ? "" : " ") + name;
    }
    CPLSetConfigOption("GDAL_SKIP", skip.c_str());
    manager->AutoSkipDrivers();
    return 0;
}

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
    // One read per input (a planetary CRS costs tens of milliseconds of PROJ set-up): NaN
    // pixels as NoData or as an error, by the parity of the size.
    try {
        terrain::io::ReadDemOptions options;
        options.nan_as_nodata = size % 2 == 1;
        // The budget of a user who gives --max-memory 512M, well under libFuzzer's 2 GB limit
        // (the fuzzer's own corpus and GDAL's and PROJ's caches hold several hundred MB): a
        // grid the file declares beyond it is the budget's refusal, as on a machine with that
        // much memory. (Without it, a sparse but valid header of 9 GB is no finding.)
        options.memory.limit = std::uint64_t{512} << 20;
        const terrain::Dem dem = terrain::io::read_dem(path, options);
        const auto d = terrain::io::describe_dem(dem);
        // A grid read is a surface (issue 53): finite sizes, and on a body, latitudes inside
        // +-90 but for the half pixel of a pixel centre and the half pixel to its edge.
        if (!std::isfinite(d.pixel_width_m) || !std::isfinite(d.pixel_height_m)) std::abort();
        if (d.has_geographic_extent) {
            const double b = dem.body.semi_minor_axis();
            // (Both steps: a rotated pixel's corner is off its centre in both.)
            const auto& t = dem.transform;
            const double pixel_degrees =
                dem.georef.kind == terrain::CrsKind::geographic
                    ? std::hypot(t[1], t[4]) + std::hypot(t[2], t[5])
                    : (b > 0 ? (dem.georef.pixel_width_m + dem.georef.pixel_height_m) / b * 180 /
                                   3.141592653589793
                             : 0);
            const double limit = 90 + pixel_degrees + 1e-9;
            if (!std::isfinite(d.lat_min) || !std::isfinite(d.lat_max) || d.lat_min < -limit ||
                d.lat_max > limit)
                std::abort();
        }
    } catch (const terrain::Error&) {
    }
    VSIUnlink(path.c_str());
    return 0;
}
