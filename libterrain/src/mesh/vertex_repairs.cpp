// Repairs of a mesh read or made: pinched vertices split into a copy per fan of triangles,
// vertices in no triangle removed (docs/mesh.md).
#include "terrain/mesh/triangle_mesh.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "mesh_lists.hpp"
#include "terrain/internal/core/disjoint_sets.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/ranked_bits.hpp"
#include "terrain/internal/core/release.hpp"

namespace terrain {

using detail::check_adjacency_size;
using detail::gather_by_slices;

namespace {

// The triangles incident to the vertices looked at (every vertex, or those may_pinch
// names), by their rank among them: those of rank r are incident[offsets[r] ..
// offsets[r + 1]), in triangle order.
struct IncidentTriangles {
    // With may_pinch, the vertices looked at are a bit each, a word of 64 of them with the
    // count of those before it: a vertex's rank is that count and the bits below its own.
    // (An array of ranks was 4 bytes a pixel at the mesh's peak, for a few vertices.)
    bool every_vertex = true;
    detail::RankedBits looked;
    std::size_t looked_at = 0;
    std::vector<std::uint32_t> offsets;
    std::vector<std::int32_t> incident;

    // v's rank among the vertices looked at; -1 when it is not looked at.
    std::int32_t rank(std::int32_t v) const {
        if (every_vertex) return v;
        if (!looked.test(std::size_t(v))) return -1;
        return static_cast<std::int32_t>(looked.rank(std::size_t(v)));
    }
};

// The triangles incident to each vertex looked at; progress 0 to 0.5.
IncidentTriangles incident_triangles(const TriangleMesh& mesh, const ProgressFn& progress,
                                     const std::function<bool(std::size_t)>& may_pinch) {
    const std::size_t n = mesh.positions().size();
    const detail::PassProgress counted(progress, 0, 0.1, "mesh");
    IncidentTriangles out;
    out.every_vertex = !may_pinch;
    out.looked_at = n;
    if (may_pinch) {  // (asked on every thread, a word each; counted in order)
        counted.at(0, 1);
        out.looked = detail::RankedBits(n);
        auto& words = out.looked.words();
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, words.size(), std::size_t{1} << 8),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t w = r.begin(); w < r.end(); ++w)
                                  for (std::size_t v = 64 * w; v < std::min(n, 64 * w + 64); ++v)
                                      if (may_pinch(v)) words[w] |= std::uint64_t{1} << (v % 64);
                          });
        out.looked.count();
        out.looked_at = out.looked.members();
    }
    // The corners at vertices looked at, (rank, triangle): with may_pinch (a few vertices of a
    // large grid) gathered by slices of triangles on every thread, in triangle order within
    // each, then counted and listed slice by slice; else (every vertex: a mesh file) counted
    // and listed in two passes over the triangles.
    const std::size_t nt = mesh.triangles().size();
    std::vector<std::vector<std::pair<std::int32_t, std::int32_t>>> corners;
    if (may_pinch)
        corners = gather_by_slices<std::pair<std::int32_t, std::int32_t>>(
            nt, [&](std::size_t t, auto& list) {
                for (auto v : mesh.triangles()[t])
                    if (const std::int32_t k = out.rank(v); k >= 0)
                        list.emplace_back(k, std::int32_t(t));
            });
    report_progress(progress, 0.15, "mesh");
    auto& offsets = out.offsets;
    offsets.assign(out.looked_at + 1, 0);
    if (may_pinch) {
        for (const auto& list : corners)
            for (const auto& c : list) ++offsets[std::size_t(c.first) + 1];
    } else {
        for (std::size_t t = 0; t < nt; ++t)
            for (auto v : mesh.triangles()[t]) ++offsets[std::size_t(v) + 1];
    }
    for (std::size_t r = 0; r < out.looked_at; ++r) offsets[r + 1] += offsets[r];
    detail::assign_in_slices(out.incident, offsets.back(), 0,
                             detail::PassProgress(progress, 0.15, 0.3, "mesh"));
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    if (may_pinch) {
        for (auto& list : corners) {
            for (const auto& c : list) out.incident[fill[std::size_t(c.first)]++] = c.second;
            detail::release(list);
        }
    } else {
        for (std::size_t t = 0; t < nt; ++t)
            for (auto v : mesh.triangles()[t])
                out.incident[fill[std::size_t(v)]++] = std::int32_t(t);
    }
    return out;
}

// Joins in `fans` (reset to k) the k triangles `around` v that share another corner (an
// edge at v): each fan's root is the lowest local index of its triangles.
void join_fans(const TriangleMesh& mesh, std::int32_t v, const std::int32_t* around, std::int32_t k,
               detail::DisjointSets<std::int32_t>& fans,
               std::vector<std::pair<std::int32_t, std::int32_t>>& others) {
    constexpr std::int32_t kPairwise = 16;
    fans.reset(static_cast<std::size_t>(k));
    auto unite = [&](std::int32_t i, std::int32_t j) { fans.unite_to_smaller(i, j); };
    if (k <= kPairwise) {
        // The usual few triangles: compared pair by pair, no sort.
        std::array<std::int32_t, 2 * kPairwise> oc{};
        for (std::int32_t i = 0; i < k; ++i) {
            int j = 0;
            for (auto w : mesh.triangles()[around[i]])
                if (w != v && j < 2) oc[2 * i + j++] = w;
        }
        for (std::int32_t i = 0; i < k; ++i)
            for (std::int32_t j = i + 1; j < k; ++j)
                if (oc[2 * i] == oc[2 * j] || oc[2 * i] == oc[2 * j + 1] ||
                    oc[2 * i + 1] == oc[2 * j] || oc[2 * i + 1] == oc[2 * j + 1])
                    unite(i, j);
    } else {
        others.clear();  // (other vertex, local index)
        for (std::int32_t i = 0; i < k; ++i)
            for (auto w : mesh.triangles()[around[i]])
                if (w != v) others.emplace_back(w, i);
        std::sort(others.begin(), others.end());
        for (std::size_t i = 1; i < others.size(); ++i)
            if (others[i].first == others[i - 1].first)
                unite(others[i].second, others[i - 1].second);
    }
}

}  // namespace

// Fans around each vertex: triangles incident to v joined when they share an edge at v.
// Every fan after the largest (ties: the one holding the lowest triangle index) gets a copy
// of v. Returns the number of vertices split.
std::size_t split_pinched_vertices(TriangleMesh& mesh, std::int32_t* first_pinched,
                                   const ProgressFn& progress,
                                   const std::function<bool(std::size_t)>& may_pinch) {
    const std::size_t n = mesh.positions().size();
    // Its passes: the incident triangles (counted, made, listed: 0 to 0.5), the fans (to 1).
    const detail::PassProgress each_vertex(progress, 0.5, 1, "mesh");
    check_adjacency_size(3 * std::uint64_t{mesh.triangles().size()}, "triangle corners");
    const IncidentTriangles around = incident_triangles(mesh, progress, may_pinch);
    report_progress(progress, 0.5, "mesh");
    std::size_t split = 0;
    std::vector<std::pair<std::int32_t, std::int32_t>> others;
    detail::DisjointSets<std::int32_t> fans_of;  // the triangles around v, by local index
    std::vector<std::int32_t> size;
    for (std::size_t v = 0; v < n; ++v) {
        each_vertex.at(v, n);
        const std::int32_t r = around.rank(std::int32_t(v));
        if (r < 0) continue;
        const std::size_t begin = around.offsets[std::size_t(r)];
        const auto k =
            static_cast<std::int32_t>(around.offsets[std::size_t(r) + 1] - begin);  // a fan's size
        if (k < 2) continue;
        const std::int32_t* triangles = around.incident.data() + begin;
        join_fans(mesh, std::int32_t(v), triangles, k, fans_of, others);
        // Fan sizes by root; roots are the lowest local index of their fan.
        size.assign(k, 0);
        for (std::int32_t i = 0; i < k; ++i) ++size[fans_of.find(i)];
        std::int32_t keep = -1, fans = 0;
        for (std::int32_t i = 0; i < k; ++i)
            if (size[i] > 0) {
                ++fans;
                if (keep < 0 || size[i] > size[keep]) keep = i;
            }
        if (fans < 2) continue;
        if (split++ == 0 && first_pinched) *first_pinched = std::int32_t(v);
        for (std::int32_t root = 0; root < k; ++root) {
            if (size[root] == 0 || root == keep) continue;
            const auto copy = std::int32_t(mesh.positions().size());
            mesh.edit_positions().push_back(mesh.edit_positions()[v]);
            if (!mesh.vertex_pixel.empty()) mesh.vertex_pixel.push_back(mesh.vertex_pixel[v]);
            for (std::int32_t i = 0; i < k; ++i)
                if (fans_of.find(i) == root)
                    for (auto& w : mesh.edit_triangles()[triangles[i]])
                        if (w == std::int32_t(v)) w = copy;
        }
    }
    return split;
}

std::size_t remove_unreferenced_vertices(TriangleMesh& mesh, const ProgressFn& progress) {
    // Its passes: the corners (0 to 0.4), the vertices (to 0.6), the corners again (to 1).
    const detail::PassProgress kept(progress, 0.4, 0.6, "mesh"),
        renumbered(progress, 0.6, 1, "mesh");
    const std::size_t nt = mesh.triangles().size(), nv = mesh.positions().size();
    // The corners marked in a bitmap on every thread (an OR, the same in any order), then
    // counted: a whole grid has no vertex to remove, and is left as it is. A vertex's new
    // number is the count of marked vertices before it: the marks before its word (counted
    // once) and in its word. (A number a vertex beside the triangles was 4 bytes a pixel more
    // at the mesh's peak.)
    detail::RankedBits used(nv);
    auto& words = used.words();
    detail::parallel_slices(nt, std::size_t{4096}, progress, 0, 0.4, "mesh",
                            [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t i = r.begin(); i < r.end(); ++i)
                                    for (auto v : mesh.triangles()[i])
                                        std::atomic_ref<std::uint64_t>(words[std::size_t(v) / 64])
                                            .fetch_or(std::uint64_t{1} << (std::size_t(v) % 64),
                                                      std::memory_order_relaxed);
                            });
    used.count();
    const std::size_t unused = nv - used.members();
    if (unused == 0) {
        report_progress(progress, 1, "mesh");
        return 0;
    }
    const auto marked = [&](std::size_t v) { return used.test(v); };
    const auto remap = [&](std::int32_t v) {
        return static_cast<std::int32_t>(used.rank(std::size_t(v)));
    };
    const bool pixels = !mesh.vertex_pixel.empty();
    std::int32_t next = 0;
    for (std::size_t v = 0; v < nv; ++v) {
        kept.at(v, nv);
        if (!marked(v)) continue;
        mesh.edit_positions()[next] = mesh.edit_positions()[v];
        if (pixels) mesh.vertex_pixel[next] = mesh.vertex_pixel[v];
        ++next;
    }
    mesh.edit_positions().resize(next);
    if (pixels) mesh.vertex_pixel.resize(next);
    for (std::size_t i = 0; i < nt; ++i) {
        renumbered.at(i, nt);
        for (auto& v : mesh.edit_triangles()[i]) v = remap(v);
    }
    // (A pole vertex in no triangle is removed too: it names none then.)
    for (auto& pv : mesh.pole_vertices)
        if (pv >= 0) pv = marked(std::size_t(pv)) ? remap(pv) : -1;
    return unused;
}

}  // namespace terrain
