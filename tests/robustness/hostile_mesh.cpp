// Mesh files that crashed or exhausted memory inside the third-party parser: each is now one
// error line and exit 1, within seconds and a bounded amount of memory.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>

#include "hostile_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/io/mesh_files.hpp"

using Catch::Matchers::Contains;
using namespace terrain::test;

namespace {

std::string le32(std::uint32_t v) {
    std::string s(4, '\0');
    for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((v >> (8 * i)) & 0xFF);
    return s;
}
std::string lef(float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    return le32(v);
}

// A binary PLY triangle whose face list declares `entries` indices (the file holds three).
std::string binary_ply_with_list(std::uint32_t entries) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\n"
        "property list uint int vertex_indices\nend_header\n";
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) s += lef(f);
    s += le32(entries);
    for (std::uint32_t i : {0u, 1u, 2u}) s += le32(i);
    return s;
}

// Each case (file bytes, expected words) written as dir/case<i>.<ext> and given to `terrain
// mesh`: one error line naming the problem, exit status 1, no output left.
template <class Cases>
void check_mesh_cases_refused(const std::filesystem::path& dir, const Cases& cases,
                              const std::string& ext) {
    int i = 0;
    for (const auto& [text, expected] : cases) {
        const auto input = write_bytes(dir / ("case" + std::to_string(i++) + "." + ext), text);
        const auto r = run_limited({"mesh", input, "-o", (dir / "m.ply").string(), "-q"}, 30, 512);
        INFO(text);
        CHECK(r.status == 1);
        CHECK(line_count(r.err) == 1);
        CHECK_THAT(r.err, Contains(expected));
    }
    CHECK_FALSE(std::filesystem::exists(dir / "m.ply"));
}

// Every command that reads a mesh, with an output in `dir`.
std::vector<std::vector<std::string>> mesh_commands(const std::string& input,
                                                    const std::filesystem::path& dir) {
    return {{"mesh", input, "-o", (dir / "m.ply").string(), "-q"},
            {"field", input, "-o", (dir / "f.ply").string(), "-q"},
            {"reeb", input, "-o", (dir / "g.json").string(), "-q"},
            {"segment", input, "-o", (dir / "seg").string(), "-q"},
            {"sweep", input, "-o", (dir / "sweep").string(), "--area-ratios", "1,2", "-q"}};
}

void check_refused_everywhere(const std::string& input, const std::filesystem::path& dir,
                              const std::string& expected, int memory_mb = 3072) {
    for (const auto& args : mesh_commands(input, dir)) {
        INFO(args[0]);
        const auto r = run_limited(args, 60, memory_mb);
        CHECK(r.status == 1);
        CHECK(line_count(r.err) == 1);
        CHECK_THAT(r.err, Contains(expected));
    }
    CHECK(std::filesystem::is_empty(std::filesystem::path(input).parent_path() / "out"));
}

}  // namespace

TEST_CASE("a PLY property before any element is one error line, not a crash",
          "[robustness][mesh]") {
    const auto dir = scratch_dir("hostile_ply_property");
    std::filesystem::create_directories(dir / "out");
    // The 49 bytes that crashed CGAL's PLY reader in every command.
    const std::string bytes = "ply\nformat ascii 1.0\nproperty float x\nend_header\n";
    REQUIRE(bytes.size() == 49);
    const auto input = write_bytes(dir / "property_first.ply", bytes);
    check_refused_everywhere(input, dir / "out", "property before any element");
    CHECK_THROWS_AS(terrain::io::read_mesh(input), terrain::Error);
}

TEST_CASE("a binary PLY face list longer than the file is refused without allocating it",
          "[robustness][mesh]") {
    const auto dir = scratch_dir("hostile_ply_list");
    std::filesystem::create_directories(dir / "out");
    // 0xFFFFFFF0 entries grew the commands to 14-16 GB; 2^28 cost 1.08 GB. 512 MB here.
    for (std::uint32_t entries : {0xFFFFFFF0u, 1u << 28}) {
        const auto input = write_bytes(dir / ("list" + std::to_string(entries) + ".ply"),
                                       binary_ply_with_list(entries));
        check_refused_everywhere(input, dir / "out", "the rest of the file cannot hold them", 512);
    }
}

TEST_CASE("OFF headers and faces declaring more than the file holds are refused",
          "[robustness][mesh]") {
    const auto dir = scratch_dir("hostile_off");
    const std::pair<const char*, const char*> cases[] = {
        {"OFF\n3 2000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "cannot hold them"},
        {"OFF\n2000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "cannot hold them"},
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n", "cannot hold them"},
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n# a comment, not a vertex or a face\n", "OFF data end"},
        {"OFF\n-3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "not a non-negative integer"},
        // Found by fuzz_mesh_off: CGAL turned the index "0-1" (-1) into a size_t from a double.
        {"OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 8 1\n3 0 2 1\n3 0-1 3\n3 0 3 2\n3 1 2 3\x1a",
         "OFF face 1 lists 2 of its 3 vertices"},
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "refers to vertex '3'"},
    };
    check_mesh_cases_refused(dir, cases, "off");
}

TEST_CASE("PLY headers that lie or break the grammar are refused by the reader",
          "[robustness][mesh]") {
    const auto dir = scratch_dir("hostile_ply_headers");
    const std::pair<std::string, const char*> cases[] = {
        {"ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\nend_header\n",
         "the file holds"},
        {"ply\nelement vertex 3\nproperty float x\nend_header\n", "before the format"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", "no end_header"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n1\n",
         "unknown PLY property type"},
        {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int v\nend_header\n200 1 2\n",
         "cannot hold them"},
        {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int v\nend_header\n-3 1 2 3\n",
         "not a non-negative integer"},
        {"ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty double x\n"
         "end_header\n" +
             std::string(40, 'x'),
         "data end inside vertex"},
    };
    int i = 0;
    for (const auto& [text, expected] : cases) {
        const auto input = write_bytes(dir / ("case" + std::to_string(i++) + ".ply"), text);
        INFO(text);
        try {
            (void)terrain::io::read_mesh(input);
            FAIL("read_mesh accepted it");
        } catch (const terrain::Error& e) {
            CHECK_THAT(std::string(e.what()), Contains(expected));
        }
    }
}

TEST_CASE("mesh coordinates of 1e308 are refused instead of giving NaN areas",
          "[robustness][mesh]") {
    const auto dir = scratch_dir("hostile_mesh_coordinates");
    const auto input =
        write_bytes(dir / "far.off", "OFF\n3 1 0\n0 0 0\n1e308 0 0\n0 1 0\n3 0 1 2\n");
    const auto r = run_limited({"segment", input, "-o", (dir / "seg").string(), "-q"}, 30);
    CHECK(r.status == 1);
    CHECK(line_count(r.err) == 1);
    CHECK_THAT(r.err, Contains("beyond 1e9"));
    CHECK_FALSE(std::filesystem::exists(dir / "seg"));
}

TEST_CASE("OFF colours and vertex lines CGAL's scanner reads unchecked are refused",
          "[robustness][mesh]") {
    const auto dir = scratch_dir("hostile_off_colours");
    const std::string tail = "1 0 0\n0 1 0\n3 0 1 2\n";
    const std::pair<std::string, const char*> cases[] = {
        // Found by fuzz_mesh_off: a COFF vertex line without numbers made CGAL read the
        // colour of an empty line (undefined behaviour in File_scanner_OFF::scan_color).
        {"COFF\n# 0 0\n1 0 0\n` 1 0\n0 ~ C0\n*CC4", "OFF vertex 0 is not a line of 3 numbers"},
        {"COFF\n3 1 0\n0 inf 0 1 2 3\n" + tail, "OFF vertex 0 is not a line"},
        {"COFF\n3 1 0\n0 0 0 1 2\n" + tail, "vertex 0 has 2 colour values"},
        {"COFF\n3 1 0\n0 0 0 300 0 0\n" + tail, "vertex 0 has a colour out of range"},
        {"COFF\n3 1 0\n0 0 0 -5\n" + tail, "vertex 0 has a colour out of range"},
        {"COFF\n3 1 0\n0 0 0 0.5 2.5 0\n" + tail, "vertex 0 has a colour out of range"},
        {"COFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 1 2\n", "face 0 has 2 colour values"},
        {"NOFF\n3 1 0\n0 0 0 0 0\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n", "not a line of 6 numbers"},
        {"STOFF\n3 1 0\n0 0 0 0 0\n" + tail, "texture coordinates"},
        {"XOFF\n3 1 0\n0 0 0\n" + tail, "unknown OFF keyword"},
        // Found by fuzz_mesh_off: CGAL reads the edge count from the next line when the
        // header line lacks it; read without it, the data were shifted by one number and a
        // face's "5 0" taken for a colour (5 x 255 does not fit a byte: undefined behaviour).
        {"COFF\n# 0\n 0\n1 \n 0\n0 5 0\n20\n2 C4", "OFF face 0 has 2 colour values"},
        {"OFF\n3 1\n0 0 0\n" + tail, "numbers after its three counts"},
        // Found by fuzz_mesh_off: a comment glued to the keyword ("OFF#4 4 0") is a comment
        // to a reader that cuts lines at '#', not to CGAL's scanner, which then took a face
        // index of 7.8e23 for a size_t (undefined behaviour).
        {"OFF#4 4 0\n0 0 0\n0 0 0\n0 1 0\n0 0 30 \n1 2x", "comment glued to the OFF keyword"},
        // Found by fuzz_mesh_off: once a face (vertex) has a colour CGAL reads one for every
        // later face (vertex), past the numbers of a line without one (a heap overflow in
        // File_scanner_OFF::scan_color). The fuzzer's input is replayed below.
        {"COFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 0 255 0\n3 0 2 1\n",
         "OFF face 1 has no colour after one with a colour"},
        {"COFF\n3 1 0\n0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n",
         "OFF vertex 1 has no colour after one with a colour"},
        {file_bytes(case_path("off_face_without_colour_after_coloured.off")),
         "OFF face 2 has no colour after one with a colour"},
    };
    check_mesh_cases_refused(dir, cases, "off");

    // Colours as CGAL reads them (an index, RGB integers, RGBA, fractions) stay readable,
    // as do normals and homogeneous coordinates.
    const std::string valid[] = {
        "COFF\n4 2 0\n0 0 0 7\n1 0 0 255 0 0\n0 1 0 0.5 0.25 1 1\n1 1 0 0 0 255 255\n"
        "3 0 1 2 12\n3 1 3 2 0 255 0\n",
        "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n",
        "4OFF\n3 1 0\n0 0 0 1\n2 0 0 2\n0 1 0 1\n3 0 1 2\n",
    };
    int i = 0;
    for (const auto& text : valid) {
        INFO(text);
        const auto input = write_bytes(dir / ("valid" + std::to_string(i++) + ".off"), text);
        const auto mesh = terrain::io::read_mesh(input);
        CHECK(mesh.triangles().size() >= 1);
    }
}

TEST_CASE("a PLY format line other than the second is refused, not read in another format",
          "[robustness][mesh]") {
    // Found by fuzz_mesh_ply: CGAL takes the second line as the format and ignores a later
    // `format` line, which the header check used to follow: the ASCII face "3 0 1 2" read as
    // binary declares a list of 0x20302033 entries, about 2 GB.
    const auto dir = scratch_dir("hostile_ply_format");
    const std::string body =
        "element vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\n"
        "property list uint int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    const std::pair<std::string, const char*> cases[] = {
        {"ply\nformat binary_little_endian 1.0\nformat ascii 1.0\n" + body, "second line"},
        {"ply\ncomment binary_little_endian 1.0\nformat ascii 1.0\n" + body, "second line"},
    };
    check_mesh_cases_refused(dir, cases, "ply");
    const auto valid = write_bytes(dir / "valid.ply", "ply\nformat ascii 1.0\n" + body);
    CHECK(terrain::io::read_mesh(valid).triangles().size() == 1);
}
