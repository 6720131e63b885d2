// The main job as one library call, as `terrain segment` runs it: read, mesh, field, Reeb
// graph, simplification, regions, and every output file plus run.json in OUTDIR.
//   segment_one_call DEM OUTDIR
#include <cstdio>

#include "terrain/core/error.hpp"
#include "terrain/pipeline/segment.hpp"

int main(int argc, char** argv) {
    if (argc != 3) return std::fprintf(stderr, "usage: segment_one_call DEM OUTDIR\n"), 2;
    using namespace terrain;
    try {
        pipeline::SegmentOptions options;  // the paper's terrain parameters are the defaults
        options.simplify = {10, 0.5};      // persistence 10, area ratio 0.5 %
        const auto progress = [](double fraction, std::string_view stage) {
            std::fprintf(stderr, "\r%3.0f%% %-24.*s", 100 * fraction, int(stage.size()),
                         stage.data());
            return true;  // false cancels
        };
        const auto result =
            pipeline::segment_to_directory(argv[1], argv[2], true, {}, options, progress);
        std::printf("\n%u regions, %zu critical nodes before simplification, %zu after\n",
                    result.segmentation.region_count, result.critical_before,
                    result.after.critical);
        for (const auto& r : result.regions.regions)
            if (r.id <= 3)
                std::printf("region %u: %.3g km^2, %s\n", r.id, r.area_m2 / 1e6,
                            segment::to_string(r.landform));
        return 0;
    } catch (const Error& e) {
        return std::fprintf(stderr, "\nsegment_one_call: %s\n", e.what()), 1;
    }
}
