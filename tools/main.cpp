// terrain: planetary terrain segmentation. Dispatches to one subcommand per file.
#include <malloc.h>

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "cli.hpp"
#include "ranks.hpp"
#include "signals.hpp"
#include "terrain/core/huge_pages.hpp"
#include "terrain/core/version.hpp"
#include "terrain/io/dependency_versions.hpp"

namespace terrain::cli {
int run_info(int argc, char** argv);
int run_synth(int argc, char** argv);
int run_mesh(int argc, char** argv);
int run_field(int argc, char** argv);
int run_reeb(int argc, char** argv);
int run_segment(int argc, char** argv);
int run_sweep(int argc, char** argv);
}  // namespace terrain::cli

namespace {

struct Command {
    const char* name;
    const char* summary;
    int (*run)(int, char**);
    bool large_arrays = false;  // works on the whole grid: started again with huge pages
    // Under mpirun its ranks share the field (ranks.hpp); other commands run on rank 0 alone.
    bool ranked = false;
};

constexpr Command kCommands[] = {
    {"info", "describe a DEM: size, pixel size, CRS, body, elevation kind and range",
     terrain::cli::run_info},
    {"mesh", "triangulate a DEM on its body (or check a mesh file) into a binary PLY",
     terrain::cli::run_mesh, true},
    {"field", "the scalar field (shape index, SDF, height) on a DEM's grid or a mesh's vertices",
     terrain::cli::run_field, true, true},
    {"reeb", "the Reeb graph of the field, simplified by persistence and area ratio",
     terrain::cli::run_reeb, true},
    {"segment", "the main job: regions from the Reeb graph, as rasters, polygons and graphs",
     terrain::cli::run_segment, true, true},
    {"sweep", "segmentations at several area ratios from one Reeb graph, with their lineage",
     terrain::cli::run_sweep, true, true},
    {"synth", "generate a synthetic cratered DEM tile (the Vesta sample)", terrain::cli::run_synth},
};

void print_usage(std::ostream& out) {
    out << "Usage: terrain <command> [options]   (terrain <command> --help for details)\n\n"
           "Commands:\n";
    for (const auto& c : kCommands)
        out << "  " << c.name << std::string(10 - std::strlen(c.name), ' ') << c.summary << "\n";
    out << "\nOptions:\n  --version   print the versions of terrain and its libraries\n"
           "  --help      show this help\n";
}

// Huge pages (docs/performance.md): glibc reads GLIBC_TUNABLES once, at start-up, so a
// command that works on whole grids starts itself again with glibc.malloc.hugetlb=1 added
// when the kernel gives huge pages on request only: whole grids run faster (fewer TLB misses
// and page faults); the outputs are the same. (`info`, `synth`, --help and --version start
// once: they gain nothing from a second start.) TERRAIN_HUGE_PAGES=0, or a GLIBC_TUNABLES
// that sets the tunable already, keeps things as they are; so does an exec that fails.
void start_again_with_huge_pages(char** argv) {
    const char* choice = std::getenv("TERRAIN_HUGE_PAGES");
    if (choice && std::strcmp(choice, "0") == 0) return;
    if (terrain::transparent_huge_page_mode() != "madvise") return;
    const char* set = std::getenv("GLIBC_TUNABLES");
    const std::string current = set ? set : "";
    const std::string tunables = terrain::tunables_with_huge_pages(current);
    if (tunables.empty()) return;
    // The program's own path, so that the process keeps its name ("terrain", not "exe") in
    // ps and top.
    char self[4096];
    const ssize_t length = ::readlink("/proc/self/exe", self, sizeof self - 1);
    if (length <= 0) return;
    self[length] = '\0';
    if (::setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
    ::execv(self, argv);
    // Still here: carry on with normal pages (run.json says which ran).
    if (set)
        ::setenv("GLIBC_TUNABLES", current.c_str(), 1);
    else
        ::unsetenv("GLIBC_TUNABLES");
}

}  // namespace

int main(int argc, char** argv) {
    // First of all: the program may start again.
    for (const auto& c : kCommands)
        if (argc >= 2 && c.large_arrays && std::strcmp(argv[1], c.name) == 0)
            start_again_with_huge_pages(argv);
    // The commands allocate a few arrays of megabytes each. glibc raises its mmap threshold
    // after such an array is freed, so later ones come from the heap and stay resident after
    // being freed; a fixed threshold gives them back at once (a lower peak of memory).
    mallopt(M_MMAP_THRESHOLD, 256 * 1024);
    terrain::cli::install_signal_handlers();
    if (argc < 2) {
        print_usage(std::cerr);
        return terrain::cli::kUsageError;
    }
    const std::string first = argv[1];
    if (first == "--help" || first == "-h" || first == "help") {
        print_usage(std::cout);
        return 0;
    }
    if (first == "--version") {
        std::cout << "terrain " << terrain::version() << "\n";
        for (const auto& [name, version] : terrain::dependency_versions())
            std::cout << "  " << name << " " << version << "\n";
        return 0;
    }
    for (const auto& c : kCommands) {
        if (first != c.name) continue;
        // Under mpirun: the ranked commands split their field over the ranks; any other runs
        // on rank 0 alone, the other ranks waiting for it to end.
        terrain::cli::start_ranks(argc, argv);
        const auto& ranks = terrain::cli::ranks();
        if (ranks.size > 1 && ranks.rank != 0 && !c.ranked) return terrain::cli::finish_ranks(0);
        return terrain::cli::finish_ranks(c.run(argc - 1, argv + 1));
    }
    std::cerr << "terrain: unknown command '" << first << "' (see terrain --help)\n";
    return terrain::cli::kUsageError;
}
