#pragma once
// Private: disjoint sets (union-find) over 0-based indices. Not installed.
//
// Two conventions are in use, both kept so that every caller's sets end up with the same
// roots as before (outputs number things by their roots):
//   - DisjointSets: a parent vector where a root is its own parent. unite(keep, other) keeps
//     keep's root; unite_to_smaller(a, b) keeps the smaller of the two roots.
//   - find_root(parent, x): a parent array owned by the caller where kNone marks a root.
// Finds compress the path they walk; that never changes a root, only shortens later finds.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <numeric>
#include <vector>

#include "terrain/internal/core/indices.hpp"

namespace terrain::detail {

template <class Index = i32>
class DisjointSets {
  public:
    DisjointSets() = default;
    explicit DisjointSets(std::size_t n) { reset(n); }

    // n singletons 0 .. n-1.
    void reset(std::size_t n) {
        parent_.resize(n);
        std::iota(parent_.begin(), parent_.end(), Index{0});
    }
    // n indices in no set yet (see make_set and contains); only for a signed Index.
    void reset_empty(std::size_t n) { parent_.assign(n, static_cast<Index>(kNone)); }
    void make_set(Index x) { parent_[at(x)] = x; }
    bool contains(Index x) const { return parent_[at(x)] != static_cast<Index>(kNone); }
    // A new singleton at the end; returns it.
    Index add() {
        const auto x = static_cast<Index>(parent_.size());
        parent_.push_back(x);
        return x;
    }
    bool empty() const { return parent_.empty(); }
    std::size_t size() const { return parent_.size(); }

    // The root of x's set (path halving).
    Index find(Index x) {
        while (parent_[at(x)] != x) x = parent_[at(x)] = parent_[at(parent_[at(x)])];
        return x;
    }
    bool is_root(Index x) const { return parent_[at(x)] == x; }
    // Joins the sets of keep and other under keep's root; returns that root.
    Index unite(Index keep, Index other) {
        const Index a = find(keep), b = find(other);
        if (a != b) parent_[at(b)] = a;
        return a;
    }
    // Joins the sets of a and b under the smaller of their two roots; returns it.
    Index unite_to_smaller(Index a, Index b) {
        const Index ra = find(a), rb = find(b);
        if (ra == rb) return ra;
        return unite(std::min(ra, rb), std::max(ra, rb));
    }
    // Points every index straight at its root: then parent(x) is the root.
    void flatten() {
        for (std::size_t x = 0; x < parent_.size(); ++x) parent_[x] = find(static_cast<Index>(x));
    }
    Index parent(Index x) const { return parent_[at(x)]; }

  private:
    static std::size_t at(Index x) { return static_cast<std::size_t>(x); }
    std::vector<Index> parent_;
};

// The root of x in a forest of parent links held by the caller, where kNone marks a root;
// the path is compressed (every node on it then points at the root).
inline i32 find_root(std::vector<i32>& parent, i32 x) {
    i32 root = x;
    while (parent[idx(root)] != kNone) root = parent[idx(root)];
    while (x != root) {
        const i32 up = parent[idx(x)];
        parent[idx(x)] = root;
        x = up;
    }
    return root;
}

// find_root for threads that search the same forest at once while no link is added: every
// link is read and written whole (relaxed atomics: plain loads and stores), and a link is only
// ever set to a root of its own tree, so each thread finds the same root whatever the others
// have compressed.
inline i32 find_root_shared(std::vector<i32>& parent, i32 x) {
    const auto link = [&](i32 n) { return std::atomic_ref<i32>(parent[idx(n)]); };
    i32 root = x;
    for (i32 up; (up = link(root).load(std::memory_order_relaxed)) != kNone;) root = up;
    while (x != root) {
        const i32 up = link(x).load(std::memory_order_relaxed);
        link(x).store(root, std::memory_order_relaxed);
        x = up;
    }
    return root;
}

}  // namespace terrain::detail
