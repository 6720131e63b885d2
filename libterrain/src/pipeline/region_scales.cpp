// The regions' scales in the region table and run.json (docs/segment.md, "Landforms at their
// own scale").
#include "region_scales.hpp"

#include <algorithm>

#include "terrain/segment/area_range.hpp"

namespace terrain::pipeline::internal {

void set_region_scales(SegmentResult& result) {
    auto& scale = result.field_scale;
    const auto& labels = result.segmentation.labels;
    auto& regions = result.regions.regions;
    if (scale.empty() || scale.size() != labels.size()) return;
    const std::size_t rungs = result.field_radii.size();
    std::vector<std::uint32_t> counts(regions.size() * rungs, 0);
    for (std::size_t v = 0; v < labels.size(); ++v)
        if (labels[v] >= 1 && labels[v] <= regions.size() && scale[v] < rungs)
            ++counts[(labels[v] - 1) * rungs + scale[v]];
    for (std::size_t r = 0; r < regions.size(); ++r) {
        std::size_t best = 0;
        for (std::size_t k = 1; k < rungs; ++k)
            if (counts[r * rungs + k] > counts[r * rungs + best]) best = k;
        regions[r].field_scale_m = counts[r * rungs + best] > 0 ? result.field_radii[best] : 0;
    }
    result.regions.has_field_scale = true;
    std::vector<std::uint8_t>().swap(scale);
}

// (The regions of pixels in no triangle come after those of `to`: they have no seed.)
void set_area_ranges(SegmentResult& result, const std::vector<double>& to) {
    for (std::size_t r = 0; r < result.regions.regions.size(); ++r) {
        auto& region = result.regions.regions[r];
        const bool seeded = r < to.size();
        region.min_area_from_m2 = seeded ? result.min_area_m2 : 0;
        region.min_area_to_m2 = seeded ? to[r] : 0;
    }
    result.regions.has_area_range = true;
}

// (The regions standing at a threshold: the map's region count at that coarser --min-area,
// read from this one run.)
void write_area_range(JsonWriter& j, const SegmentResult& result) {
    const double step = segment::AreaRangeOptions{}.step;
    j.key("area_range").begin_object().field("step", step);
    std::vector<double> thresholds;
    double top = 0;
    for (const auto& r : result.regions.regions) top = std::max(top, r.min_area_to_m2);
    for (double t = result.min_area_m2; t > 0 && t < top; t *= step) thresholds.push_back(t);
    j.key("thresholds_m2").begin_array();
    for (const double t : thresholds) j.value(t);
    j.end_array().key("regions").begin_array();
    for (const double t : thresholds) {
        std::int64_t standing = 0;
        for (const auto& r : result.regions.regions) standing += r.min_area_to_m2 > t;
        j.value(standing);
    }
    j.end_array().end_object();
}

}  // namespace terrain::pipeline::internal
