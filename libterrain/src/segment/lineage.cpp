#include "terrain/segment/lineage.hpp"

#include <algorithm>
#include <map>

#include "pixel_areas.hpp"
#include "terrain/core/error.hpp"
#include "terrain/segment/regions.hpp"

namespace terrain::segment {

std::vector<RegionLineage> region_lineage(const TriangleMesh& mesh, const Dem* dem,
                                          const std::vector<std::uint32_t>& from,
                                          std::uint32_t from_count,
                                          const std::vector<std::uint32_t>& to,
                                          std::uint32_t to_count) {
    // On a DEM, label_pixels may add regions of pixels in no triangle after the vertices'.
    std::vector<std::uint32_t> pa, pb;
    if (dem && from.size() == mesh.vertex_count() && to.size() == mesh.vertex_count()) {
        pa = label_pixels(mesh, *dem, from);
        pb = label_pixels(mesh, *dem, to);
        std::uint32_t top_a = 0, top_b = 0;
        for (const auto l : from) top_a = std::max(top_a, l);
        for (const auto l : to) top_b = std::max(top_b, l);
        for (const auto l : pa) from_count = std::max(from_count, l > top_a ? l : 0u);
        for (const auto l : pb) to_count = std::max(to_count, l > top_b ? l : 0u);
    }
    if (from.size() != mesh.vertex_count() || to.size() != mesh.vertex_count())
        throw Error("segment", "lineage: the labels do not match the mesh");
    std::map<std::pair<std::uint32_t, std::uint32_t>, double> shared;
    auto add = [&](std::uint32_t a, std::uint32_t b, double area) {
        if (a == 0 || b == 0) return;
        if (a > from_count || b > to_count) throw Error("segment", "lineage: label out of range");
        shared[{a, b}] += area;
    };
    if (dem) {
        const PixelAreas areas(*dem);
        for (int row = 0; row < dem->height; ++row)
            for (int col = 0; col < dem->width; ++col) {
                const auto i = dem->index(col, row);
                if (pa[i] != 0) add(pa[i], pb[i], areas(col, row));
            }
    } else {
        for (std::size_t v = 0; v < from.size(); ++v)
            add(from[v], to[v], mesh.vertex_areas.empty() ? 1.0 : mesh.vertex_areas[v]);
    }
    std::vector<RegionLineage> out(from_count);
    for (std::uint32_t r = 0; r < from_count; ++r) out[r].region = r + 1;
    for (const auto& [key, area] : shared) {
        auto& entry = out[key.first - 1];
        entry.area_m2 += area;
        entry.overlaps.push_back({key.second, area, 0});
    }
    for (auto& entry : out) {
        for (auto& o : entry.overlaps) {
            o.fraction = entry.area_m2 > 0 ? o.area_m2 / entry.area_m2 : 0;
            if (o.area_m2 > entry.parent_area_m2) {  // ties: the lower id, listed first
                entry.parent = o.region;
                entry.parent_area_m2 = o.area_m2;
                entry.parent_share = o.fraction;
            }
        }
    }
    return out;
}

double mean_parent_share(const std::vector<RegionLineage>& lineage) {
    double inside = 0, total = 0;
    for (const auto& r : lineage) {
        inside += r.parent_area_m2;
        total += r.area_m2;
    }
    return total > 0 ? inside / total : 1.0;
}

}  // namespace terrain::segment
