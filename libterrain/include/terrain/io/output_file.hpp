#pragma once
// Outputs appear complete or not at all: write to a temporary sibling, rename when done.

#include <string>

namespace terrain::io {

// Throws terrain::Error (stage "write") when `path` exists and !overwrite, or when its
// directory does not exist or is not writable.
void check_output_path(const std::string& path, bool overwrite);

class AtomicOutput {
  public:
    AtomicOutput(std::string path, bool overwrite);  // runs check_output_path
    ~AtomicOutput();                                 // removes the temporary unless committed
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::string& temp_path() const { return temp_; }
    const std::string& path() const { return path_; }
    void commit();  // renames the temporary onto the final path

  private:
    std::string path_, temp_;
    bool committed_ = false;
};

}  // namespace terrain::io
