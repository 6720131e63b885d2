#include "terrain/io/output_file.hpp"

#include <unistd.h>

#include <filesystem>
#include <system_error>

#include "terrain/core/error.hpp"
#include "terrain/io/temporary_files.hpp"

namespace terrain::io {

namespace fs = std::filesystem;

void check_output_path(const std::string& path, bool overwrite) {
    const fs::path p(path);
    std::error_code ec;
    if (fs::exists(p, ec) && !overwrite)
        throw Error("write", "'" + path + "' already exists; pass --overwrite to replace it");
    if (fs::is_directory(p, ec))
        throw Error("write", "'" + path + "' is a directory; give a file name");
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
        throw Error("write", "cannot write '" + path + "': '" + dir.string() + "' " +
                                 (fs::exists(dir, ec) ? "is not a directory" : "does not exist") +
                                 "; create the directory first");
    if (::access(dir.c_str(), W_OK) != 0)
        throw Error("write", "cannot create files in '" + dir.string() + "': it is not writable");
}

AtomicOutput::AtomicOutput(std::string path, bool overwrite) : path_(std::move(path)) {
    check_output_path(path_, overwrite);
    const fs::path p(path_);
    // Same directory (rename stays atomic), same extension (drivers pick formats by it).
    temp_ = (p.parent_path() / ("." + p.stem().string() + ".tmp" + std::to_string(::getpid()) +
                                p.extension().string()))
                .string();
    remove_stale_temporaries(path_);
    register_temporary(temp_);
}

AtomicOutput::~AtomicOutput() {
    unregister_temporary(temp_);
    if (committed_) return;
    std::error_code ec;
    fs::remove(temp_, ec);
}

void AtomicOutput::commit() {
    std::error_code ec;
    fs::rename(temp_, path_, ec);
    if (ec)
        throw Error("write", "cannot rename '" + temp_ + "' to '" + path_ + "': " + ec.message());
    committed_ = true;
}

}  // namespace terrain::io
