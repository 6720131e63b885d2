// placeholder: being written
#include "cli.hpp"
namespace terrain::cli {
int run_synth(int, char**) { return kUserError; }
}  // namespace terrain::cli
