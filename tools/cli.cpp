#include "cli.hpp"
#include "ranks.hpp"

#include <cmath>
#include <iostream>
#include <memory>

#include "signals.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/memory_budget.hpp"

namespace terrain::cli {

bool parse(int argc, char** argv, const std::string& usage, const po::options_description& options,
           const po::positional_options_description& positional, po::variables_map& vm) {
    po::options_description all;
    all.add(options);
    all.add_options()("help,h", "show this help");
    try {
        po::store(po::command_line_parser(argc, argv).options(all).positional(positional).run(),
                  vm);
        if (vm.count("help")) {
            std::cout << "Usage: " << usage << "\n\n" << all << "\n";
            return false;
        }
        po::notify(vm);
    } catch (const po::invalid_option_value& e) {  // a bad value: exit 1
        throw Error("options", std::string(e.what()) + " (see --help)");
    } catch (const po::error& e) {
        throw UsageError(std::string(e.what()) + " (see --help)");
    }
    return true;
}

namespace {
// True while a progress line is unfinished on stderr: an error then starts a new line.
bool progress_line_open = false;
}  // namespace

ProgressFn terminal_progress(bool quiet) {
    // Quiet or not, the callback turns SIGINT/SIGTERM into a cancellation.
    if (quiet) return [](double, std::string_view) { return pending_signal() == 0; };
    // As GDALTermProgress: each tenth as its number, a dot at each 2.5 % between, each once;
    // shared state lives in the closure.
    auto last = std::make_shared<int>(-1);
    return [last](double fraction, std::string_view) {
        const int step = static_cast<int>(fraction * 40.0 + 1e-9);
        while (*last < step) {
            ++*last;
            if (*last == 40)
                std::cerr << "100 - done." << std::endl;
            else if (*last % 4 == 0)
                std::cerr << *last / 4 * 10 << std::flush;
            else
                std::cerr << '.' << std::flush;
            progress_line_open = *last != 40;
        }
        return pending_signal() == 0;
    };
}

int guarded(const std::string& command, const std::function<int()>& body) {
    // With several ranks, the line names the rank, and every rank stops.
    const bool several = ranks().size > 1;
    auto report = [&](const std::string& message) {
        if (progress_line_open) std::cerr << "\n";
        progress_line_open = false;
        std::cerr << "terrain " << command << ": "
                  << (several ? "rank " + std::to_string(ranks().rank) + ": " : "") << message
                  << "\n";
        std::cerr.flush();
    };
    const auto stop = [&](int status) {
        if (several) stop_all_ranks(status);
        return status;
    };
    // Interrupted: the work stopped at a progress callback and the temporaries went with the
    // unwinding; the status says which signal.
    auto interrupted = [&] {
        report("interrupted");
        return 128 + pending_signal();
    };
    try {
        const int status = body();
        return pending_signal() != 0 ? stop(interrupted()) : status;
    } catch (const UsageError& e) {
        if (pending_signal() != 0) return stop(interrupted());
        report(e.what());
        return stop(kUsageError);
    } catch (const terrain::Error& e) {
        if (pending_signal() != 0) return stop(interrupted());
        report(e.what());
        return stop(kUserError);
    } catch (const std::bad_alloc&) {
        report("out of memory; try a smaller input");
        return stop(kUserError);
    } catch (const std::exception& e) {
        if (pending_signal() != 0) return stop(interrupted());
        report(e.what());
        return stop(kUserError);
    }
}

}  // namespace terrain::cli

#include "dem_options.hpp"

namespace terrain::cli {

void add_dem_options(po::options_description& options, DemOptionValues& values) {
    options.add_options()("band,b", po::value(&values.band)->default_value(1),
                          "raster band to read (1-based)")(
        "elevation", po::value(&values.elevation)->default_value("auto"),
        "radius|height|auto: whether values are radii from the body's centre or heights "
        "above its reference (auto: radius when they sit near the body's radius)")(
        "nan-nodata", po::bool_switch(&values.nan_nodata),
        "treat NaN/Inf pixels as NoData holes instead of refusing the raster")(
        "pixel-size", po::value(&values.pixel_size),
        "metres per pixel, for a raster with no geotransform (default 1; at most 1e9)")(
        "max-memory", po::value(&values.max_memory),
        "refuse work whose estimated peak memory exceeds this (e.g. 2G, 512M); the memory "
        "available is always checked");
}

io::ReadDemOptions to_read_options(const DemOptionValues& values) {
    io::ReadDemOptions options;
    options.band = values.band;
    if (values.elevation != "auto") {
        options.elevation = value_named(kElevationNames, values.elevation);
        if (!options.elevation)
            throw Error("options", "--elevation must be radius, height or auto, not '" +
                                       values.elevation + "'");
    }
    options.nan_as_nodata = values.nan_nodata;
    if (values.pixel_size < 0 || !std::isfinite(values.pixel_size) || values.pixel_size > 1e9)
        throw Error("options", "--pixel-size must be a number of metres in (0, 1e9]");
    if (!values.max_memory.empty()) set_memory_limit(parse_memory_size(values.max_memory));
    if (values.pixel_size > 0) options.pixel_size = values.pixel_size;
    return options;
}

void add_common_options(po::options_description& options, CommonValues& values,
                        const char* output_help) {
    options.add_options()("input", po::value(&values.input)->required(),
                          "a DEM or a mesh (.off, .ply, .obj)")(
        "output,o", po::value(&values.output)->required(), output_help)(
        "overwrite", po::bool_switch(&values.overwrite), "replace existing outputs")(
        "quiet,q", po::bool_switch(&values.quiet), "no progress output");
}

bool parse_command(int argc, char** argv, const std::string& usage,
                   const po::options_description& options, po::variables_map& vm) {
    po::positional_options_description positional;
    positional.add("input", 1);
    return parse(argc, argv, usage, options, positional, vm);
}

}  // namespace terrain::cli
