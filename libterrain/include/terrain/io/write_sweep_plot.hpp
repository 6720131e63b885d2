#pragma once
// sweep.png: how a sweep's segmentations change with the area ratio (docs/sweep.md). Like
// every writer of io/: atomic, refuses an existing file unless `overwrite`, throws one
// terrain::Error (stage "write") on failure, and writes the same bytes for the same input.

#include <string>
#include <vector>

namespace terrain::io {

// Region count (blue) and mean region area (red) against the area ratio (log scale), each on
// its own axis from 0 to its maximum.
void write_sweep_plot(const std::vector<double>& area_ratios,
                      const std::vector<double>& region_counts,
                      const std::vector<double>& mean_areas, const std::string& path,
                      bool overwrite);

}  // namespace terrain::io
