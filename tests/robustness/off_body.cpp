// Projected grids that fall off their body (issue 53): a PDS3 label whose radius lost its
// <KM>, a line offset past the pole, a GeoTIFF whose origin is moved to 1e7 m. They gave
// latitudes of -4590 or 329 degrees, NaN vertices and areas, or an error about an internal
// step, with exit 0; each is now one line naming the bad value, exit 1, nothing written. A
// property test mutates the label's keys and the geotransform: exit 1 with one line, or exit
// 0 with finite outputs.
#include <gdal_priv.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "hostile_support.hpp"

using Catch::Matchers::Contains;
using namespace terrain::test;

namespace {

using Edits = std::vector<std::pair<std::string, std::string>>;

// The Vesta sample's label cut to a 64 x 64 tile beside an image made here (MSB Int16,
// radius = DN * 2 + 255000 m), with `edits` setting label keys (KEY = value, the first
// occurrence of the key at the start of a line).
std::string vesta_tile(const std::filesystem::path& dir, const std::string& name,
                       const Edits& edits) {
    std::string image;
    for (int row = 0; row < 64; ++row)
        for (int col = 0; col < 64; ++col) {
            const auto dn = static_cast<std::int16_t>(
                300 * std::sin(col / 5.0) * std::cos(row / 7.0) + 40 * ((row * col) % 5));
            image += static_cast<char>((static_cast<std::uint16_t>(dn) >> 8) & 0xff);
            image += static_cast<char>(static_cast<std::uint16_t>(dn) & 0xff);
        }
    write_bytes(dir / "tile64.img", image);
    std::string label = file_bytes(sample("vesta_hamo_tile.lbl"));
    Edits all = {{"RECORD_BYTES", "128"},      {"FILE_RECORDS", "64"},
                 {"^IMAGE", "\"tile64.img\""}, {"LINES", "64"},
                 {"LINE_SAMPLES", "64"},       {"LINE_LAST_PIXEL", "64"},
                 {"SAMPLE_LAST_PIXEL", "64"},  {"SAMPLE_PROJECTION_OFFSET", "31.5 <PIXEL>"}};
    all.insert(all.end(), edits.begin(), edits.end());
    for (const auto& [key, value] : all) {
        std::size_t at = 0;
        for (;;) {
            at = label.find(key, at);
            if (at == std::string::npos) throw std::runtime_error(key + " not in the label");
            const auto line = label.rfind('\n', at) + 1;
            const auto after = label.find_first_not_of(' ', at + key.size());
            if (label.find_first_not_of(' ', line) == at && label[after] == '=') break;
            at += key.size();
        }
        const auto end = label.find('\n', at);
        label.replace(at, end - at, key + " = " + value);
    }
    return write_bytes(dir / name, label);
}

// The Moon sample (simple cylindrical, 128 x 96) copied to `dir` with geotransform term
// `term` set to `value`.
std::string moon_with(const std::filesystem::path& dir, const std::string& name,
                      const std::vector<std::pair<int, double>>& terms) {
    const auto path = dir / name;
    std::filesystem::copy_file(sample("moon_ldem4_copernicus.tif"), path,
                               std::filesystem::copy_options::overwrite_existing);
    GDALAllRegister();
    std::unique_ptr<GDALDataset> ds(
        GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_UPDATE));
    if (!ds) throw std::runtime_error("cannot update " + path.string());
    double t[6];
    ds->GetGeoTransform(t);
    for (const auto& [term, value] : terms) t[term] = value;
    ds->SetGeoTransform(t);
    return path.string();
}

// The vertices' x, y, z and areas of a binary PLY that terrain wrote are all finite.
bool ply_finite(const std::filesystem::path& path, std::size_t& vertices) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    std::vector<std::string> types;
    bool in_vertex = false;
    vertices = 0;
    while (std::getline(in, line) && line != "end_header") {
        std::istringstream words(line);
        std::string word, type, name;
        words >> word;
        if (word == "element") {
            words >> name;
            in_vertex = name == "vertex";
            if (in_vertex) words >> vertices;
        } else if (word == "property" && in_vertex) {
            words >> type;
            types.push_back(type);
        }
    }
    for (std::size_t v = 0; v < vertices; ++v)
        for (const auto& type : types) {
            if (type == "double") {
                double d;
                in.read(reinterpret_cast<char*>(&d), sizeof d);
                if (!std::isfinite(d)) return false;
            } else if (type == "float") {
                float f;
                in.read(reinterpret_cast<char*>(&f), sizeof f);
                if (!std::isfinite(f)) return false;
            } else {
                in.ignore(4);  // int col, row; uint labels
            }
        }
    return bool(in);
}

}  // namespace

TEST_CASE("a PDS3 label whose radius lost its unit is refused, naming the key",
          "[robustness][dem][off_body]") {
    const auto dir = scratch_dir("off_body_radius");
    // 1.5 gave latitudes -4590 .. -4420 and 4096 NaN vertices; 32 and 64: -215 and -107.
    for (const char* radius : {"1.5", "32", "64"}) {
        const auto label = vesta_tile(dir, "radius.lbl", {{"A_AXIS_RADIUS", radius}});
        check_refused(
            label, dir,
            {"A_AXIS_RADIUS = " + std::string(radius), "not about 255000 m", "not a surface"});
    }
    // The tile as it is reads and meshes (the helper makes a valid grid).
    const auto good = vesta_tile(dir, "good.lbl", {});
    const auto r = run_limited({"mesh", good, "-o", (dir / "good.ply").string(), "-q"}, 60, 2048);
    CHECK(r.status == 0);
    std::size_t vertices = 0;
    CHECK(ply_finite(dir / "good.ply", vertices));
    CHECK(vertices == 4096);
}

TEST_CASE("a PDS3 line offset that puts the rows off the body is refused",
          "[robustness][dem][off_body]") {
    const auto dir = scratch_dir("off_body_line_offset");
    // With the radius of 1.5: "divide_absorbed: vertex 0 is in no region" from segment.
    const auto both =
        vesta_tile(dir, "both.lbl", {{"A_AXIS_RADIUS", "1.5"}, {"LINE_PROJECTION_OFFSET", "-1"}});
    check_refused(both, dir, {"A_AXIS_RADIUS = 1.5", "not a surface"});
    // With Vesta's radius, rows from -98.4 degrees: the offset is named.
    const auto south = vesta_tile(dir, "south.lbl", {{"LINE_PROJECTION_OFFSET", "-7000"}});
    check_refused(south, dir, {"LINE_PROJECTION_OFFSET = -7000", "not a surface"});
    // An offset of -1 alone puts the rows at 0 .. -1 degrees: a surface.
    const auto equator = vesta_tile(dir, "equator.lbl", {{"LINE_PROJECTION_OFFSET", "-1"}});
    const auto r = run_limited({"segment", equator, "-o", (dir / "eq").string(), "-q"}, 60, 2048);
    CHECK(r.status == 0);
    CHECK(r.err.empty());
}

TEST_CASE("a simple cylindrical GeoTIFF whose origin is moved off the Moon is refused",
          "[robustness][dem][off_body]") {
    const auto dir = scratch_dir("off_body_geotiff");
    // y origin 1e7 m: "lat 305.778855 .. 329.778862 degrees", and mesh and segment ran.
    const auto moved = moon_with(dir, "moved.tif", {{3, 1e7}});
    check_refused(moved, dir, {"geotransform's y origin", "Moon", "not a surface"});
    // A pixel height making 96 rows span more than pole to pole names the geotransform's step.
    const auto tall = moon_with(dir, "tall.tif", {{3, 0}, {5, -1e5}});
    check_refused(tall, dir, {"geotransform's pixel height", "not a surface"});
}

TEST_CASE("heights through the body's centre are refused", "[robustness][dem][off_body]") {
    const auto dir = scratch_dir("off_body_heights");
    // Radii of DN * 2 - 300000 m on Vesta (255 km): through the centre.
    const auto label = vesta_tile(dir, "deep.lbl", {{"OFFSET", "-300000.0"}});
    check_refused(label, dir, {"OFFSET = -300000", "must stay positive"});
}

TEST_CASE("mutated projected grids exit 1 with one line or 0 with finite outputs",
          "[robustness][dem][off_body]") {
    const auto dir = scratch_dir("off_body_property");
    std::vector<std::pair<std::string, std::string>> inputs;  // (what, path)
    const Edits label_mutations = {{"A_AXIS_RADIUS", "1.5"},
                                   {"A_AXIS_RADIUS", "0.001"},
                                   {"A_AXIS_RADIUS", "0"},
                                   {"A_AXIS_RADIUS", "-255.0 <KM>"},
                                   {"A_AXIS_RADIUS", "255000"},
                                   {"A_AXIS_RADIUS", "255000.0 <M>"},
                                   {"MAP_SCALE", "0.001 <KM/PIXEL>"},
                                   {"MAP_SCALE", "10 <KM/PIXEL>"},
                                   {"MAP_SCALE", "100"},
                                   {"MAP_SCALE", "-0.07 <KM/PIXEL>"},
                                   {"MAP_RESOLUTION", "0.01 <PIX/DEG>"},
                                   {"LINE_PROJECTION_OFFSET", "0"},
                                   {"LINE_PROJECTION_OFFSET", "5700"},
                                   {"LINE_PROJECTION_OFFSET", "5800"},
                                   {"LINE_PROJECTION_OFFSET", "-5790"},
                                   {"LINE_PROJECTION_OFFSET", "1e12"},
                                   {"SAMPLE_PROJECTION_OFFSET", "-1e6"},
                                   {"SAMPLE_PROJECTION_OFFSET", "1e15"},
                                   {"CENTER_LATITUDE", "90.0 <DEG>"},
                                   {"CENTER_LATITUDE", "-89.999"},
                                   {"CENTER_LATITUDE", "1000"},
                                   {"CENTER_LONGITUDE", "1e6"},
                                   {"MAXIMUM_LATITUDE", "95"},
                                   {"MINIMUM_LATITUDE", "-200"},
                                   {"LINES", "63"},
                                   {"LINES", "2"},
                                   {"LINE_SAMPLES", "63"},
                                   {"LINE_SAMPLES", "65"},
                                   {"OFFSET", "-254000.0"},
                                   {"SCALING_FACTOR", "-1000.0"}};
    int k = 0;
    for (const auto& [key, value] : label_mutations) {
        const std::string name = "label" + std::to_string(k++) + ".lbl";
        inputs.emplace_back(key + " = " + value, vesta_tile(dir, name, {{key, value}}));
    }
    const std::vector<std::vector<std::pair<int, double>>> transforms = {
        {{3, 1e7}},  {{3, -1e7}},    {{3, 2.72e6}}, {{3, 2.8e6}}, {{3, -2.0e6}},
        {{5, -1e5}}, {{5, 7580.84}}, {{0, 1e9}},    {{0, -1e12}}, {{2, 1e4}},
        {{4, 3e4}},  {{1, 4e6}},     {{3, 1e300}}};
    for (const auto& terms : transforms) {
        std::ostringstream what;
        for (const auto& [term, value] : terms) what << "t[" << term << "] = " << value << " ";
        const std::string name = "moon" + std::to_string(k++) + ".tif";
        inputs.emplace_back(what.str(), moon_with(dir, name, terms));
    }
    int refused = 0, meshed = 0;
    for (const auto& [what, input] : inputs) {
        INFO(what << " (" << input << ")");
        const auto info = run_limited({"info", input}, 60, 2048);
        INFO("info: " << info.err);
        CHECK((info.status == 0 || (info.status == 1 && line_count(info.err) == 1)));
        CHECK(info.out.find("nan") == std::string::npos);
        const auto ply = dir / "out.ply";
        std::filesystem::remove(ply);
        const auto mesh = run_limited({"mesh", input, "-o", ply.string(), "-q"}, 60, 2048);
        INFO("mesh: " << mesh.err);
        if (mesh.status == 0) {
            ++meshed;
            std::size_t vertices = 0;
            CHECK(ply_finite(ply, vertices));
            CHECK(vertices > 0);
        } else {
            ++refused;
            CHECK(mesh.status == 1);
            CHECK(line_count(mesh.err) == 1);
            CHECK_FALSE(std::filesystem::exists(ply));
        }
        // Where info refuses, mesh refuses too (the same check on reading).
        if (info.status == 1) CHECK(mesh.status == 1);
    }
    // Both outcomes are exercised.
    CHECK(refused > 5);
    CHECK(meshed > 5);
}
