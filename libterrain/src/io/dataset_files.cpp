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
    // Every file named like the temporary in its directory, whether or not the driver listed
    // it (a Shapefile's .prj is written after the list is taken; a relative path may be listed
    // as "./.x.tmp1.dbf").
    const fs::path temp(output.temp_path());
    const std::string temp_stem = temp.stem().string() + ".";
    const std::string final_stem = stem_path(output.path());
    std::error_code ec;
    const fs::path dir = temp.has_parent_path() ? temp.parent_path() : fs::path(".");
    std::vector<fs::path> sidecars;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.compare(0, temp_stem.size(), temp_stem) == 0 && name != temp.filename().string())
            sidecars.push_back(it->path());
    }
    (void)files;
    for (const auto& f : sidecars) {
        const std::string name = f.filename().string();
        const std::string target = final_stem + name.substr(temp_stem.size() - 1);
        if (fs::exists(target, ec) && !overwrite)
            throw Error("write", "'" + target + "' already exists; pass --overwrite to replace it");
        fs::rename(f, target, ec);
        if (ec)
            throw Error("write",
                        "cannot rename '" + f.string() + "' to '" + target + "': " + ec.message());
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
