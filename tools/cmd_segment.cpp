// terrain segment INPUT -o OUTDIR [field options] [--persistence 10] [--area-ratio 0.5]
//                  [--cost graph|standard] [--saddle-penalty 20] [--timings]
// The main job: field, Reeb graph, simplification, region growing, then the files of
// docs/outputs.md (io::write_segment_outputs) and run.json.
// The outputs are written into a temporary sibling directory that replaces OUTDIR at the end,
// so OUTDIR appears complete or not at all.
#include "cli.hpp"
#include "field_options.hpp"
#include "input.hpp"
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
        add_field_options(options, field_values);
        add_input_options(options, input_values);
        po::variables_map vm;
        if (!parse_command(argc, argv,
                           "terrain segment INPUT -o OUTDIR [--persistence 10] [--area-ratio 0.5] "
                           "[--cost graph|standard] [--saddle-penalty 20] [--timings]",
                           options, vm))
            return 0;
        const auto field_options = to_field_options(field_values, vm);
        check_segment_options(segment_values);
        OutputDirectory dir(common.output, common.overwrite);

        const auto progress = terminal_progress(common.quiet);
        SegmentJob job;
        job.input = load_input(common.input, input_values, scaled_progress(progress, 0, 0.15));
        job.timings.push_back({"read", job.input.read_seconds});
        if (job.input.dem) job.timings.push_back({"mesh", job.input.mesh_seconds});
        compute_field(job, field_options, scaled_progress(progress, 0.15, 0.45));
        compute_reeb(job, scaled_progress(progress, 0.45, 0.6));
        segment_once(job, segment_values, scaled_progress(progress, 0.6, 0.7));
        // The preview is written last, once the large data is freed: OpenImageIO, loaded for
        // it, then does not add to the peak memory.
        io::PreviewImage preview;
        const auto files = write_segmentation(job, segment_values, dir.temp_path(),
                                              scaled_progress(progress, 0.7, 0.95),
                                              job.input.dem ? &preview : nullptr);
        release_large_data(job);
        if (job.input.dem) write_deferred_preview(job, preview, dir.temp_path());
        write_run_json(job, common.input, field_values, segment_values, files,
                       dir.temp_path() + "/run.json");
        dir.commit();
        report_progress(progress, 1.0);
        print_summary(job, common.output, segment_values.timings);
        return 0;
    });
}

}  // namespace terrain::cli
