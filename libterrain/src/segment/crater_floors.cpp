// The possible floors of craters in a region graph (crater_floors.hpp, docs/craters.md).
#include "crater_floors.hpp"

#include <algorithm>
#include <utility>

namespace terrain::segment::internal {
namespace {

// Two adjacent concave regions are also tried as one floor when the smaller has at least
// this share of the larger's area.
constexpr double kPairAreaRatio = 0.25;
// The most regions a floor of several pieces is grown to.
constexpr std::size_t kGroupMembers = 12;

// How round a floor of this area and outer boundary is: area / perimeter^2 (1 / (4 pi) for a
// disk), 0 without a boundary.
double roundness(double area, double length) {
    return length > 0 ? area / (length * length) : 0.0;
}

// Groups of three or more adjacent concave regions as one floor: a large crater's floor that
// the segmentation cut into several pieces (its small craters, terraces and peaks each an
// extremum of the field). From each concave region, as the largest of its group, the group
// grows by the neighbouring concave region no larger than it that leaves the union roundest
// (area / perimeter^2, the shared boundaries taken out), up to kGroupMembers regions; the
// roundest union met on the way is the floor when it has three regions or more and is rounder
// than the region it grew from. (Pieces round a centre make a round union only once they are
// all in: a quarter of a disk is rounder than a half, the whole disk rounder than both.)
template <class Concave, class Add>
void add_groups(const RegionGraph& graph, const std::vector<double>& perimeter,
                const std::vector<double>& rim, const Concave& concave, const Add& add) {
    const auto& regions = graph.regions;
    std::vector<std::vector<std::pair<std::uint32_t, double>>> next(regions.size() + 1);
    for (const auto& e : graph.edges)
        if (concave(e.a) && concave(e.b)) {
            next[e.a].push_back({e.b, e.boundary_length_m});
            next[e.b].push_back({e.a, e.boundary_length_m});
        }
    const auto area = [&](std::uint32_t id) { return regions[id - 1].area_m2; };
    std::vector<double> shared(regions.size() + 1, 0);  // with the group, by region
    std::vector<std::uint32_t> touched;
    for (const auto& seed : regions) {
        if (!concave(seed.id) || next[seed.id].empty()) continue;
        // A region no larger than the seed (equal areas: a higher id) may join it.
        const auto may_join = [&](std::uint32_t id) {
            return area(id) < seed.area_m2 || (area(id) == seed.area_m2 && id > seed.id);
        };
        std::vector<std::uint32_t> members{seed.id};
        double a = seed.area_m2, length = perimeter[seed.id], rim_length = rim[seed.id];
        double best = roundness(a, length);
        std::size_t best_size = 1;
        double best_area = a, best_length = length, best_rim = rim_length;
        const auto meet = [&](std::uint32_t id) {
            for (const auto& [other, l] : next[id]) {
                if (shared[other] == 0) touched.push_back(other);
                shared[other] += l;
            }
        };
        meet(seed.id);
        while (members.size() < kGroupMembers) {
            std::uint32_t pick = 0;
            double pick_round = -1;
            for (const auto id : touched) {
                if (!may_join(id) || std::find(members.begin(), members.end(), id) != members.end())
                    continue;
                const double r = roundness(a + area(id), length + perimeter[id] - 2 * shared[id]);
                if (r > pick_round || (r == pick_round && id < pick)) {
                    pick = id;
                    pick_round = r;
                }
            }
            if (pick == 0) break;
            members.push_back(pick);
            a += area(pick);
            length += perimeter[pick] - 2 * shared[pick];
            rim_length += rim[pick];
            meet(pick);
            if (pick_round > best) {
                best = pick_round;
                best_size = members.size();
                best_area = a;
                best_length = length;
                best_rim = rim_length;
            }
        }
        for (const auto id : touched) shared[id] = 0;
        touched.clear();
        if (best_size < 3) continue;
        members.resize(best_size);
        add(std::move(members), best_area, best_length, best_rim);
    }
}

}  // namespace

std::vector<FloorCandidate> floor_candidates(const RegionGraph& graph,
                                             const CraterOptions& options) {
    const auto& regions = graph.regions;
    const std::size_t m = regions.size();
    const auto convex = [&](std::uint32_t id) { return convex_region(graph, id, options); };
    const auto concave = [&](std::uint32_t id) {
        return regions[id - 1].field_mean < options.concave_below &&
               regions[id - 1].vertex_count >= 3;
    };
    // Perimeters and the length shared with convex neighbours.
    std::vector<double> perimeter(m + 1, 0), rim(m + 1, 0);
    for (const auto& e : graph.edges) {
        perimeter[e.a] += e.boundary_length_m;
        perimeter[e.b] += e.boundary_length_m;
        if (convex(e.b)) rim[e.a] += e.boundary_length_m;
        if (convex(e.a)) rim[e.b] += e.boundary_length_m;
    }
    std::vector<FloorCandidate> out;
    const auto add = [&](std::vector<std::uint32_t> members, double area, double length,
                         double rim_length) {
        if (!(length > 0) || rim_length < 0.5 * options.min_rim_fraction * length) return;
        out.push_back({std::move(members), area, length});
    };
    for (const auto& r : regions)
        if (concave(r.id)) add({r.id}, r.area_m2, perimeter[r.id], rim[r.id]);
    for (const auto& e : graph.edges) {
        if (!concave(e.a) || !concave(e.b)) continue;
        const double aa = regions[e.a - 1].area_m2, ab = regions[e.b - 1].area_m2;
        if (std::min(aa, ab) < kPairAreaRatio * std::max(aa, ab)) continue;
        // Two floors side by side are less round together than either alone; a floor cut in
        // two is rounder whole than at least one of its pieces.
        const double length = perimeter[e.a] + perimeter[e.b] - 2 * e.boundary_length_m;
        if (roundness(aa + ab, length) <=
            std::min(roundness(aa, perimeter[e.a]), roundness(ab, perimeter[e.b])))
            continue;
        // The larger region first (the crater's floor_region).
        const bool a_first = aa > ab || (aa == ab && e.a < e.b);
        add({a_first ? e.a : e.b, a_first ? e.b : e.a}, aa + ab, length, rim[e.a] + rim[e.b]);
    }
    add_groups(graph, perimeter, rim, concave, add);
    return out;
}

}  // namespace terrain::segment::internal
