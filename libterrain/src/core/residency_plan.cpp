// The memory plan of a segmentation run and its stage table (residency_plan.hpp).

#include "terrain/internal/core/residency_plan.hpp"

#include <algorithm>

#include "terrain/core/error.hpp"

namespace terrain {

Residency& all_resident() {
    static Residency none;
    return none;
}

namespace detail {

namespace {

constexpr std::uint32_t bit(Held a) {
    return std::uint32_t{1} << static_cast<unsigned>(a);
}
constexpr std::uint32_t kMesh = bit(Held::positions) | bit(Held::vertex_areas) |
                                bit(Held::pixel_vertex) | bit(Held::vertex_pixel) |
                                bit(Held::neighbor_directions);
constexpr std::uint32_t kGrid =
    bit(Held::pixel_vertex) | bit(Held::vertex_pixel) | bit(Held::neighbor_directions);
constexpr std::uint32_t kField = bit(Held::field) | bit(Held::field_scale);

// The stage table: a row a stage, the arrays it reads or writes. The triangles are read at
// random only by the SDF's rays and by contour tracking; every other stage that needs them
// walks them from the grid in order (mesh/grid_triangles.hpp). The Reeb graph and the
// simplification read neither the DEM nor the positions (placed again for the flooding).
constexpr std::array<std::uint32_t, kStageCount> kReads{
    /* shape_index     */ kMesh | kField,
    /* height_field    */ bit(Held::dem) | kMesh | kField,
    /* sdf             */ bit(Held::triangles) | kMesh | kField,
    /* reeb_events     */ kGrid | bit(Held::field),
    /* reeb_links      */ kGrid,
    /* reeb_sweeps     */ bit(Held::neighbor_directions),
    /* reeb_arcs       */ kGrid,
    /* reeb_loops      */ bit(Held::triangles) | kGrid | bit(Held::field),
    /* simplify_nodes  */ bit(Held::vertex_areas),
    /* simplify_arcs   */ 0,
    /* simplify_output */ 0,
    /* grow            */ bit(Held::vertex_areas) | kGrid | bit(Held::labels),
    /* flood           */ kMesh | bit(Held::field),
    /* relabel         */ kMesh | bit(Held::field) | bit(Held::labels),
    /* regions         */ bit(Held::dem) | kMesh | kField | bit(Held::labels),
};

constexpr std::array<const char*, kHeldCount> kNames{
    "the DEM",        "the triangles",  "the positions", "the vertex areas",   "the pixel map",
    "the vertex map", "the directions", "the field",     "the field's scales", "the labels",
};

constexpr std::array<const char*, kStageCount> kStageNames{
    "shape index",     "height field", "SDF",        "Reeb events",    "Reeb links",
    "Reeb sweeps",     "Reeb arcs",    "Reeb loops", "simplify nodes", "simplify arcs",
    "simplify output", "grow",         "flood",      "relabel",        "regions",
};

}  // namespace

bool stage_reads(Stage stage, Held array) {
    return (kReads[static_cast<std::size_t>(stage)] & bit(array)) != 0;
}

const char* held_name(Held array) {
    return kNames[static_cast<std::size_t>(array)];
}

ResidencyPlan::ResidencyPlan(std::string dir, std::size_t min_bytes)
    : store_(std::move(dir), min_bytes) {}

void ResidencyPlan::bind(Held array, Holder holder) {
    auto& b = bound_[index(array)];
    b.resident = holder.resident;
    b.holder = std::move(holder);
    b.bound = true;
}

void ResidencyPlan::on_entry(Stage stage, std::function<void(const ProgressFn&)> work) {
    on_entry_[static_cast<std::size_t>(stage)] = std::move(work);
}

void ResidencyPlan::decide() {
    std::size_t bytes = 0;
    for (const auto& b : bound_)
        if (b.bound && b.holder.bytes) bytes += b.holder.bytes();
    store_.decide(bytes);
}

void ResidencyPlan::note_parked() {
    if (stage_ == Stage::count) return;
    auto& most = parked_in_[static_cast<std::size_t>(stage_)];
    most = std::max(most, store_.parked_bytes());
}

void ResidencyPlan::hold(Held array, const ProgressFn& progress) {
    auto& b = bound_[index(array)];
    if (b.holder.hold(store_, progress)) b.resident = false;
}

void ResidencyPlan::back(Held array, const ProgressFn& progress) {
    auto& b = bound_[index(array)];
    b.holder.back(store_, progress);
    b.resident = true;
}

void ResidencyPlan::enter(Stage stage, const ProgressFn& progress) {
    if (stage == stage_) return;  // (the run entered it before the algorithm did)
    if (stage_ != Stage::count && stage < stage_)
        throw Error("memory", std::string("internal: the stage '") +
                                  kStageNames[static_cast<std::size_t>(stage)] +
                                  "' entered after '" +
                                  kStageNames[static_cast<std::size_t>(stage_)] + "'");
    if (!store_.decided()) decide();
    stage_ = stage;
    const auto reads = [&](Held a) { return stage_reads(stage, a); };
    auto& work = on_entry_[static_cast<std::size_t>(stage)];
    const double moves_from = work ? 0.6 : 0;
    if (work) work(scaled_progress(progress, 0, moves_from));
    // What moves: the arrays the stage does not read out (first: the least memory held),
    // then those it reads back, each after what it needs to come back.
    std::array<bool, kHeldCount> needed{};
    for (std::size_t i = 0; i < kHeldCount; ++i) {
        const auto& b = bound_[i];
        if (!b.bound || !reads(Held(i))) continue;
        needed[i] = true;
        if (!b.resident && b.holder.needs != Held::count) needed[index(b.holder.needs)] = true;
    }
    std::size_t moves = 0;
    for (std::size_t i = 0; i < kHeldCount; ++i)
        if (bound_[i].bound) moves += bound_[i].resident != needed[i];
    for (std::size_t i = 0; i < kHeldCount; ++i)
        if (needed[i] && !reads(Held(i))) ++moves;  // back, then out again
    std::size_t done = 0;
    const auto slice = [&] {
        const double span = (1 - moves_from) / double(std::max<std::size_t>(moves, 1));
        const double from = moves_from + span * double(done++);
        return scaled_progress(progress, from, from + span);
    };
    for (std::size_t i = 0; i < kHeldCount; ++i)
        if (bound_[i].bound && bound_[i].resident && !needed[i]) hold(Held(i), slice());
    for (std::size_t i = 0; i < kHeldCount; ++i)
        if (needed[i] && !bound_[i].resident) back(Held(i), slice());
    for (std::size_t i = 0; i < kHeldCount; ++i)
        if (needed[i] && !reads(Held(i))) hold(Held(i), slice());
    note_parked();
    report_progress(progress, 1, "park");
}

}  // namespace detail
}  // namespace terrain
