#pragma once
// What the algorithms tell a run about the memory it holds (docs/architecture.md, "The memory
// plan"): the stage they enter, and their own arrays that wait unread for a while. A run that
// holds large arrays (pipeline::segment) answers by parking on disk, freeing or packing what
// the stage entered does not read, and bringing back what it reads, as its stage table says.
// The default answer does nothing: every array stays in memory, and the results are the same
// either way.

#include <cstdint>
#include <vector>

#include "terrain/core/progress.hpp"

namespace terrain {

// The stages of a segmentation in the order a run enters them (a run may skip some). Each is
// a row of the stage table (src/core/residency_plan.cpp), which names the arrays it reads.
enum class Stage : std::uint8_t {
    shape_index,      // the shape index (at one radius or chosen per vertex)
    height_field,     // the height field: the DEM's values
    sdf,              // the Shape Diameter Function: rays through the triangles
    reeb_events,      // the Reeb graph's events ordered by the field
    reeb_links,       // the contour tree's link components and the nodes around them
    reeb_sweeps,      // the contour tree's join and split sweeps (the Reeb graph's peak)
    reeb_arcs,        // the contour tree's arcs and its check for loops
    reeb_loops,       // contour tracking on a mesh with handles or holes
    simplify_nodes,   // the simplification's working copy of the nodes (their areas)
    simplify_arcs,    // the copy of the arcs (the simplification's peak) and the cancellations
    simplify_output,  // the simplified graph written
    grow,             // the regions grown on the simplified graph, the absorbed vertices split
    flood,            // the absorbed vertices flooded back (the simplified graph read no more)
    relabel,          // the regions' labels rewritten after the flooding
    regions,          // the region graph, the craters: everything read
    count
};
inline constexpr std::size_t kStageCount = static_cast<std::size_t>(Stage::count);

// The interface an algorithm sees. enter(stage) before the work of a stage; stash(v) for an
// array of its own that it does not read until take_back(v), which gives back the same values
// (a stashed array may be emptied meanwhile). Stages come in increasing order: entering the
// stage entered last again does nothing, entering one before it throws terrain::Error.
class Residency {
  public:
    virtual ~Residency() = default;
    virtual void enter(Stage, const ProgressFn& = {}) {}
    virtual void stash(std::vector<std::int32_t>&) {}
    virtual void stash(std::vector<float>&) {}
    virtual void take_back(std::vector<std::int32_t>&) {}
    virtual void take_back(std::vector<float>&) {}
};

// The answer that keeps everything in memory (what a call without a run's plan uses).
Residency& all_resident();

}  // namespace terrain
