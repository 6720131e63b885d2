#include "dataset_files.hpp"

#include <gdal_priv.h>

#include <filesystem>
#include <fstream>
#include <system_error>

#include "terrain/core/error.hpp"

namespace terrain::io {
namespace {

namespace fs = std::filesystem;

// "dir/.labels.tmp42.tif" -> "dir/.labels.tmp42"
std::string stem_path(const std::string& path) {
    const fs::path p(path);
    return (p.parent_path() / p.stem()).string();
}

}  // namespace

std::vector<std::string> dataset_files(void* gdal_dataset) {
    std::vector<std::string> out;
    char** list = static_cast<GDALDataset*>(gdal_dataset)->GetFileList();
    for (char** f = list; f && *f; ++f) out.emplace_back(*f);
    CSLDestroy(list);
    return out;
}

void commit_dataset(AtomicOutput& output, const std::vector<std::string>& files, bool overwrite) {
    const std::string temp_stem = stem_path(output.temp_path());
    const std::string final_stem = stem_path(output.path());
    std::error_code ec;
    for (const auto& file : files) {
        if (fs::path(file) == fs::path(output.temp_path())) continue;
        if (file.compare(0, temp_stem.size(), temp_stem) != 0 || !fs::exists(file, ec)) continue;
        const std::string target = final_stem + file.substr(temp_stem.size());
        if (fs::exists(target, ec) && !overwrite)
            throw Error("write", "'" + target + "' already exists; pass --overwrite to replace it");
        fs::rename(file, target, ec);
        if (ec)
            throw Error("write",
                        "cannot rename '" + file + "' to '" + target + "': " + ec.message());
    }
    output.commit();
}

void write_file_atomically(const std::string& path, bool overwrite,
                           const std::function<void(std::ostream&)>& write) {
    AtomicOutput output(path, overwrite);
    {
        std::ofstream out(output.temp_path(), std::ios::binary);
        if (!out) throw Error("write", "cannot create '" + path + "'");
        write(out);
        out.flush();
        if (!out) throw Error("write", "writing '" + path + "' failed (disk full?)");
    }
    output.commit();
}

TemporaryFiles::~TemporaryFiles() {
    if (released_) return;
    const fs::path temp(output_.temp_path());
    const std::string prefix = temp.stem().string() + ".";
    std::error_code ec;
    const fs::path dir = temp.has_parent_path() ? temp.parent_path() : fs::path(".");
    std::vector<fs::path> left;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.compare(0, prefix.size(), prefix) == 0) left.push_back(it->path());
    }
    for (const auto& p : left) fs::remove(p, ec);
}

}  // namespace terrain::io
