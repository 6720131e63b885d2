#include "terrain/io/write_pds3_dem.hpp"

#include <ogr_spatialref.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numbers>
#include <vector>

#include "gdal_support.hpp"
#include "terrain/core/error.hpp"
#include "terrain/core/version.hpp"
#include "terrain/io/output_file.hpp"

namespace terrain::io {
namespace {

namespace fs = std::filesystem;

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr int kMissing = -32768;  // PDS MISSING_CONSTANT of 16-bit signed DEMs (GDAL's too)
constexpr int kValidMin = -32767, kValidMax = 32767;

[[noreturn]] void fail(const std::string& message) {
    throw Error("write", message);
}

std::string upper(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    return s;
}

// Shortest text that reads back as the same double, in fixed notation, always with a decimal
// point (an ODL real rather than an integer).
std::string real(double v) {
    char buffer[400];
    const auto r = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::fixed);
    std::string s(buffer, r.ptr);
    if (s.find('.') == std::string::npos) s += ".0";
    return s;
}

// `v` rounded to `decimals` places, trailing zeros dropped (keeping one after the point).
std::string fixed(double v, int decimals) {
    char buffer[400];
    const auto r =
        std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::fixed, decimals);
    std::string s(buffer, r.ptr);
    if (s.find('.') == std::string::npos) return s + ".0";
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s += '0';
    return s == "-0.0" ? "0.0" : s;
}

// Angles in degrees and pixel offsets: 1e-10 degree is 0.5 mm on Vesta, 1e-10 pixel less.
std::string angle(double v) {
    return fixed(v, 10);
}

// The label: KEY = VALUE lines, '=' aligned, CR LF line ends as PDS3 asks.
class Label {
  public:
    void line(const std::string& text = {}) { text_ += text + "\r\n"; }
    void comment(const std::string& text) { line("/* " + text + " */"); }
    void field(const std::string& key, const std::string& value) {
        std::string k = std::string(indent_, ' ') + key;
        if (k.size() < kColumn) k.resize(kColumn, ' ');
        line(k + " = " + value);
    }
    // A quoted text value wrapped so that lines with their CR LF fit 80 bytes, continuation
    // lines indented.
    void text(const std::string& key, std::string value) {
        std::replace(value.begin(), value.end(), '"', '\'');
        const std::size_t first_width = 78 - std::max(kColumn, indent_ + key.size()) - 5;
        const std::size_t next_width = 78 - indent_ - 4 - 1;
        std::vector<std::string> lines{""};
        std::size_t start = 0;
        while (start < value.size()) {
            std::size_t end = value.find(' ', start);
            if (end == std::string::npos) end = value.size();
            const std::string word = value.substr(start, end - start);
            const std::size_t width = lines.size() == 1 ? first_width : next_width;
            if (!lines.back().empty() && lines.back().size() + 1 + word.size() > width)
                lines.emplace_back();
            if (!lines.back().empty()) lines.back() += ' ';
            lines.back() += word;
            start = end + 1;
        }
        std::string joined = "\"" + lines[0];
        for (std::size_t i = 1; i < lines.size(); ++i)
            joined += "\r\n" + std::string(indent_ + 4, ' ') + lines[i];
        field(key, joined + "\"");
    }
    void begin(const std::string& object) {
        field("OBJECT", object);
        indent_ += 2;
    }
    void end(const std::string& object) {
        indent_ -= 2;
        field("END_OBJECT", object);
    }
    const std::string& str() const { return text_; }

  private:
    static constexpr std::size_t kColumn = 28;
    std::string text_;
    std::size_t indent_ = 0;
};

// The equirectangular projection of the DEM, in metres from the projection origin (the
// equator on the central meridian), as PDS3 describes it.
struct Projection {
    double a = 0, c = 0;       // semi-major and semi-minor axes, metres
    double center_lon = 0;     // degrees
    double center_lat = 0;     // latitude of true scale, degrees
    double pixel = 0;          // metres
    double left = 0, top = 0;  // top-left corner, metres from the origin
};

Projection read_projection(const Dem& dem) {
    if (dem.crs_wkt.empty())
        fail(
            "the DEM has no CRS; a PDS3 DEM needs an equirectangular projection of its body "
            "(assign one, e.g. gdal_edit.py -a_srs '+proj=eqc +R=255000 +units=m')");
    if (!dem.has_transform)
        fail(
            "the DEM has no geotransform; a PDS3 DEM needs map coordinates (assign them, e.g. "
            "gdal_edit.py -a_ullr)");
    OGRSpatialReference srs;
    if (srs.SetFromUserInput(dem.crs_wkt.c_str()) != OGRERR_NONE)
        fail("cannot read the DEM's CRS; give it as WKT");
    const char* method = srs.IsProjected() ? srs.GetAttrValue("PROJECTION") : nullptr;
    if (!method || std::string(method) != SRS_PT_EQUIRECTANGULAR)
        fail(std::string("the DEM's CRS is ") +
             (srs.IsProjected() ? std::string("a ") + (method ? method : "?") + " projection"
                                : std::string("not projected")) +
             "; write_pds3_dem supports EQUIRECTANGULAR only: reproject with gdalwarp -t_srs "
             "'+proj=eqc +R=<radius> +lon_0=<lon>'");
    const auto& t = dem.transform;
    if (t[2] != 0 || t[4] != 0 || !(t[1] > 0) || !(t[5] < 0) || std::abs(t[1] + t[5]) > 1e-9 * t[1])
        fail("the DEM's pixels are not square and north-up (geotransform " + real(t[1]) + ", " +
             real(t[2]) + ", " + real(t[4]) + ", " + real(t[5]) +
             "); PDS3 has one MAP_SCALE: resample with gdalwarp -tr <size> <size>");
    Projection p;
    OGRErr err = OGRERR_NONE;
    p.a = srs.GetSemiMajor(&err);
    p.c = srs.GetSemiMinor(&err);
    const double unit = srs.GetLinearUnits();
    p.center_lon = srs.GetNormProjParm(SRS_PP_CENTRAL_MERIDIAN, 0.0);
    p.center_lat = srs.GetNormProjParm(SRS_PP_STANDARD_PARALLEL_1, 0.0);
    const double lat0 = srs.GetNormProjParm(SRS_PP_LATITUDE_OF_ORIGIN, 0.0);
    const double false_easting = srs.GetNormProjParm(SRS_PP_FALSE_EASTING, 0.0);
    const double false_northing = srs.GetNormProjParm(SRS_PP_FALSE_NORTHING, 0.0);
    if (!(p.a > 0) || !(unit > 0) || std::abs(p.center_lat) >= 89.9)
        fail(
            "the DEM's equirectangular CRS has no usable body radius or a standard parallel at "
            "a pole");
    p.pixel = t[1] * unit;
    // PROJ's eqc: x = a cos(lat_ts) (lon - lon_0) + x_0, y = a (lat - lat_0) + y_0.
    p.left = t[0] * unit - false_easting;
    p.top = t[3] * unit - false_northing + p.a * lat0 * kDegree;
    return p;
}

std::string target_name(const Dem& dem, const Pds3DemOptions& options) {
    std::string name = options.target_name.empty() ? upper(dem.body.name) : options.target_name;
    if (name.empty() || name == "UNKNOWN" || name == "NONE")
        fail(
            "the DEM's body is not recognised from its CRS; give the target name "
            "(Pds3DemOptions::target_name, e.g. \"VESTA\")");
    for (char ch : name)
        if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) return "\"" + name + "\"";
    return name;
}

std::string normalise_lon(double lon) {
    lon -= 360.0 * std::floor(lon / 360.0);
    return angle(lon);
}

void write_file(const fs::path& path, const void* data, std::size_t size) {
    errno = 0;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f)
        fail("cannot create '" + path.string() + "': " + std::strerror(errno) +
             "; choose a writable directory");
    const bool written = std::fwrite(data, 1, size, f) == size;
    const int write_errno = errno;
    const bool closed = std::fclose(f) == 0;
    if (!written || !closed)
        fail("cannot write '" + path.string() + "': " +
             std::strerror(write_errno ? write_errno : errno) + "; check the free disk space");
}

// Removes the temporary files unless released.
}  // namespace

std::string pds3_image_path(const std::string& label_path) {
    fs::path path(label_path);
    const std::string extension = path.extension().string();
    const bool lower = !extension.empty() && extension != upper(extension);
    path.replace_extension(lower ? ".img" : ".IMG");
    return path.string();
}

namespace {

// The DEM's values as 16-bit DNs, MSB first, and the least and greatest DN written.
struct EncodedDem {
    std::vector<unsigned char> bytes;
    int dn_min = 0, dn_max = 0;
};

EncodedDem encode_dns(const Dem& dem, double offset, double scaling_factor) {
    EncodedDem out;
    std::vector<unsigned char>& bytes = out.bytes;
    int& dn_min = out.dn_min;
    int& dn_max = out.dn_max;
    bytes.resize(dem.values.size() * 2);
    dn_min = std::numeric_limits<int>::max(), dn_max = std::numeric_limits<int>::min();
    for (int row = 0; row < dem.height; ++row)
        for (int col = 0; col < dem.width; ++col) {
            const std::size_t i = dem.index(col, row);
            const double v = dem.values[i];
            int dn = kMissing;
            if (!std::isnan(v)) {
                const double q = std::round((v - offset) / scaling_factor);
                if (!std::isfinite(v) || q < kValidMin || q > kValidMax)
                    fail("the value " + real(v) + " m at column " + std::to_string(col) + ", row " +
                         std::to_string(row) + " does not fit a 16-bit DN with " +
                         "SCALING_FACTOR " + real(scaling_factor) + " and OFFSET " + real(offset) +
                         "; choose a larger scaling factor or an offset nearer "
                         "the values");
                dn = static_cast<int>(q);
                dn_min = std::min(dn_min, dn);
                dn_max = std::max(dn_max, dn);
            }
            const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(dn));
            bytes[2 * i] = static_cast<unsigned char>(u >> 8);  // MSB first
            bytes[2 * i + 1] = static_cast<unsigned char>(u & 0xff);
        }

    return out;
}

// The DEM's extent on its body, in degrees.
struct MapExtent {
    double lat_min = 0, lat_max = 0, lon_west = 0, lon_east = 0;
};

MapExtent map_extent(const Dem& dem, const Projection& p) {
    // Map extent. Sample s (1-based) has its centre at x = (s - SAMPLE_PROJECTION_OFFSET - 1) *
    // MAP_SCALE and line l at y = (LINE_PROJECTION_OFFSET - l + 1) * MAP_SCALE, as GDAL's PDS
    // driver reads them.
    const double cos_ts = std::cos(p.center_lat * kDegree);
    const double lat_max = p.top / p.a / kDegree;
    const double lat_min = (p.top - dem.height * p.pixel) / p.a / kDegree;
    const double lon_west = p.center_lon + p.left / (p.a * cos_ts) / kDegree;
    const double lon_east =
        p.center_lon + (p.left + dem.width * p.pixel) / (p.a * cos_ts) / kDegree;
    if (lat_max > 90 + 1e-9 || lat_min < -90 - 1e-9 || lon_east - lon_west > 360 + 1e-9)
        fail("the DEM's extent (latitude " + real(lat_min) + " to " + real(lat_max) +
             ") does not lie on its body; check the geotransform and CRS");

    return {lat_min, lat_max, lon_west, lon_east};
}

// The label's IMAGE object: the DNs and how they give metres.
void label_image(Label& l, const Dem& dem, const Pds3DemOptions& options, bool radius,
                 double offset, const EncodedDem& dns) {
    const std::string quantity = radius ? "RADIUS" : "HEIGHT";
    const int dn_min = dns.dn_min, dn_max = dns.dn_max;
    l.begin("IMAGE");
    l.field("NAME", quantity);
    l.text("DESCRIPTION", quantity + " in metres = DN * SCALING_FACTOR + OFFSET" +
                              (radius ? std::string(", from the centre of mass of the body")
                                      : std::string(", above the reference surface")) +
                              "; DN = MISSING_CONSTANT where there is no data.");
    l.field("LINES", std::to_string(dem.height));
    l.field("LINE_SAMPLES", std::to_string(dem.width));
    l.field("BANDS", "1");
    l.field("SAMPLE_TYPE", "MSB_INTEGER");
    l.field("SAMPLE_BITS", "16");
    l.field("UNIT", "METER");
    l.field("SCALING_FACTOR", real(options.scaling_factor));
    l.field("OFFSET", real(offset));
    l.field("MISSING_CONSTANT", std::to_string(kMissing));
    l.field("VALID_MINIMUM", std::to_string(kValidMin));
    l.field("VALID_MAXIMUM", std::to_string(kValidMax));
    if (dn_min <= dn_max) {
        l.field("MINIMUM", std::to_string(dn_min));
        l.field("MAXIMUM", std::to_string(dn_max));
    }
    l.end("IMAGE");
}

// The label's IMAGE_MAP_PROJECTION object: the equirectangular projection of the grid.
void label_projection(Label& l, const Dem& dem, const Projection& p, const MapExtent& e) {
    const double lat_min = e.lat_min, lat_max = e.lat_max, lon_west = e.lon_west,
                 lon_east = e.lon_east;
    l.begin("IMAGE_MAP_PROJECTION");
    l.field("MAP_PROJECTION_TYPE", "\"EQUIRECTANGULAR\"");
    l.field("PROJECTION_LATITUDE_TYPE", "PLANETOCENTRIC");
    l.field("A_AXIS_RADIUS", real(p.a / 1000.0) + " <KM>");
    l.field("B_AXIS_RADIUS", real(p.a / 1000.0) + " <KM>");
    l.field("C_AXIS_RADIUS", real(p.c / 1000.0) + " <KM>");
    l.field("FIRST_STANDARD_PARALLEL", "\"N/A\"");
    l.field("SECOND_STANDARD_PARALLEL", "\"N/A\"");
    l.field("POSITIVE_LONGITUDE_DIRECTION", "\"EAST\"");
    l.field("CENTER_LATITUDE", angle(p.center_lat) + " <DEG>");
    l.field("CENTER_LONGITUDE", angle(p.center_lon) + " <DEG>");
    l.field("REFERENCE_LATITUDE", "\"N/A\"");
    l.field("REFERENCE_LONGITUDE", "\"N/A\"");
    l.field("LINE_FIRST_PIXEL", "1");
    l.field("LINE_LAST_PIXEL", std::to_string(dem.height));
    l.field("SAMPLE_FIRST_PIXEL", "1");
    l.field("SAMPLE_LAST_PIXEL", std::to_string(dem.width));
    l.field("MAP_PROJECTION_ROTATION", "0.0 <DEG>");
    l.field("MAP_RESOLUTION", angle(p.a * kDegree / p.pixel) + " <PIX/DEG>");
    l.field("MAP_SCALE", real(p.pixel / 1000.0) + " <KM/PIXEL>");
    l.field("MAXIMUM_LATITUDE", angle(lat_max) + " <DEG>");
    l.field("MINIMUM_LATITUDE", angle(lat_min) + " <DEG>");
    l.field("EASTERNMOST_LONGITUDE", normalise_lon(lon_east) + " <DEG>");
    l.field("WESTERNMOST_LONGITUDE", normalise_lon(lon_west) + " <DEG>");
    l.field("LINE_PROJECTION_OFFSET", angle(p.top / p.pixel - 0.5) + " <PIXEL>");
    l.field("SAMPLE_PROJECTION_OFFSET", angle(-p.left / p.pixel - 0.5) + " <PIXEL>");
    l.field("COORDINATE_SYSTEM_TYPE", "\"BODY-FIXED ROTATING\"");
    l.field("COORDINATE_SYSTEM_NAME", "PLANETOCENTRIC");
    l.end("IMAGE_MAP_PROJECTION");
}

}  // namespace

void write_pds3_dem(const Dem& dem, const std::string& label_path, const Pds3DemOptions& options) {
    ensure_gdal_registered();
    const GdalErrorCapture quiet;
    const fs::path label(label_path);
    if (upper(label.extension().string()) != ".LBL")
        fail("'" + label_path +
             "' does not end in .lbl; name the PDS3 label *.lbl (the image "
             "is written beside it as *.img)");
    const fs::path image(pds3_image_path(label_path));
    if (dem.width < 1 || dem.height < 1 ||
        dem.values.size() != static_cast<std::size_t>(dem.width) * dem.height)
        fail("the DEM is empty or its values do not match its size");

    // Everything is checked and encoded before any file is touched.
    const Projection p = read_projection(dem);
    const std::string target = target_name(dem, options);
    if (!std::isfinite(options.scaling_factor) || !(options.scaling_factor > 0))
        fail("the scaling factor must be a positive number of metres per DN");
    const bool radius = dem.elevation == ElevationKind::radius;
    if (radius && !options.offset && !(dem.body.semi_major_axis > 0))
        fail("the DEM holds radii but its body has no radius; give the offset");
    const double offset = options.offset.value_or(radius ? dem.body.semi_major_axis : 0.0);
    if (!std::isfinite(offset)) fail("the offset must be a finite number of metres");

    const EncodedDem dns = encode_dns(dem, offset, options.scaling_factor);
    const MapExtent extent = map_extent(dem, p);
    const std::string stem = label.stem().string();
    const std::string product_id = options.product_id.empty() ? stem : options.product_id;
    const std::string quantity = radius ? "RADIUS" : "HEIGHT";
    Label l;
    l.field("PDS_VERSION_ID", "PDS3");
    l.line();
    l.comment("FILE CHARACTERISTICS");
    l.field("RECORD_TYPE", "FIXED_LENGTH");
    l.field("RECORD_BYTES", std::to_string(2 * dem.width));
    l.field("FILE_RECORDS", std::to_string(dem.height));
    l.line();
    l.comment("POINTER TO THE DATA OBJECT");
    l.field("^IMAGE", "\"" + image.filename().string() + "\"");
    l.line();
    l.comment("IDENTIFICATION");
    l.field("PRODUCT_ID", "\"" + product_id + "\"");
    l.field("PRODUCT_TYPE", "DTM");
    l.field("TARGET_NAME", target);
    l.field("SOFTWARE_NAME", "\"terrain\"");
    l.field("SOFTWARE_VERSION_ID", "\"" + version() + "\"");
    l.text("DESCRIPTION", options.description.empty()
                              ? "Digital terrain model of " + upper(dem.body.name) + ": " +
                                    (radius ? "planetary radius" : "height") + " in metres, " +
                                    quantity +
                                    " = DN * SCALING_FACTOR + OFFSET, in an equirectangular map "
                                    "projection."
                              : options.description);
    l.line();
    label_image(l, dem, options, radius, offset, dns);
    l.line();
    label_projection(l, dem, p, extent);
    l.line();
    l.line("END");

    // Both files under temporary names (existing ones only with overwrite), then the image
    // first, so that a label never points at a missing or older image.
    AtomicOutput image_out(image.string(), options.overwrite);
    AtomicOutput label_out(label.string(), options.overwrite);
    write_file(image_out.temp_path(), dns.bytes.data(), dns.bytes.size());
    write_file(label_out.temp_path(), l.str().data(), l.str().size());
    image_out.commit();
    label_out.commit();
    std::error_code ec;
    // A GDAL side-car of an earlier product would override what was just written.
    if (options.overwrite) fs::remove(label.string() + ".aux.xml", ec);
}

}  // namespace terrain::io
