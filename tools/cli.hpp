#pragma once
// Shared pieces of the `terrain` subcommands: exit codes, option parsing with --help, and
// the GDAL-style terminal progress bar.

#include <boost/program_options.hpp>
#include <functional>
#include <string>

#include "terrain/core/progress.hpp"

namespace terrain::cli {

namespace po = boost::program_options;

enum ExitCode : int { kSuccess = 0, kUserError = 1, kUsageError = 2 };

// Thrown for bad usage (unknown option, missing argument): exit status 2.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Parses argv into `vm` against `options` (+ positional), handling --help. Returns false when
// help was printed (the caller exits 0). Throws UsageError on bad usage.
bool parse(int argc, char** argv, const std::string& usage, const po::options_description& options,
           const po::positional_options_description& positional, po::variables_map& vm);

// The options of every mesh-based command: INPUT (positional), -o, --overwrite, -q.
struct CommonValues {
    std::string input, output;
    bool overwrite = false, quiet = false;
};
void add_common_options(po::options_description& options, CommonValues& values,
                        const char* output_help);
// parse() with INPUT as the positional argument.
bool parse_command(int argc, char** argv, const std::string& usage,
                   const po::options_description& options, po::variables_map& vm);

// GDAL-style progress on stderr ("0...10...20...30...40...50...60...70...80...90...100 - done.")
// or nothing when quiet.
ProgressFn terminal_progress(bool quiet);

// Runs a subcommand body, turning exceptions into one line on stderr and an exit code.
int guarded(const std::string& command, const std::function<int()>& body);

}  // namespace terrain::cli
