#pragma once
// Private: atomic output for GDAL datasets made of several files (a GeoTIFF and its
// .aux.xml, a shapefile's .shp/.dbf/.shx/.prj). Not installed.

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "terrain/io/output_file.hpp"

namespace terrain::io {

// The files a dataset wrote (GDALDataset::GetFileList, before closing it).
std::vector<std::string> dataset_files(void* gdal_dataset);

// Renames the dataset's other files from the temporary name to the final one (".aux.xml"
// after "labels.tif", ".dbf" beside "regions.shp"; an existing one is replaced only with
// `overwrite`), then commits the main file.
void commit_dataset(AtomicOutput& output, const std::vector<std::string>& files, bool overwrite);

// Writes a file through `write` into a temporary sibling and renames it when complete;
// throws terrain::Error (stage "write") when it cannot be created or written.
void write_file_atomically(const std::string& path, bool overwrite,
                           const std::function<void(std::ostream&)>& write);

// Removes, unless released, every file left under the output's temporary name.
class TemporaryFiles {
  public:
    explicit TemporaryFiles(const AtomicOutput& output) : output_(output) {}
    ~TemporaryFiles();
    TemporaryFiles(const TemporaryFiles&) = delete;
    TemporaryFiles& operator=(const TemporaryFiles&) = delete;
    void release() { released_ = true; }

  private:
    const AtomicOutput& output_;
    bool released_ = false;
};

}  // namespace terrain::io
