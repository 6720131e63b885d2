#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

#include "terrain/core/error.hpp"
#include "terrain/io/temporary_files.hpp"
#include "terrain/pipeline/segment.hpp"

namespace terrain::pipeline {

namespace fs = std::filesystem;

OutputDirectory::OutputDirectory(std::string path, bool overwrite) : path_(std::move(path)) {
    std::error_code ec;
    const fs::path p = fs::path(path_).lexically_normal();
    if (p.filename().empty()) throw Error("write", "'" + path_ + "' is not a directory name");
    if (fs::exists(p, ec)) {
        if (!fs::is_directory(p, ec))
            throw Error("write", "'" + path_ + "' exists and is not a directory");
        if (!overwrite && !fs::is_empty(p, ec))
            throw Error("write", "'" + path_ + "' already exists; pass --overwrite to replace it");
    }
    const fs::path parent = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (!fs::is_directory(parent, ec))
        throw Error("write", "cannot write '" + path_ + "': '" + parent.string() +
                                 "' does not exist; create it first");
    if (::access(parent.c_str(), W_OK) != 0)
        throw Error("write",
                    "cannot create '" + path_ + "': '" + parent.string() + "' is not writable");
    temp_ = (parent / ("." + p.filename().string() + ".tmp" + std::to_string(::getpid()))).string();
    fs::remove_all(temp_, ec);
    io::remove_stale_temporaries(path_, true);  // of runs that died (interrupted, killed)
    if (!fs::create_directory(temp_, ec))
        throw Error("write", "cannot create a directory beside '" + path_ + "': " + ec.message());
}

OutputDirectory::~OutputDirectory() {
    if (committed_) return;
    std::error_code ec;
    fs::remove_all(temp_, ec);
}

void OutputDirectory::commit() {
    std::error_code ec;
    const std::string old = temp_ + ".old";
    const bool existed = fs::exists(path_, ec);
    if (existed) fs::rename(path_, old, ec);
    if (ec) throw Error("write", "cannot replace '" + path_ + "': " + ec.message());
    fs::rename(temp_, path_, ec);
    if (ec) {
        std::error_code ignored;
        if (existed) fs::rename(old, path_, ignored);
        throw Error("write", "cannot move the outputs into '" + path_ + "': " + ec.message());
    }
    committed_ = true;
    if (existed) fs::remove_all(old, ec);
}

}  // namespace terrain::pipeline
