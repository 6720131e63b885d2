#pragma once
// preview.png: a small map of one segmentation of a DEM (docs/outputs.md). Like every writer of
// io/: atomic, refuses an existing file unless `overwrite`, throws one terrain::Error (stage
// "write") on failure, and writes the same bytes for the same input.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "terrain/core/dem.hpp"
#include "terrain/field/field_kind.hpp"

namespace terrain::io {

// What the map's caption says beyond what the DEM tells (its body, CRS and pixel size): plain
// values from the caller.
struct PreviewCaption {
    std::string input;  // the input's file name
    // The shape index: the colour bar names the landform classes.
    field::FieldKind field = field::FieldKind::shape_index;
    std::vector<std::string> parameters;  // the thresholds: "persistence 10", "area ratio 0.5 %"
    std::size_t regions = 0;              // 0: not stated
};

// The map: the hillshade of the DEM blended with the field's colour map (blue concave, white
// flat, red convex on [0,100]), region boundaries in black, NoData transparent; scaled by an
// integer factor (nearest neighbour) to about 1024 pixels on the long side, or reduced to at
// most 4096. Around it, on white: longitude/latitude ticks on the frame, the field's colour bar
// with the landform classes' names, a scale bar in km (true at the map's centre; on a
// geographic grid along the centre's parallel), a north arrow computed at the centre, a title
// (body and input) and a caption (field, thresholds, region count, CRS, pixel size). The text
// is drawn in DejaVu Sans (map_text_warning); without the font the map is drawn without it.
// `field_pixels`: field::field_to_pixels() of the DEM; `pixels`: segment::label_pixels() of the
// DEM (row-major, 0 = no region).
void write_preview_png(const Dem& dem, const std::vector<float>& field_pixels,
                       const std::vector<std::uint32_t>& pixels, const std::string& path,
                       bool overwrite, const PreviewCaption& caption = {});

// What the frame around the map shows, as plain values computed from the DEM by
// render_preview.
struct MapTick {
    int edge = 0;         // 0 top, 1 right, 2 bottom, 3 left
    double position = 0;  // map pixels along the edge from its left or top end
    std::string label;    // "30°E", "12.5°S"
};
struct MapFrame {
    std::string title;                 // "Vesta · vesta_hamo_tile.lbl"
    std::vector<std::string> caption;  // items, joined with " · " and wrapped
    std::vector<MapTick> ticks;        // longitudes on the top and bottom edges, latitudes on
                                       // the left and right
    double metres_per_pixel = 0;       // east-west, at the map's centre; 0: no scale bar
    std::string scale_note;            // where the scale is true
    bool has_north = false;
    double north_degrees = 0;      // direction of north, clockwise from up
    bool landform_classes = true;  // the colour bar names the shape index's classes
};

// The preview in two steps: the map's pixels (8-bit RGBA, row-major) and its frame, then the
// PNG, on which the frame is drawn around the map. A program low on memory renders first,
// frees its large data, then writes (the frame and the PNG's buffers come after).
struct PreviewImage {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;
    MapFrame frame;
};
PreviewImage render_preview(const Dem& dem, const std::vector<float>& field_pixels,
                            const std::vector<std::uint32_t>& pixels,
                            const PreviewCaption& caption = {});
void write_preview_image(const PreviewImage& image, const std::string& path, bool overwrite);

// The framed map as written: its size, where the map and the colour bar lie in it, and
// whether text was drawn.
struct FramedMap {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;
    int map_x = 0, map_y = 0;                        // the map's top-left corner
    int bar_x = 0, bar_y = 0, bar_w = 0, bar_h = 0;  // colour bar: 100 at the top, 0 at the bottom
    int font_size = 0;
    bool text = false;
};
FramedMap frame_preview(const PreviewImage& image);

// The map's colour of a field value in [0,100] (values outside are clamped), before shading.
std::array<std::uint8_t, 3> preview_field_colour(double value);

// Empty when the maps' text can be drawn; otherwise what to tell the user once (no DejaVu Sans
// font: install Debian's fonts-dejavu-core or set TERRAIN_FONT; or the font could not be
// rendered). The library never prints it.
std::string map_text_warning();

}  // namespace terrain::io
