// terrain segment INPUT -o OUTDIR [field options] [--persistence 10]
//                  [--area-ratio 0.5 | --min-area AREA] [--cost graph|standard]
//                  [--saddle-penalty 20] [--absorbed divide|whole] [--format GeoJSON]
//                  [--timings]
// The main job: field, Reeb graph, simplification, region growing, and every output file
// (terrain/pipeline/segment.hpp does the work). The outputs are written into a temporary
// sibling directory that replaces OUTDIR at the end, so OUTDIR appears complete or not at all.
#include <optional>

#include "cli.hpp"
#include "field_options.hpp"
#include "input.hpp"
#include "ranks.hpp"
#include "segment_job.hpp"

namespace terrain::cli {

int run_segment(int argc, char** argv) {
    return guarded("segment", [&] {
        CommonValues common;
        InputOptionValues input_values;
        FieldOptionValues field_values;
        SegmentOptionValues segment_values;
        po::options_description options("terrain segment options");
        add_common_options(options, common, "OUTDIR: the directory to write");
        add_segment_options(options, segment_values);
        options.add_options()("craters", po::value(&segment_values.craters)->default_value("on"),
                              "on: a DEM's craters read from the regions (craters.csv, "
                              "craters.scc; docs/craters.md); off");
        add_field_options(options, field_values);
        add_input_options(options, input_values);
        po::variables_map vm;
        if (!parse_command(
                argc, argv,
                "terrain segment INPUT -o OUTDIR [--radius auto|M] [--persistence 10] "
                "[--area-ratio 0.5 | --min-area auto|AREA] [--cost graph|standard] "
                "[--saddle-penalty 20] [--absorbed auto|divide|whole] [--craters on|off] "
                "[--format GeoJSON|GPKG|...] [--timings]",
                options, vm))
            return 0;
        // (refuses contradictions: exit status 2)
        field_values.options = to_field_options(field_values, vm);
        check_one_area_threshold(vm, "min-area");
        segment_values.landform_defaults = no_scale_option(vm);
        auto segment_options = to_pipeline_options(field_values, segment_values);
        // Under mpirun the ranks make the field's bands together, and rank 0 alone goes on,
        // checks, reports and writes (docs/scale.md, "Ranks").
        const RankedCommand ranked;
        std::optional<pipeline::OutputDirectory> dir;
        if (ranked.writer()) dir.emplace(common.output, common.overwrite);

        const auto progress = terminal_progress(common.quiet || !ranked.writer());
        ranked.reading();
        auto input = load_input(common.input, input_values, field_values.options.kind,
                                scaled_progress(progress, 0, 0.15), true);
        check_field_limits(field_values.options, input.mesh);  // --radius against the mesh
        if (ranked.writer()) print_input_warnings("segment", input);
        ranked.read();
        if (!ranked.take_part(segment_options, input)) return 0;
        auto result = pipeline::segment(std::move(input), segment_options,
                                        scaled_progress(progress, 0.15, 0.7));
        if (!ranked.writer()) return 0;
        pipeline::WriteOptions write;
        write.release_memory = true;
        pipeline::write_segment_directory(result, segment_options, common.input, dir->temp_path(),
                                          write, scaled_progress(progress, 0.7, 0.95));
        dir->commit();
        report_progress(progress, 1.0);
        print_summary(result, common.output, segment_values.timings);
        return 0;
    });
}

}  // namespace terrain::cli
