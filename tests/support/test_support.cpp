#include "support/test_support.hpp"

#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace terrain::test {

std::string sample(const std::string& name) {
    return std::string(TERRAIN_SOURCE_DIR) + "/examples/data/" + name;
}

std::optional<std::string> real_data(const std::string& relative) {
    const std::string path = std::string(TERRAIN_REAL_DATA_DIR) + "/" + relative;
    if (!std::filesystem::exists(path)) return std::nullopt;
    return path;
}

std::filesystem::path scratch_dir(const std::string& name) {
    const auto dir = std::filesystem::current_path() / "scratch" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

std::string file_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::size_t resident_bytes(const void* p, std::size_t n) {
    const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    const auto first = reinterpret_cast<std::uintptr_t>(p) & ~(page - 1);
    const auto end = reinterpret_cast<std::uintptr_t>(p) + n;
    std::vector<unsigned char> in((end - first + page - 1) / page);
    if (::mincore(reinterpret_cast<void*>(first), end - first, in.data()) != 0)
        throw std::runtime_error("mincore failed");
    std::size_t pages = 0;
    for (const unsigned char c : in) pages += c & 1;
    return pages * page;
}

std::string write_raster(const std::filesystem::path& path, const RasterSpec& spec) {
    GDALAllRegister();
    GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
    const GDALDataType type = GDALGetDataTypeByName(spec.type.c_str());
    std::unique_ptr<GDALDataset> ds(
        driver->Create(path.c_str(), spec.width, spec.height, 1, type, nullptr));
    if (!ds) throw std::runtime_error("cannot create " + path.string());
    if (!spec.geotransform.empty()) {
        std::vector<double> gt = spec.geotransform;
        ds->SetGeoTransform(gt.data());
    }
    if (!spec.crs.empty()) {
        OGRSpatialReference srs;
        srs.SetFromUserInput(spec.crs.c_str());
        ds->SetSpatialRef(&srs);
    }
    GDALRasterBand* band = ds->GetRasterBand(1);
    if (spec.nodata) band->SetNoDataValue(*spec.nodata);
    if (spec.scale != 1) band->SetScale(spec.scale);
    if (spec.offset != 0) band->SetOffset(spec.offset);
    std::vector<double> values = spec.values;
    values.resize(static_cast<std::size_t>(spec.width) * spec.height, 0.0);
    if (band->RasterIO(GF_Write, 0, 0, spec.width, spec.height, values.data(), spec.width,
                       spec.height, GDT_Float64, 0, 0) != CE_None)
        throw std::runtime_error("cannot write " + path.string());
    return path.string();
}

std::vector<float> read_raster_values(const std::string& path) {
    GDALAllRegister();
    std::unique_ptr<GDALDataset> ds(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
    if (!ds) throw std::runtime_error("cannot open " + path);
    const int width = ds->GetRasterXSize(), height = ds->GetRasterYSize();
    std::vector<float> values(static_cast<std::size_t>(width) * height);
    if (ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, width, height, values.data(), width, height,
                                       GDT_Float32, 0, 0) != CE_None)
        throw std::runtime_error("cannot read " + path);
    return values;
}

namespace {
std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}
std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}
}  // namespace

CliResult run_cli(const std::vector<std::string>& args) {
    return run_program(TERRAIN_CLI, args);
}

CliResult run_program(const std::string& program, const std::vector<std::string>& args,
                      const std::vector<std::string>& environment) {
    static int counter = 0;
    const auto dir = std::filesystem::current_path() / "scratch" / "cli";
    std::filesystem::create_directories(dir);
    // CTest runs test cases as parallel processes: the pid keeps their files apart.
    const std::string id = std::to_string(::getpid()) + "_" + std::to_string(counter++);
    const auto out = dir / ("out" + id + ".txt");
    const auto err = dir / ("err" + id + ".txt");
    std::string command = environment.empty() ? "" : "env ";
    for (const auto& setting : environment) command += quote(setting) + " ";
    command += quote(program);
    for (const auto& a : args) command += " " + quote(a);
    command += " </dev/null >" + quote(out) + " 2>" + quote(err);
    const int raw = std::system(command.c_str());
    CliResult r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

}  // namespace terrain::test
