// The order of events (paper s.3.1: the sweep over the field's values; docs/reeb.md "Nodes").
// Vertices are sorted by value with a stable radix sort of the float bits; adjacent vertices
// of exactly equal value are one event, one node (a plateau, the paper's Conley-index
// treatment); other ties are broken by the plateau's lowest vertex, then by vertex index
// (simulation of simplicity), so the graph depends on nothing but the mesh and the field.

#include "event_order.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <numeric>
#include <utility>

#include "terrain/internal/core/disjoint_sets.hpp"
#include "terrain/internal/core/indices.hpp"
#include "terrain/internal/core/pass_progress.hpp"
#include "terrain/internal/core/release.hpp"

namespace terrain::reeb::internal {

namespace {

using detail::i32;
using detail::idx;

// The parallel passes' fixed chunks of the vertices, run kGroup at a time.
constexpr std::size_t kChunks = 64, kGroup = 8;

// Sort key of a float: monotonic unsigned bits (-0 taken as +0).
inline std::uint32_t float_key(float f) {
    if (f == 0.0f) f = 0.0f;
    const auto u = std::bit_cast<std::uint32_t>(f);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

// The float of a sort key (-0 comes back as +0).
inline float key_float(std::uint32_t k) {
    return std::bit_cast<float>((k & 0x80000000u) ? (k & 0x7fffffffu) : ~k);
}

// The vertices' fixed chunks: f(chunk, first, end) for every chunk, kGroup chunks at a time
// in parallel; the progress from `from` to `to` after each group (a pass over a global grid
// takes seconds).
struct Chunks {
    std::size_t nv;
    const ProgressFn& progress;
    std::size_t begin(std::size_t c) const { return nv * c / kChunks; }
    template <class F>
    void each(double from, double to, F&& f) const {
        for (std::size_t group = 0; group < kChunks; group += kGroup) {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(group, group + kGroup, 1),
                              [&](const tbb::blocked_range<std::size_t>& r) {
                                  for (std::size_t c = r.begin(); c < r.end(); ++c)
                                      f(c, begin(c), begin(c + 1));
                              });
            report_progress(progress, from + (to - from) * double(group + kGroup) / kChunks,
                            "reeb: order");
        }
    }
};

bool same_value(std::uint64_t a, std::uint64_t b) {
    return (a >> 32) == (b >> 32);
}
i32 vertex(std::uint64_t k) {
    return static_cast<i32>(k & 0xffffffffu);
}

// The sort keys (value bits << 32 | vertex) of the field in order; progress 0 to 0.6.
std::vector<std::uint64_t> sorted_keys(const std::vector<float>& field, const Chunks& chunks) {
    const std::size_t nv = field.size();
    const ProgressFn& progress = chunks.progress;
    using detail::PassProgress;
    // Stable LSD radix sort of (value bits << 32 | vertex) on the value bits, 11 bits per
    // pass: ties keep vertex order. Each pass in parallel over fixed chunks of the array: a
    // chunk's items of a digit go after those of the chunks before it, so the result is the
    // one sort's, whatever the threads.
    // (Large blocks made a slice at a time: their first touch is slow, docs/performance.md.)
    std::vector<std::uint64_t> keys, tmp;
    detail::assign_in_slices(keys, nv, std::uint64_t{0},
                             PassProgress(progress, 0, 0.05, "reeb: order"));
    detail::assign_in_slices(tmp, nv, std::uint64_t{0},
                             PassProgress(progress, 0.05, 0.1, "reeb: order"));
    const auto each_chunk = [&](double from, double to, auto&& f) { chunks.each(from, to, f); };
    each_chunk(0.1, 0.15, [&](std::size_t, std::size_t first, std::size_t end) {
        for (std::size_t v = first; v < end; ++v)
            keys[v] = (std::uint64_t{float_key(field[v])} << 32) | v;
    });
    constexpr int kBits = 11;
    constexpr std::size_t kBuckets = std::size_t{1} << kBits;
    std::vector<std::uint32_t> count(kChunks * kBuckets);
    for (int p = 0; p < 3; ++p) {
        const int shift = 32 + kBits * p;
        const auto digit = [shift](std::uint64_t k) { return (k >> shift) & (kBuckets - 1); };
        const double at = 0.15 + 0.15 * p;
        each_chunk(at, at + 0.05, [&](std::size_t c, std::size_t first, std::size_t end) {
            std::uint32_t* mine = count.data() + c * kBuckets;
            std::fill(mine, mine + kBuckets, 0u);
            for (std::size_t i = first; i < end; ++i) ++mine[digit(keys[i])];
        });
        // Each chunk's first place for each digit; none to move when one digit holds all.
        std::uint32_t sum = 0;
        bool one_digit = false;
        for (std::size_t b = 0; b < kBuckets; ++b) {
            const std::uint32_t before = sum;
            for (std::size_t c = 0; c < kChunks; ++c)
                sum += std::exchange(count[c * kBuckets + b], sum);
            one_digit |= sum - before == nv;
        }
        if (nv == 0 || one_digit) continue;
        each_chunk(at + 0.05, at + 0.15, [&](std::size_t c, std::size_t first, std::size_t end) {
            std::uint32_t* place = count.data() + c * kBuckets;
            for (std::size_t i = first; i < end; ++i) {
                const std::uint64_t k = keys[i];
                tmp[place[digit(k)]++] = k;
            }
        });
        keys.swap(tmp);
    }
    detail::release(tmp);
    return keys;
}

// Each vertex's plateau (adjacent vertices of equal value), its representative (the root)
// its lowest vertex; empty when there is none. Progress 0.6 to 0.74.
detail::DisjointSets<i32> plateaus_of(const TriangleMesh& mesh, const std::vector<float>& field,
                                      const std::vector<std::uint64_t>& keys,
                                      const Chunks& chunks) {
    const std::size_t nv = field.size();
    const auto each_chunk = [&](double from, double to, auto&& f) { chunks.each(from, to, f); };
    // Plateaus: adjacent vertices of equal value. Only a vertex whose value another vertex
    // shares (next to it in the sorted order) can be in one. On a noisy grid of quantized
    // heights about half the vertices share their value (a few each): the passes run in
    // parallel over the chunks, with the same sets as one pass in order.
    std::atomic<bool> any_tie{false};
    each_chunk(0.6, 0.62, [&](std::size_t, std::size_t first, std::size_t end) {
        for (std::size_t i = std::max<std::size_t>(first, 1); i < end; ++i)
            if (same_value(keys[i], keys[i - 1])) {
                any_tie = true;
                return;
            }
    });
    std::vector<char> tied;
    if (any_tie) {
        tied.assign(nv, 0);
        each_chunk(0.62, 0.65, [&](std::size_t, std::size_t first, std::size_t end) {
            for (std::size_t i = std::max<std::size_t>(first, 1); i < end; ++i)
                if (same_value(keys[i], keys[i - 1]))  // (a vertex may be marked by two chunks)
                    for (const std::size_t at : {i, i - 1})
                        std::atomic_ref<char>(tied[idx(vertex(keys[at]))])
                            .store(1, std::memory_order_relaxed);
        });
    }
    // Each vertex's plateau; its representative (the root) is its lowest vertex. Each chunk of
    // vertices joins the equal neighbours within it (its sets' links stay within it), and
    // the pairs reaching a later chunk are joined after, in order: the same sets, the same
    // roots (a set's lowest vertex).
    detail::DisjointSets<i32> plateaus;
    if (!tied.empty()) {
        plateaus.reset(nv);
        std::vector<std::vector<std::pair<i32, i32>>> crossing(kChunks);
        std::atomic<bool> joined{false};
        each_chunk(0.65, 0.74, [&](std::size_t c, std::size_t first, std::size_t end) {
            bool any = false;
            for (std::size_t v = first; v < end; ++v) {
                if (!tied[v]) continue;
                for (const i32 w : mesh.neighbors_of(v)) {
                    if (idx(w) <= v || field[idx(w)] != field[v]) continue;
                    any = true;
                    if (idx(w) < end)
                        plateaus.unite_to_smaller(static_cast<i32>(v), w);
                    else
                        crossing[c].emplace_back(static_cast<i32>(v), w);
                }
            }
            if (any) joined = true;
        });
        for (const auto& pairs : crossing)
            for (const auto& [v, w] : pairs) plateaus.unite_to_smaller(v, w);
        if (!joined) plateaus = {};
    }
    detail::release(tied);
    return plateaus;
}

// Within each run of equal values, the plateaus together, ordered by their lowest vertex,
// then by vertex; progress 0.75 to 0.8.
void order_plateaus(std::vector<std::uint64_t>& keys, const detail::DisjointSets<i32>& plateaus,
                    const Chunks& chunks) {
    const std::size_t nv = keys.size();
    const auto each_chunk = [&](double from, double to, auto&& f) { chunks.each(from, to, f); };
    // Equal values: plateaus together, ordered by their lowest vertex, then by vertex. A
    // run of equal values is sorted as (plateau << 32 | vertex), so that the sort reads
    // nothing else. Half the vertices of a noisy grid are in such runs (a few vertices
    // each): each chunk sorts the runs that start in it, from its first run's start.
    std::vector<std::size_t> run_start(kChunks + 1, nv);
    // (A chunk with no run starting in it gets the next chunk's first start: nothing.)
    each_chunk(0.75, 0.77, [&](std::size_t c, std::size_t first, std::size_t) {
        std::size_t i = first;
        while (i < nv && i > 0 && same_value(keys[i - 1], keys[i])) ++i;
        run_start[c] = i;
    });
    each_chunk(0.77, 0.8, [&](std::size_t c, std::size_t, std::size_t) {
        std::vector<std::uint64_t> run;
        const std::size_t stop = run_start[c + 1];
        for (std::size_t i = run_start[c]; i < stop;) {
            std::size_t j = i + 1;
            while (j < nv && same_value(keys[i], keys[j])) ++j;
            if (j - i > 1) {
                run.clear();
                for (std::size_t k = i; k < j; ++k) {
                    const i32 v = vertex(keys[k]);
                    run.push_back(std::uint64_t(std::uint32_t(plateaus.parent(v))) << 32 |
                                  std::uint32_t(v));
                }
                std::sort(run.begin(), run.end());
                const std::uint64_t value_bits = keys[i] & ~std::uint64_t{0xffffffffu};
                for (std::size_t k = i; k < j; ++k)
                    keys[k] = value_bits | (run[k - i] & 0xffffffffu);
            }
            i = j;
        }
    });
}

// The nodes from the sorted keys: each event (a vertex, or a plateau's vertices) a node, its
// vertices and value; progress 0.8 to 1.
void write_nodes(ReebGraph& g, const std::vector<std::uint64_t>& keys,
                 const detail::DisjointSets<i32>& plateaus, const Chunks& chunks) {
    const std::size_t nv = keys.size();
    const ProgressFn& progress = chunks.progress;
    using detail::PassProgress;
    const bool any_plateau = !plateaus.empty();
    const auto chunk_begin = [&](std::size_t c) { return chunks.begin(c); };
    const auto each_chunk = [&](double from, double to, auto&& f) { chunks.each(from, to, f); };
    auto same_event = [&](std::uint64_t a, std::uint64_t b) {
        return any_plateau && same_value(a, b) &&
               plateaus.parent(vertex(a)) == plateaus.parent(vertex(b));
    };
    // Sorted entry i starts a node unless it is in the same event as the one before it.
    const auto starts = [&](std::size_t i) { return i == 0 || !same_event(keys[i], keys[i - 1]); };
    // The nodes before each chunk's first entry (with plateaus, counted in parallel).
    std::vector<std::size_t> nodes_before(kChunks + 1, 0);
    for (std::size_t c = 0; c <= kChunks; ++c) nodes_before[c] = chunk_begin(c);
    if (any_plateau) {
        each_chunk(0.8, 0.82, [&](std::size_t c, std::size_t first, std::size_t end) {
            std::size_t begun = 0;
            for (std::size_t i = first; i < end; ++i) begun += starts(i);
            nodes_before[c + 1] = begun;
        });
        nodes_before[0] = 0;
        std::partial_sum(nodes_before.begin(), nodes_before.end(), nodes_before.begin());
    }
    const std::size_t n_nodes = nodes_before[kChunks];
    detail::assign_in_slices(g.node_vertices, nv, i32{0},
                             PassProgress(progress, 0.82, 0.85, "reeb: order"));
    detail::assign_in_slices(g.vertex_nodes, nv, i32{0},
                             PassProgress(progress, 0.85, 0.88, "reeb: order"));
    detail::assign_in_slices(g.node_vertex_offsets, n_nodes + 1, i32{0},
                             PassProgress(progress, 0.88, 0.89, "reeb: order"));
    detail::assign_in_slices(g.node_values, n_nodes, 0.0f,
                             PassProgress(progress, 0.89, 0.9, "reeb: order"));
    // The nodes in parallel: each chunk numbers its events on from those before it.
    constexpr std::size_t kAhead = 16;  // vertex_nodes is written in random order
    each_chunk(0.9, 1.0, [&](std::size_t c, std::size_t first, std::size_t end) {
        auto node = static_cast<i32>(nodes_before[c]) - 1;
        for (std::size_t i = first; i < end; ++i) {
            if (i + kAhead < end)
                __builtin_prefetch(&g.vertex_nodes[idx(vertex(keys[i + kAhead]))], 1);
            const i32 v = vertex(keys[i]);
            if (!any_plateau || starts(i)) {
                ++node;
                g.node_vertex_offsets[idx(node)] = static_cast<i32>(i);
                g.node_values[idx(node)] = key_float(static_cast<std::uint32_t>(keys[i] >> 32));
            }
            g.node_vertices[i] = v;
            g.vertex_nodes[idx(v)] = node;
        }
    });
    g.node_vertex_offsets[n_nodes] = static_cast<i32>(nv);
}

}  // namespace

void order_events(const TriangleMesh& mesh, const std::vector<float>& field, ReebGraph& g,
                  const ProgressFn& progress) {
    // Its passes: the keys (0 to 0.15), three radix passes (to 0.6), the ties (to 0.65), the
    // plateaus (to 0.75), the runs of equal values (to 0.8), the nodes (to 1).
    const Chunks chunks{field.size(), progress};
    std::vector<std::uint64_t> keys = sorted_keys(field, chunks);
    detail::DisjointSets<i32> plateaus = plateaus_of(mesh, field, keys, chunks);
    if (!plateaus.empty()) {
        plateaus.flatten();
        order_plateaus(keys, plateaus, chunks);
    }
    write_nodes(g, keys, plateaus, chunks);
    report_progress(progress, 1.0, "reeb: order");
}

}  // namespace terrain::reeb::internal
