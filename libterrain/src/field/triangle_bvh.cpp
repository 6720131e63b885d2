#include "triangle_bvh.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <limits>

namespace terrain::field::detail {
namespace {

constexpr int kBins = 16;
constexpr std::int32_t kLeafSize = 4;
// Below this depth splits follow the surface-area heuristic; deeper, the median, so the
// depth (and the traversal stack) stays bounded whatever the triangles look like.
constexpr int kMaxSahDepth = 40;
// Each 4-wide node pushes at most 4 entries and the depth stays below 80.
constexpr int kStackSize = 4 * (kMaxSahDepth + 40);

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Box {
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    void grow(const Vec3& p) {
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    }
    void grow(const Box& b) {
        for (int k = 0; k < 3; ++k)
            lo[k] = std::min(lo[k], b.lo[k]), hi[k] = std::max(hi[k], b.hi[k]);
    }
    double half_area() const {
        const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
        return dx < 0 ? 0.0 : dx * dy + dy * dz + dz * dx;
    }
};

struct Prim {
    Box box;
    Vec3 centre;
    std::int32_t face;
};

// A node of the binary tree the 4-wide one is collapsed from.
struct BinaryNode {
    Box box;
    std::int32_t first = 0;  // leaf: first triangle; inner: the left child (right = +1)
    std::int32_t count = 0;  // leaf: number of triangles; 0 for an inner node
};

class Builder {
  public:
    Builder(std::vector<Prim>& prims, std::vector<BinaryNode>& nodes)
        : prims_(prims), nodes_(nodes) {}

    void build(std::int32_t node, std::int32_t begin, std::int32_t end, int depth) {
        Box box, centres;
        for (std::int32_t i = begin; i < end; ++i) {
            box.grow(prims_[i].box);
            centres.grow(prims_[i].centre);
        }
        nodes_[node].box = box;
        const std::int32_t count = end - begin;
        int axis = 0;
        for (int k = 1; k < 3; ++k)
            if (centres.hi[k] - centres.lo[k] > centres.hi[axis] - centres.lo[axis]) axis = k;
        const double extent = centres.hi[axis] - centres.lo[axis];
        if (count <= kLeafSize) return make_leaf(node, begin, count);
        std::int32_t mid = -1;  // coincident centres or too deep: the median
        if (depth < kMaxSahDepth && extent > 0) {
            mid = sah_split(begin, end, axis, centres.lo[axis], extent, box);
            if (mid == 0) return make_leaf(node, begin, count);
        }
        if (mid <= begin || mid >= end) {
            mid = begin + count / 2;
            std::nth_element(prims_.begin() + begin, prims_.begin() + mid, prims_.begin() + end,
                             [axis](const Prim& a, const Prim& b) {
                                 return a.centre[axis] < b.centre[axis] ||
                                        (a.centre[axis] == b.centre[axis] && a.face < b.face);
                             });
        }
        const auto left = static_cast<std::int32_t>(nodes_.size());
        nodes_.resize(nodes_.size() + 2);
        nodes_[node].first = left;
        nodes_[node].count = 0;
        build(left, begin, mid, depth + 1);
        build(left + 1, mid, end, depth + 1);
    }

  private:
    void make_leaf(std::int32_t node, std::int32_t begin, std::int32_t count) {
        nodes_[node].first = begin;
        nodes_[node].count = count;
    }

    // Partitions [begin, end) at the cheapest of the bin boundaries along `axis`; returns
    // the split point, 0 when a leaf is cheaper, -1 when no boundary separates anything.
    std::int32_t sah_split(std::int32_t begin, std::int32_t end, int axis, double lo, double extent,
                           const Box& box) {
        struct Bin {
            Box box;
            std::int32_t count = 0;
        };
        std::array<Bin, kBins> bins;
        const double scale = kBins / extent;
        auto bin_of = [&](const Prim& p) {
            return std::clamp(static_cast<int>((p.centre[axis] - lo) * scale), 0, kBins - 1);
        };
        for (std::int32_t i = begin; i < end; ++i) {
            Bin& b = bins[bin_of(prims_[i])];
            b.box.grow(prims_[i].box);
            ++b.count;
        }
        std::array<double, kBins> right_cost{};
        Box acc;
        std::int32_t n = 0;
        for (int k = kBins - 1; k > 0; --k) {
            acc.grow(bins[k].box);
            n += bins[k].count;
            right_cost[k] = n * acc.half_area();
        }
        double best = kInf;
        int best_split = -1;
        acc = Box{};
        n = 0;
        for (int k = 1; k < kBins; ++k) {
            acc.grow(bins[k - 1].box);
            n += bins[k - 1].count;
            if (n == 0 || n == end - begin) continue;
            const double cost = n * acc.half_area() + right_cost[k];
            if (cost < best) best = cost, best_split = k;
        }
        if (best_split < 0) return -1;
        // Intersection tests cost about as much as box tests: a small node stays a leaf
        // when splitting would not save tests.
        if (end - begin <= 4 * kLeafSize && best >= (end - begin) * box.half_area()) return 0;
        const auto it = std::partition(prims_.begin() + begin, prims_.begin() + end,
                                       [&](const Prim& p) { return bin_of(p) < best_split; });
        return static_cast<std::int32_t>(it - prims_.begin());
    }

    std::vector<Prim>& prims_;
    std::vector<BinaryNode>& nodes_;
};

// Rounds outwards to float.
float round_down(double x) {
    const auto f = static_cast<float>(x);
    return f > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float round_up(double x) {
    const auto f = static_cast<float>(x);
    return f < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

// Collapses the binary tree into 4-wide nodes: a node's children are found by opening the
// inner child with the largest surface until there are four.
class Collapser {
  public:
    Collapser(const std::vector<BinaryNode>& binary, std::vector<TriangleBvh::Node>& nodes,
              double pad)
        : binary_(binary), nodes_(nodes), pad_(pad) {}

    // The 4-wide node for the binary node `b`; returns its index.
    std::int32_t collapse(std::int32_t b) {
        std::array<std::int32_t, 4> kids{b, -1, -1, -1};
        int n = 1;
        if (binary_[b].count == 0) {
            kids = {binary_[b].first, binary_[b].first + 1, -1, -1};
            n = 2;
            while (n < 4) {
                int open = -1;
                for (int i = 0; i < n; ++i)
                    if (binary_[kids[i]].count == 0 &&
                        (open < 0 ||
                         binary_[kids[i]].box.half_area() > binary_[kids[open]].box.half_area()))
                        open = i;
                if (open < 0) break;
                const std::int32_t first = binary_[kids[open]].first;
                kids[open] = first;
                kids[n++] = first + 1;
            }
        }
        const auto index = static_cast<std::int32_t>(nodes_.size());
        nodes_.emplace_back();
        for (int i = 0; i < 4; ++i) {
            TriangleBvh::Node& node = nodes_[index];
            if (i >= n) {
                node.child[i] = -1;
                node.count[i] = 0;
                for (int k = 0; k < 3; ++k) {  // an empty box no ray enters
                    node.bounds[k][0][i] = std::numeric_limits<float>::infinity();
                    node.bounds[k][1][i] = -std::numeric_limits<float>::infinity();
                }
                continue;
            }
            const BinaryNode& kid = binary_[kids[i]];
            // Padded so that float rounding in the slab test never misses a triangle.
            for (int k = 0; k < 3; ++k) {
                node.bounds[k][0][i] = round_down(kid.box.lo[k] - pad_);
                node.bounds[k][1][i] = round_up(kid.box.hi[k] + pad_);
            }
            node.count[i] = kid.count;
            node.child[i] = kid.first;
        }
        for (int i = 0; i < n; ++i)
            if (binary_[kids[i]].count == 0) {
                const std::int32_t child = collapse(kids[i]);
                nodes_[index].child[i] = child;
            }
        return index;
    }

  private:
    const std::vector<BinaryNode>& binary_;
    std::vector<TriangleBvh::Node>& nodes_;
    double pad_;
};

// A ray prepared for the float slab tests of a node's four boxes: t = corner * inv - offset
// along each axis, the corner picked by the direction's sign so that no swap is needed.
struct SlabRay {
    std::array<float, 3> inv, offset;
    std::array<int, 3> near;  // 0: the lower corner is met first along the axis, 1: the upper

    SlabRay(const Vec3& origin, const Vec3& direction) {
        for (int k = 0; k < 3; ++k) {
            // A zero component would give 0 * inf = NaN; a huge finite inverse gives the
            // same answer without it.
            const double d =
                std::abs(direction[k]) < 1e-30 ? std::copysign(1e-30, direction[k]) : direction[k];
            inv[k] = static_cast<float>(1.0 / d);
            offset[k] = static_cast<float>(origin[k]) * inv[k];
            near[k] = d < 0;
        }
    }

    // Entry distances into the four boxes within [0, t_max]; negative for a miss.
    std::array<float, 4> enter(const TriangleBvh::Node& node, float t_max) const {
        const auto& x0 = node.bounds[0][near[0]];
        const auto& x1 = node.bounds[0][1 - near[0]];
        const auto& y0 = node.bounds[1][near[1]];
        const auto& y1 = node.bounds[1][1 - near[1]];
        const auto& z0 = node.bounds[2][near[2]];
        const auto& z1 = node.bounds[2][1 - near[2]];
        std::array<float, 4> out;
#if defined(__SSE2__)
        auto slab = [](const std::array<float, 4>& corner, float scale, float shift) {
            return _mm_sub_ps(_mm_mul_ps(_mm_loadu_ps(corner.data()), _mm_set1_ps(scale)),
                              _mm_set1_ps(shift));
        };
        const __m128 t0 =
            _mm_max_ps(_mm_max_ps(slab(x0, inv[0], offset[0]), slab(y0, inv[1], offset[1])),
                       _mm_max_ps(slab(z0, inv[2], offset[2]), _mm_setzero_ps()));
        const __m128 t1 =
            _mm_min_ps(_mm_min_ps(slab(x1, inv[0], offset[0]), slab(y1, inv[1], offset[1])),
                       _mm_min_ps(slab(z1, inv[2], offset[2]), _mm_set1_ps(t_max)));
        // t0 where t0 <= t1, else -1.
        const __m128 met = _mm_cmple_ps(t0, t1);
        _mm_storeu_ps(out.data(),
                      _mm_or_ps(_mm_and_ps(met, t0), _mm_andnot_ps(met, _mm_set1_ps(-1.0f))));
#else
        for (int c = 0; c < 4; ++c) {
            const float t0 =
                std::max(std::max(x0[c] * inv[0] - offset[0], y0[c] * inv[1] - offset[1]),
                         std::max(z0[c] * inv[2] - offset[2], 0.0f));
            const float t1 =
                std::min(std::min(x1[c] * inv[0] - offset[0], y1[c] * inv[1] - offset[1]),
                         std::min(z1[c] * inv[2] - offset[2], t_max));
            out[c] = t0 <= t1 ? t0 : -1.0f;
        }
#endif
        return out;
    }
};

}  // namespace

TriangleBvh::TriangleBvh(const std::vector<Vec3>& points,
                         const std::vector<std::array<std::int32_t, 3>>& triangles,
                         const std::vector<std::int32_t>& faces) {
    if (faces.empty()) return;
    std::vector<Prim> prims(faces.size());
    Box scene;
    for (std::size_t i = 0; i < faces.size(); ++i) {
        const auto& t = triangles[faces[i]];
        Prim& p = prims[i];
        for (int k = 0; k < 3; ++k) p.box.grow(points[t[k]]);
        for (int k = 0; k < 3; ++k) p.centre[k] = 0.5 * (p.box.lo[k] + p.box.hi[k]);
        p.face = faces[i];
        scene.grow(p.box);
    }
    lower_ = scene.lo;
    upper_ = scene.hi;
    std::vector<BinaryNode> binary;
    binary.reserve(2 * faces.size() / kLeafSize + 1);
    binary.resize(1);
    Builder(prims, binary).build(0, 0, static_cast<std::int32_t>(prims.size()), 0);
    // Float slab tests are off by a few float epsilons of the coordinates (at most the
    // scene's size, the origin being inside it): pad by more than that.
    double size = 0;
    for (int k = 0; k < 3; ++k)
        size = std::max({size, std::abs(scene.lo[k]), std::abs(scene.hi[k])});
    nodes_.reserve(binary.size() / 2 + 1);
    Collapser(binary, nodes_, 1e-6 * size).collapse(0);
    triangles_.resize(prims.size());
    for (std::size_t i = 0; i < prims.size(); ++i) {
        const auto& t = triangles[prims[i].face];
        Triangle& tri = triangles_[i];
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k)
                tri.corners[3 * c + k] = static_cast<float>(points[t[c]][k]);
        tri.face = prims[i].face;
    }
}

TriangleBvh::Hit TriangleBvh::first_hit(const Vec3& origin, const Vec3& direction, double t_max,
                                        std::int32_t skip) const {
    Hit hit;
    if (nodes_.empty()) return hit;
    const SlabRay ray(origin, direction);
    double best = t_max;
    float best_f = round_up(best);
    struct Entry {
        std::int32_t child, count;  // as in Node
        float t;
    };
    std::array<Entry, kStackSize> stack;
    int top = 0;
    stack[top++] = {0, 0, 0.0f};
    while (top > 0) {
        const Entry e = stack[--top];
        if (e.t > best_f) continue;
        if (e.count > 0) {
            for (std::int32_t i = e.child; i < e.child + e.count; ++i) {
                const Triangle& tri = triangles_[i];
                if (tri.face == skip) continue;
                const auto& c = tri.corners;
                const Vec3 v0{c[0], c[1], c[2]};
                const Vec3 e1{double(c[3]) - c[0], double(c[4]) - c[1], double(c[5]) - c[2]};
                const Vec3 e2{double(c[6]) - c[0], double(c[7]) - c[1], double(c[8]) - c[2]};
                const Vec3 p = cross(direction, e2);
                const double det = dot(e1, p);
                if (det == 0) continue;  // parallel to the plane (or grazing inside it)
                const double inv_det = 1.0 / det;
                const Vec3 s = sub(origin, v0);
                const double u = dot(s, p) * inv_det;
                if (u < 0 || u > 1) continue;
                const Vec3 q = cross(s, e1);
                const double v = dot(direction, q) * inv_det;
                if (v < 0 || u + v > 1) continue;
                const double t = dot(e2, q) * inv_det;
                if (t > 0 && t < best) {
                    best = t;
                    best_f = round_up(best);
                    // det = -direction . (e1 x e2): negative when the ray leaves through
                    // the face's front (normal) side.
                    hit = {tri.face, t, det < 0};
                }
            }
            continue;
        }
        const Node& node = nodes_[e.child];
        const auto t = ray.enter(node, best_f);
        // Push the boxes met, farthest first, so that the nearest is popped first and the
        // others are often culled by `best`.
        std::array<int, 4> order;
        int n = 0;
        for (int c = 0; c < 4; ++c) {
            if (t[c] < 0) continue;
            int j = n++;
            for (; j > 0 && t[order[j - 1]] < t[c]; --j) order[j] = order[j - 1];
            order[j] = c;
        }
        for (int j = 0; j < n; ++j) {
            const int c = order[j];
            stack[top++] = {node.child[c], node.count[c], t[c]};
        }
    }
    return hit;
}

}  // namespace terrain::field::detail
