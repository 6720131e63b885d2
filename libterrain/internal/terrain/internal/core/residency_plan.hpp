#pragma once
// The memory plan of a segmentation run (docs/architecture.md, "The memory plan"): the run's
// large arrays, bound by name, and the stage table that says which stages read each of them.
// On entering a stage the plan takes out of memory every array the stage does not read
// (parked on disk, freed to be made again, packed) and puts back every array it reads; an
// algorithm's own arrays that wait unread are parked while stashed. Whether to park at all is
// decided on entering the first stage, from what the bound arrays will hold. Not installed.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <type_traits>
#include <vector>

#include "terrain/core/residency.hpp"
#include "terrain/internal/core/parked_arrays.hpp"

namespace terrain::detail {

// The run's arrays, in the order they are put back on entering a stage.
enum class Held : std::uint8_t {
    dem,           // the DEM's values (doubles where read; packed, parked elsewhere)
    triangles,     // the mesh's triangles (freed; made again from the grid)
    positions,     // the mesh's positions (freed; placed again from the DEM)
    vertex_areas,  // the mesh's vertices' areas
    pixel_vertex,  // the mesh's pixel maps
    vertex_pixel,
    neighbor_directions,  // the mesh's adjacency on the grid
    field,                // the field, a float a vertex
    field_scale,          // the field's chosen scale, a byte a vertex
    labels,               // the regions' labels as grown
    count
};
inline constexpr std::size_t kHeldCount = static_cast<std::size_t>(Held::count);

// The stage table: whether `stage` reads (or writes) `array`. An array a stage does not read is
// taken out of memory while it runs, when it is bound and its holder can.
bool stage_reads(Stage stage, Held array);
const char* held_name(Held array);

class ResidencyPlan final : public Residency {
  public:
    // How a bound array leaves memory and comes back. `hold` takes it out (it may do nothing:
    // the array then stays), `back` puts back the same values. `bytes`: what parking it would
    // write, for the decision to park. `needs`: an array that must be in memory while `back`
    // runs (the DEM, for the positions placed again from it).
    struct Holder {
        std::function<bool(ParkedArrays&, const ProgressFn&)> hold;  // false: stays
        std::function<void(ParkedArrays&, const ProgressFn&)> back;
        std::function<std::size_t()> bytes;
        Held needs = Held::count;
        bool resident = true;  // in memory when bound
    };

    // `dir`, `min_bytes`: where parked arrays go and the least they must hold in all for
    // parking to be worth the file (ParkedArrays).
    ResidencyPlan(std::string dir, std::size_t min_bytes);

    void bind(Held array, Holder holder);
    // A vector parked on disk while not read; `bytes`: what it will hold when first parked
    // (a field not computed yet is empty when bound).
    template <class T>
    void bind(Held array, std::vector<T>& v, std::size_t bytes) {
        static_assert(std::is_trivially_copyable_v<T>);
        Holder h;
        h.hold = [&v](ParkedArrays& store, const ProgressFn& p) { return store.park(v, p, 0, 1); };
        h.back = [&v](ParkedArrays& store, const ProgressFn& p) { store.restore(v, p, 0, 1); };
        h.bytes = [bytes] { return bytes; };
        bind(array, std::move(h));
    }
    // Work of the run's own to do on entering `stage`, before the arrays move (freeing what the
    // stages before it leave, say).
    void on_entry(Stage stage, std::function<void(const ProgressFn&)> work);

    void enter(Stage stage, const ProgressFn& progress = {}) override;
    void stash(std::vector<std::int32_t>& v) override { park_stashed(v); }
    void stash(std::vector<float>& v) override { park_stashed(v); }
    void take_back(std::vector<std::int32_t>& v) override { store_.restore(v, {}, 0, 0); }
    void take_back(std::vector<float>& v) override { store_.restore(v, {}, 0, 0); }

    bool resident(Held array) const { return bound_[index(array)].resident; }
    // The stage entered last (Stage::count before the first).
    Stage stage() const { return stage_; }
    // The most bytes parked while `stage` ran: once its arrays moved, and with what the
    // algorithms stashed in it.
    std::size_t parked_in(Stage stage) const { return parked_in_[static_cast<std::size_t>(stage)]; }
    const ParkedArrays& store() const { return store_; }

  private:
    static std::size_t index(Held a) { return static_cast<std::size_t>(a); }
    template <class T>
    void park_stashed(std::vector<T>& v) {
        store_.park(v, {}, 0, 0);
        note_parked();
    }
    void decide();
    void hold(Held array, const ProgressFn& progress);
    void back(Held array, const ProgressFn& progress);
    void note_parked();

    struct Bound {
        Holder holder;
        bool bound = false, resident = true;
    };
    ParkedArrays store_;
    std::array<Bound, kHeldCount> bound_{};
    std::array<std::function<void(const ProgressFn&)>, kStageCount> on_entry_{};
    std::array<std::size_t, kStageCount> parked_in_{};
    Stage stage_ = Stage::count;
};

}  // namespace terrain::detail
