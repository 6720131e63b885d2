#include "mesh_header_check.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>
#include <vector>

#include "terrain/core/error.hpp"

namespace terrain::io {
namespace {

[[noreturn]] void refuse(const std::string& name, const std::string& what) {
    throw Error("mesh", "cannot read a mesh from '" + name + "': " + what);
}

std::string str(std::uint64_t n) {
    return std::to_string(n);
}

// One line of a text header, without its end of line (LF or CRLF).
struct LineReader {
    std::string_view bytes;
    std::size_t pos = 0;
    std::optional<std::string_view> next() {
        if (pos >= bytes.size()) return std::nullopt;
        const std::size_t end = bytes.find('\n', pos);
        const std::size_t stop = end == std::string_view::npos ? bytes.size() : end;
        std::string_view line = bytes.substr(pos, stop - pos);
        pos = end == std::string_view::npos ? bytes.size() : end + 1;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        return line;
    }
};

std::vector<std::string_view> split(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        const std::size_t start = i;
        while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        if (i > start) out.push_back(line.substr(start, i - start));
    }
    return out;
}

// A non-negative decimal integer, or nullopt (signs, other characters, overflow).
std::optional<std::uint64_t> parse_count(std::string_view token) {
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    std::uint64_t value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size() || token.empty())
        return std::nullopt;
    return value;
}

// ---------------------------------------------------------------------------------- PLY

struct PlyType {
    const char* name;
    int size;
    bool is_signed;
    bool is_float;
};
constexpr PlyType kPlyTypes[] = {
    {"char", 1, true, false},    {"int8", 1, true, false},    {"uchar", 1, false, false},
    {"uint8", 1, false, false},  {"short", 2, true, false},   {"int16", 2, true, false},
    {"ushort", 2, false, false}, {"uint16", 2, false, false}, {"int", 4, true, false},
    {"int32", 4, true, false},   {"uint", 4, false, false},   {"uint32", 4, false, false},
    {"float", 4, true, true},    {"float32", 4, true, true},  {"double", 8, true, true},
    {"float64", 8, true, true},
};

const PlyType* ply_type(std::string_view name) {
    for (const auto& t : kPlyTypes)
        if (name == t.name) return &t;
    return nullptr;
}

struct PlyProperty {
    const PlyType* type = nullptr;       // the value's type
    const PlyType* size_type = nullptr;  // a list's length type, or null
};
struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

// Reads a binary list length; false when it is negative or a float.
bool read_length(const unsigned char* p, const PlyType& t, bool big_endian, std::uint64_t& out) {
    if (t.is_float) return false;
    std::uint64_t v = 0;
    for (int i = 0; i < t.size; ++i) {
        const unsigned char b = big_endian ? p[i] : p[t.size - 1 - i];
        v = (v << 8) | b;
    }
    if (t.is_signed && (v >> (8 * t.size - 1)) != 0) return false;
    out = v;
    return true;
}

// A PLY header: its format (0 ascii, 1 little endian, 2 big endian), its elements and where
// its data begin.
struct PlyHeader {
    int format = -1;
    std::vector<PlyElement> elements;
    std::size_t body = 0;
};

PlyHeader read_ply_header(std::string_view bytes, const std::string& name) {
    LineReader lines{bytes};
    const auto first = lines.next();
    if (!first || *first != "ply") refuse(name, "not a PLY file (the first line is not 'ply')");
    PlyHeader header;
    int& format = header.format;  // 0 ascii, 1 little endian, 2 big endian
    std::vector<PlyElement>& elements = header.elements;
    bool ended = false;
    std::size_t line_number = 1;
    while (auto line = lines.next()) {
        ++line_number;
        const auto tokens = split(*line);
        const std::string where = " (header line " + str(line_number) + ")";
        if (tokens.empty()) continue;
        const auto key = tokens[0];
        if (key == "comment" || key == "obj_info") continue;
        if (key == "end_header") {
            ended = true;
            break;
        }
        if (key == "format") {
            // CGAL takes the second line as the format whatever it says and ignores other
            // format lines: the data must be walked in the format CGAL reads.
            if (line_number != 2 || format >= 0)
                refuse(name, "PLY format line must be the second line, and the only one" + where);
            if (tokens.size() < 2) refuse(name, "PLY format line without a format" + where);
            if (tokens[1] == "ascii")
                format = 0;
            else if (tokens[1] == "binary_little_endian")
                format = 1;
            else if (tokens[1] == "binary_big_endian")
                format = 2;
            else
                refuse(name, "unknown PLY format '" + std::string(tokens[1]) + "'" + where);
        } else if (key == "element") {
            if (format < 0) refuse(name, "PLY element before the format line" + where);
            if (tokens.size() != 3)
                refuse(name, "PLY element line needs a name and a count" + where);
            const auto count = parse_count(tokens[2]);
            if (!count)
                refuse(name, "PLY element count '" + std::string(tokens[2]) +
                                 "' is not a non-negative integer" + where);
            // Every element takes at least one byte of the file.
            if (*count > bytes.size())
                refuse(name, "PLY header declares " + str(*count) + " " + std::string(tokens[1]) +
                                 " elements but the file holds " + str(bytes.size()) + " bytes");
            elements.push_back({std::string(tokens[1]), *count, {}});
        } else if (key == "property") {
            if (elements.empty()) refuse(name, "PLY property before any element" + where);
            PlyProperty property;
            if (tokens.size() >= 2 && tokens[1] == "list") {
                if (tokens.size() != 5)
                    refuse(name, "PLY list property needs two types and a name" + where);
                property.size_type = ply_type(tokens[2]);
                property.type = ply_type(tokens[3]);
                if (!property.size_type || property.size_type->is_float)
                    refuse(name, "PLY list length type '" + std::string(tokens[2]) +
                                     "' is not an integer type" + where);
            } else {
                if (tokens.size() != 3)
                    refuse(name, "PLY property needs a type and a name" + where);
                property.type = ply_type(tokens[1]);
            }
            if (!property.type) refuse(name, "unknown PLY property type" + where);
            elements.back().properties.push_back(property);
        } else {
            refuse(name, "unknown PLY header keyword '" + std::string(key) + "'" + where);
        }
    }
    if (!ended) refuse(name, "PLY header has no end_header line");
    if (format < 0) refuse(name, "PLY header has no format line (the second line)");

    header.body = lines.pos;
    return header;
}

// The ascii data after the header (whitespace-separated tokens), walked as CGAL reads them;
// adds the faces' indices to `counts`.
void check_ply_ascii(std::string_view bytes, const std::string& name, const PlyHeader& header,
                     MeshFileCounts& counts) {
    auto truncated = [&](const PlyElement& e, std::uint64_t i) {
        refuse(name, "PLY data end inside " + e.name + " " + str(i) + " of " + str(e.count) +
                         " declared; the file is truncated or its header lies");
    };
    std::size_t pos = header.body;
    auto token = [&]() -> std::optional<std::string_view> {
        while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
        const std::size_t start = pos;
        while (pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
        if (pos == start) return std::nullopt;
        return bytes.substr(start, pos - start);
    };
    for (const auto& e : header.elements)
        for (std::uint64_t i = 0; i < e.count; ++i)
            for (const auto& p : e.properties) {
                const auto t = token();
                if (!t) truncated(e, i);
                if (!p.size_type) continue;
                const auto n = parse_count(*t);
                if (!n)
                    refuse(name, "PLY list length '" + std::string(*t) + "' in " + e.name + " " +
                                     str(i) + " is not a non-negative integer");
                // Each entry takes at least one character and one separator.
                if (*n > (bytes.size() - pos + 1) / 2)
                    refuse(name, "PLY " + e.name + " " + str(i) + " declares a list of " + str(*n) +
                                     " entries; the rest of the file cannot hold them");
                if (e.name == "face") counts.indices += *n;
                for (std::uint64_t k = 0; k < *n; ++k)
                    if (!token()) truncated(e, i);
            }
}

// The binary data after the header, walked as CGAL reads them; adds the faces' indices to
// `counts`.
void check_ply_binary(std::string_view bytes, const std::string& name, const PlyHeader& header,
                      MeshFileCounts& counts) {
    auto truncated = [&](const PlyElement& e, std::uint64_t i) {
        refuse(name, "PLY data end inside " + e.name + " " + str(i) + " of " + str(e.count) +
                         " declared; the file is truncated or its header lies");
    };
    const bool big_endian = header.format == 2;
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    std::uint64_t pos = header.body;
    for (const auto& e : header.elements) {
        const bool fixed = std::none_of(e.properties.begin(), e.properties.end(),
                                        [](const PlyProperty& p) { return p.size_type; });
        if (fixed) {
            std::uint64_t row = 0;
            for (const auto& p : e.properties) row += p.type->size;
            if (row > 0 && e.count > (bytes.size() - pos) / row)
                truncated(e, (bytes.size() - pos) / row);
            pos += row * e.count;
            continue;
        }
        for (std::uint64_t i = 0; i < e.count; ++i)
            for (const auto& p : e.properties) {
                if (!p.size_type) {
                    if (bytes.size() - pos < std::uint64_t(p.type->size)) truncated(e, i);
                    pos += p.type->size;
                    continue;
                }
                if (bytes.size() - pos < std::uint64_t(p.size_type->size)) truncated(e, i);
                std::uint64_t n = 0;
                if (!read_length(data + pos, *p.size_type, big_endian, n))
                    refuse(name, "PLY list length in " + e.name + " " + str(i) + " is negative");
                pos += p.size_type->size;
                if (n > (bytes.size() - pos) / p.type->size)
                    refuse(name, "PLY " + e.name + " " + str(i) + " declares a list of " + str(n) +
                                     " entries; the rest of the file cannot hold them");
                if (e.name == "face") counts.indices += n;
                pos += n * p.type->size;
            }
    }
}

MeshFileCounts check_ply(std::string_view bytes, const std::string& name) {
    const PlyHeader header = read_ply_header(bytes, name);
    MeshFileCounts counts;
    for (const auto& e : header.elements) {
        if (e.name == "vertex") counts.vertices = e.count;
        if (e.name == "face") counts.faces = e.count;
    }
    if (header.format == 0)  // ascii: whitespace-separated tokens
        check_ply_ascii(bytes, name, header, counts);
    else
        check_ply_binary(bytes, name, header, counts);
    return counts;
}

// ---------------------------------------------------------------------------------- OFF

// The data lines of an OFF file: comments (from '#') removed, blank lines skipped.
struct OffLines {
    LineReader reader;
    std::optional<std::string_view> next() {
        while (auto line = reader.next()) {
            std::string_view l = *line;
            if (const auto hash = l.find('#'); hash != std::string_view::npos)
                l = l.substr(0, hash);
            if (!split(l).empty()) return l;
        }
        return std::nullopt;
    }
};

// The numbers of an OFF data line, each token read whole; nullopt when one is not a finite
// decimal number. CGAL's scanner stops at the first token its stream cannot read ("inf",
// hexadecimal) and counts the entries after it from what it read: the line must read the
// same both ways.
std::optional<std::vector<double>> off_numbers(const std::vector<std::string_view>& tokens) {
    std::vector<double> values;
    for (const auto token : tokens) {
        const char* end = token.data() + token.size();
        double v = 0;
        const auto [ptr, ec] = std::from_chars(token.data(), end, v);
        if (ec != std::errc() || ptr != end || !std::isfinite(v)) return std::nullopt;
        values.push_back(v);
    }
    return values;
}

// The colour of a vertex or face of a "C" OFF variant: the `count` values from `first`.
// CGAL's scanner reads 1 (an index into its colour map) or 3 or 4 (RGB[A], integers 0..255
// or fractions 0..1) without checking the count or converting safely: other counts read past
// the line's numbers, and values out of range are undefined behaviour in its conversions.
// Once one vertex (face) has a colour, it reads a colour for every later vertex (face), past
// the numbers of a line that has none: `seen` carries that from line to line.
void check_off_colour(const std::vector<double>& values, std::size_t first, const std::string& name,
                      const std::string& what, bool& seen) {
    const std::size_t count = values.size() - first;
    if (count == 0) {
        if (seen)
            refuse(name, "OFF " + what +
                             " has no colour after one with a colour; give every one a colour "
                             "or none");
        return;
    }
    seen = true;
    if (count != 1 && count != 3 && count != 4)
        refuse(name, "OFF " + what + " has " + str(count) +
                         " colour values; a colour is 1 index, or 3 or 4 components");
    const auto bad = [&] {
        refuse(name, "OFF " + what +
                         " has a colour out of range (an index 0..148, components 0..255 or 0..1)");
    };
    if (count == 1) {
        const double id = values[first];
        if (!(id >= 0 && id <= 148)) bad();
        return;
    }
    bool integers = true;
    for (std::size_t k = first; k < first + 3; ++k)
        if (std::floor(values[k]) != values[k]) integers = false;
    for (std::size_t k = first; k < first + 3; ++k) {
        const double v = integers ? values[k] : values[k] * 255;
        if (!(v >= 0 && v < 256)) bad();
    }
}

std::uint32_t big_endian32(const unsigned char* p) {
    return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) |
           std::uint32_t(p[3]);
}

// What an OFF keyword ([ST][C][N][4][n]OFF) says the data hold.
struct OffKeyword {
    bool n_dimensional = false, homogeneous = false, normals = false, colours = false;
};

OffKeyword parse_off_keyword(std::string_view keyword, const std::string& name) {
    // [ST][C][N][4][n]OFF
    std::string_view prefix = keyword;
    if (prefix.size() < 3 || prefix.substr(prefix.size() - 3) != "OFF")
        refuse(name, "not an OFF file (no OFF keyword on its first line)");
    prefix.remove_suffix(3);
    OffKeyword k;
    const bool n_dimensional = !prefix.empty() && prefix.back() == 'n';
    if (n_dimensional) prefix.remove_suffix(1);
    const bool homogeneous = !prefix.empty() && prefix.back() == '4';
    if (homogeneous) prefix.remove_suffix(1);
    const bool normals = !prefix.empty() && prefix.back() == 'N';
    if (normals) prefix.remove_suffix(1);
    const bool colours = !prefix.empty() && prefix.back() == 'C';
    if (colours) prefix.remove_suffix(1);
    if (prefix == "ST")
        refuse(name, "OFF texture coordinates (" + std::string(keyword) +
                         ") are not read; remove them (OFF, COFF, NOFF, 4OFF)");
    if (!prefix.empty()) refuse(name, "unknown OFF keyword '" + std::string(keyword) + "'");
    k.n_dimensional = n_dimensional, k.homogeneous = homogeneous, k.normals = normals;
    k.colours = colours;
    return k;
}

// A binary OFF file's data from `pos`: the counts and the faces' lists walked.
MeshFileCounts check_off_binary(std::string_view bytes, const std::string& name,
                                std::uint64_t pos) {
    MeshFileCounts counts;
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    if (bytes.size() - pos < 12) refuse(name, "binary OFF header is truncated");
    const std::uint32_t nv = big_endian32(data + pos), nf = big_endian32(data + pos + 4);
    if ((nv >> 31) || (nf >> 31)) refuse(name, "binary OFF header declares a negative count");
    pos += 12;
    counts.vertices = nv;
    counts.faces = nf;
    if (nv > (bytes.size() - pos) / 12)
        refuse(name,
               "binary OFF header declares " + str(nv) + " vertices; the file cannot hold them");
    pos += std::uint64_t(nv) * 12;
    for (std::uint64_t f = 0; f < nf; ++f) {
        for (int part = 0; part < 2; ++part) {  // the corner indices, then the colour
            if (bytes.size() - pos < 4) refuse(name, "binary OFF data end inside face " + str(f));
            const std::uint32_t n = big_endian32(data + pos);
            pos += 4;
            if ((n >> 31) || n > (bytes.size() - pos) / 4)
                refuse(name, "binary OFF face " + str(f) + " declares " + str(n) +
                                 " entries; the file cannot hold them");
            if (part == 0) counts.indices += n;
            pos += std::uint64_t(n) * 4;
        }
    }
    return counts;
}

// The vertex lines of an ASCII OFF file: `coordinates` numbers or more each, and their
// colours when the keyword has C.
void check_off_vertices(OffLines& lines, const std::string& name, std::uint64_t nv,
                        std::size_t coordinates, bool colours) {
    bool vertex_colours = false;
    for (std::uint64_t v = 0; v < nv; ++v) {
        const auto line = lines.next();
        if (!line)
            refuse(name, "OFF data end at vertex " + str(v) + " of " + str(nv) + " declared");
        const auto values = off_numbers(split(*line));
        if (!values || values->size() < coordinates)
            refuse(name, "OFF vertex " + str(v) + " is not a line of " + str(coordinates) +
                             " numbers or more");
        if (colours)
            check_off_colour(*values, coordinates, name, "vertex " + str(v), vertex_colours);
    }
}

// The face lines of an ASCII OFF file: each index a vertex of the file, and their colours
// when the keyword has C; adds the faces' indices to `counts`.
void check_off_faces(std::string_view bytes, OffLines& lines, const std::string& name,
                     std::uint64_t nv, std::uint64_t nf, bool colours, MeshFileCounts& counts) {
    bool face_colours = false;
    for (std::uint64_t f = 0; f < nf; ++f) {
        const auto line = lines.next();
        if (!line) refuse(name, "OFF data end at face " + str(f) + " of " + str(nf) + " declared");
        const auto face = split(*line);
        const auto n = parse_count(face[0]);
        if (!n)
            refuse(name, "OFF face " + str(f) + " starts with '" + std::string(face[0]) +
                             "', not a vertex count");
        if (*n > (bytes.size() - lines.reader.pos + line->size() + 1) / 2)
            refuse(name, "OFF face " + str(f) + " declares " + str(*n) +
                             " vertices; the file cannot hold them");
        counts.indices += *n;
        // CGAL converts each index from a floating-point reading: a negative one is
        // undefined behaviour there, so every index is checked here.
        if (face.size() < *n + 1)
            refuse(name, "OFF face " + str(f) + " lists " + str(face.size() - 1) + " of its " +
                             str(*n) + " vertices");
        for (std::uint64_t k = 1; k <= *n; ++k) {
            const auto index = parse_count(face[k]);
            if (!index || *index >= nv)
                refuse(name, "OFF face " + str(f) + " refers to vertex '" + std::string(face[k]) +
                                 "'; the file has " + str(nv) + " vertices");
        }
        if (colours) {
            const auto values = off_numbers(face);
            if (!values) refuse(name, "OFF face " + str(f) + " is not a line of numbers");
            check_off_colour(*values, *n + 1, name, "face " + str(f), face_colours);
        }
    }
}

MeshFileCounts check_off(std::string_view bytes, const std::string& name) {
    OffLines lines{LineReader{bytes}};
    const auto header = lines.next();
    if (!header) refuse(name, "empty OFF file");
    auto tokens = split(*header);
    std::string_view keyword = tokens[0];
    // A '#' right after the keyword starts a comment here, not to CGAL's scanner, which reads
    // the counts from what follows it: the two readings would differ.
    if (const char* end = keyword.data() + keyword.size();
        end < bytes.data() + bytes.size() && *end == '#')
        refuse(name, "a comment glued to the OFF keyword ('" + std::string(keyword) +
                         "#...'); put a space or a line break before '#'");
    const OffKeyword k = parse_off_keyword(keyword, name);
    const bool binary = tokens.size() > 1 && tokens[1] == "BINARY";
    std::vector<std::string_view> numbers(tokens.begin() + 1 + (binary ? 1 : 0), tokens.end());
    if (binary) {
        if (keyword != "OFF")
            refuse(name, "binary " + std::string(keyword) +
                             " files are not read; convert to ASCII OFF or PLY");
        return check_off_binary(bytes, name, lines.reader.pos);
    }
    MeshFileCounts counts;
    auto next_number = [&]() -> std::optional<std::uint64_t> {
        if (numbers.empty()) {
            const auto line = lines.next();
            if (!line) return std::nullopt;
            numbers = split(*line);
        }
        const auto token = numbers.front();
        numbers.erase(numbers.begin());
        const auto n = parse_count(token);
        if (!n)
            refuse(name,
                   "OFF header count '" + std::string(token) + "' is not a non-negative integer");
        return n;
    };
    if (k.n_dimensional && !next_number()) refuse(name, "OFF header has no dimension");
    const auto nv = next_number();
    const auto nf = next_number();
    if (!nv || !nf) refuse(name, "OFF header has no vertex and face counts");
    // CGAL reads the edge count too, from the next line if need be: without it, the first
    // number of the data would be taken for it and the data read shifted.
    if (!next_number()) refuse(name, "OFF header has no edge count (the third number)");
    // CGAL reads the first vertex from the rest of that line.
    if (!numbers.empty()) refuse(name, "OFF header has numbers after its three counts");
    counts.vertices = *nv;
    counts.faces = *nf;
    const std::uint64_t rest = bytes.size() - lines.reader.pos + 1;
    // A vertex takes at least 6 characters ("0 0 0\n"), a face at least 2 ("0\n").
    if (*nv > rest / 6 || *nf > rest / 2 || *nv * 6 + *nf * 2 > rest)
        refuse(name, "OFF header declares " + str(*nv) + " vertices and " + str(*nf) +
                         " faces; the file (" + str(bytes.size()) + " bytes) cannot hold them");
    // Coordinates (and normals) a vertex line starts with; CGAL reads past a short line.
    const std::size_t coordinates = (k.homogeneous ? 4 : 3) * (k.normals ? 2 : 1);
    check_off_vertices(lines, name, *nv, coordinates, k.colours);
    check_off_faces(bytes, lines, name, *nv, *nf, k.colours, counts);
    return counts;
}

// ---------------------------------------------------------------------------------- OBJ

MeshFileCounts check_obj(std::string_view bytes) {
    // Text without counts: what CGAL reads grows with the bytes; count for the memory budget.
    MeshFileCounts counts;
    LineReader lines{bytes};
    while (auto line = lines.next()) {
        const auto tokens = split(*line);
        if (tokens.empty()) continue;
        if (tokens[0] == "v") ++counts.vertices;
        if (tokens[0] == "f") {
            ++counts.faces;
            counts.indices += tokens.size() - 1;
        }
    }
    return counts;
}

}  // namespace

MeshFileCounts check_mesh_bytes(std::string_view bytes, const std::string& extension,
                                const std::string& name) {
    if (extension == ".ply") return check_ply(bytes, name);
    if (extension == ".off") return check_off(bytes, name);
    return check_obj(bytes);
}

MeshFileCounts check_mesh_file(const std::string& path, const std::string& extension) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error("mesh", "cannot open '" + path + "': " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        throw Error("mesh", "'" + path + "' is not a regular file");
    }
    if (st.st_size == 0) {
        ::close(fd);
        throw Error("mesh", "'" + path + "' is empty");
    }
    void* map =
        ::mmap(nullptr, static_cast<std::size_t>(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
    ::close(fd);
    if (map == MAP_FAILED)
        throw Error("mesh", "cannot map '" + path + "': " + std::strerror(errno));
    struct Unmap {
        void* p;
        std::size_t n;
        ~Unmap() { ::munmap(p, n); }
    } unmap{map, static_cast<std::size_t>(st.st_size)};
    return check_mesh_bytes(std::string_view(static_cast<const char*>(map), unmap.n), extension,
                            path);
}

}  // namespace terrain::io
