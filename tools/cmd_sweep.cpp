// terrain sweep INPUT -o OUTDIR [--area-ratios 0.1,0.25,0.5,1,2 | --min-areas 1km2,5km2]
//                [segment options]
// One segmentation per area ratio (or area on the body), reusing the field and the unsimplified
// Reeb graph; the scales run side by side on the cores (terrain/pipeline/sweep.hpp does the work).
// Outputs: labels.tif (one band per scale), regions.gpkg (one layer per scale) and
// regions_<ratio>.geojson, adjacency_<ratio>.json, lineage.json (how each region overlaps the
// regions of the next scale), sweep.csv, sweep.png and run.json. See docs/sweep.md.
#include <cstdio>

#include <optional>

#include "cli.hpp"
#include "field_options.hpp"
#include "input.hpp"
#include "ranks.hpp"
#include "segment_job.hpp"
#include "terrain/pipeline/sweep.hpp"

namespace terrain::cli {

int run_sweep(int argc, char** argv) {
    return guarded("sweep", [&] {
        CommonValues common;
        std::string ratios_text, areas_text;
        InputOptionValues input_values;
        FieldOptionValues field_values;
        SegmentOptionValues segment_values;
        po::options_description options("terrain sweep options");
        add_common_options(options, common, "OUTDIR: the directory to write");
        options.add_options()("area-ratios",
                              po::value(&ratios_text)->default_value("0.1,0.25,0.5,1,2"),
                              "the scales: area-ratio thresholds in percent, comma separated")(
            "min-areas", po::value(&areas_text),
            "instead of --area-ratios: the scales as areas on the body, comma separated (m^2, or "
            "1km2,5km2,20km2)");
        add_segment_options(options, segment_values);
        add_field_options(options, field_values);
        add_input_options(options, input_values);
        po::variables_map vm;
        if (!parse_command(
                argc, argv,
                "terrain sweep INPUT -o OUTDIR [--area-ratios 0.1,0.25,0.5,1,2 | --min-areas "
                "1km2,5km2] [segment options]",
                options, vm))
            return 0;
        if (!vm["area-ratio"].defaulted())
            throw UsageError("terrain sweep takes --area-ratios (a list), not --area-ratio");
        if (vm.count("min-area"))
            throw UsageError("terrain sweep takes --min-areas (a list), not --min-area");
        if (vm.count("min-areas") && !vm["area-ratios"].defaulted())
            throw UsageError("give --area-ratios or --min-areas, not both");
        const bool by_area = vm.count("min-areas") > 0;
        // (refuses contradictions: exit status 2)
        field_values.options = to_field_options(field_values, vm);
        auto segment_options = to_pipeline_options(field_values, segment_values);
        std::vector<double> ratios;
        std::vector<pipeline::AreaThreshold> areas;
        if (by_area)
            areas = pipeline::parse_min_areas(areas_text);
        else
            ratios = pipeline::parse_area_ratios(ratios_text);
        // Under mpirun the ranks make the field's bands together (docs/scale.md, "Ranks").
        const RankedCommand ranked;
        std::optional<pipeline::OutputDirectory> dir;
        if (ranked.writer()) dir.emplace(common.output, common.overwrite);

        const auto progress = terminal_progress(common.quiet || !ranked.writer());
        ranked.reading();
        auto input = load_input(common.input, input_values, field_values.options.kind,
                                scaled_progress(progress, 0, 0.15));
        check_field_limits(field_values.options, input.mesh);  // --radius against the mesh
        if (ranked.writer()) print_input_warnings("sweep", input);
        ranked.read();
        if (!ranked.take_part(segment_options, input)) return 0;
        auto result = by_area ? pipeline::sweep(std::move(input), areas, segment_options,
                                                scaled_progress(progress, 0.15, 0.75))
                              : pipeline::sweep(std::move(input), ratios, segment_options,
                                                scaled_progress(progress, 0.15, 0.75));
        if (!ranked.writer()) return 0;
        pipeline::write_sweep_directory(result, segment_options, common.input, dir->temp_path(),
                                        scaled_progress(progress, 0.75, 0.99));
        dir->commit();
        report_progress(progress, 1.0);
        std::printf("%s: %zu scales;", common.output.c_str(), result.scales.size());
        for (const auto& s : result.scales)
            std::printf(by_area ? " %s: %u regions;" : " %s%%: %u regions;", s.name.c_str(),
                        s.segmentation.region_count);
        std::printf(" %zu critical nodes before simplification\n", result.base.critical_before);
        if (segment_values.timings) print_timings(result.base.timings);
        return 0;
    });
}

}  // namespace terrain::cli
