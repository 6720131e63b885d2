#include "triangle_bvh.hpp"

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
constexpr int kStackSize = kMaxSahDepth + 40;

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

Vec3 sub(const Vec3& a, const Vec3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

class Builder {
  public:
    Builder(std::vector<Prim>& prims, std::vector<TriangleBvh::Node>& nodes, double pad)
        : prims_(prims), nodes_(nodes), pad_(pad) {}

    void build(std::int32_t node, std::int32_t begin, std::int32_t end, int depth) {
        Box box, centres;
        for (std::int32_t i = begin; i < end; ++i) {
            box.grow(prims_[i].box);
            centres.grow(prims_[i].centre);
        }
        // Padded so that rounding in the slab test never misses a triangle on a box face.
        for (int k = 0; k < 3; ++k) box.lo[k] -= pad_, box.hi[k] += pad_;
        nodes_[node].box = {box.lo, box.hi};
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
    std::vector<TriangleBvh::Node>& nodes_;
    double pad_;
};

// A ray prepared for slab tests: t = corner * inv - origin * inv along each axis, the
// corner picked by the direction's sign so that no swap is needed.
struct SlabRay {
    Vec3 inv, offset;
    std::array<int, 3> near;  // 0: the lower corner is met first along the axis, 1: the upper

    SlabRay(const Vec3& origin, const Vec3& direction) {
        for (int k = 0; k < 3; ++k) {
            // A zero component would give 0 * inf = NaN; a huge finite inverse gives the
            // same answer without it.
            const double d = std::abs(direction[k]) < 1e-300 ? std::copysign(1e-300, direction[k])
                                                             : direction[k];
            inv[k] = 1.0 / d;
            offset[k] = origin[k] * inv[k];
            near[k] = d < 0;
        }
    }

    // Entry distance into the box within [0, t_max], or a negative value on a miss.
    double enter(const std::array<Vec3, 2>& box, double t_max) const {
        const double x0 = box[near[0]][0] * inv[0] - offset[0];
        const double x1 = box[1 - near[0]][0] * inv[0] - offset[0];
        const double y0 = box[near[1]][1] * inv[1] - offset[1];
        const double y1 = box[1 - near[1]][1] * inv[1] - offset[1];
        const double z0 = box[near[2]][2] * inv[2] - offset[2];
        const double z1 = box[1 - near[2]][2] * inv[2] - offset[2];
        const double t0 = std::max(std::max(x0, y0), std::max(z0, 0.0));
        const double t1 = std::min(std::min(x1, y1), std::min(z1, t_max));
        return t0 <= t1 ? t0 : -1.0;
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
    double size = 0;
    for (int k = 0; k < 3; ++k) size = std::max(size, scene.hi[k] - scene.lo[k]);
    nodes_.reserve(2 * faces.size() / kLeafSize + 1);
    nodes_.resize(1);
    Builder(prims, nodes_, 1e-9 * size + 1e-300)
        .build(0, 0, static_cast<std::int32_t>(prims.size()), 0);
    triangles_.resize(prims.size());
    for (std::size_t i = 0; i < prims.size(); ++i) {
        const auto& t = triangles[prims[i].face];
        const Vec3& a = points[t[0]];
        triangles_[i] = {a, sub(points[t[1]], a), sub(points[t[2]], a), prims[i].face};
    }
}

TriangleBvh::Hit TriangleBvh::first_hit(const Vec3& origin, const Vec3& direction, double t_max,
                                        std::int32_t skip) const {
    Hit hit;
    if (nodes_.empty()) return hit;
    const SlabRay ray(origin, direction);
    double best = t_max;
    struct Entry {
        std::int32_t node;
        double t;
    };
    std::array<Entry, kStackSize> stack;
    int top = 0;
    const double t_root = ray.enter(nodes_[0].box, best);
    if (t_root < 0) return hit;
    stack[top++] = {0, t_root};
    while (top > 0) {
        const Entry e = stack[--top];
        if (e.t > best) continue;
        const Node& node = nodes_[e.node];
        if (node.count > 0) {
            for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
                const Triangle& tri = triangles_[i];
                if (tri.face == skip) continue;
                const Vec3 p = cross(direction, tri.e2);
                const double det = dot(tri.e1, p);
                if (det == 0) continue;  // parallel to the plane (or grazing inside it)
                const double inv_det = 1.0 / det;
                const Vec3 s = sub(origin, tri.v0);
                const double u = dot(s, p) * inv_det;
                if (u < 0 || u > 1) continue;
                const Vec3 q = cross(s, tri.e1);
                const double v = dot(direction, q) * inv_det;
                if (v < 0 || u + v > 1) continue;
                const double t = dot(tri.e2, q) * inv_det;
                if (t > 0 && t < best) {
                    best = t;
                    // det = -direction . (e1 x e2): negative when the ray leaves through
                    // the face's front (normal) side.
                    hit = {tri.face, t, det < 0};
                }
            }
            continue;
        }
        const Node& a = nodes_[node.first];
        const Node& b = nodes_[node.first + 1];
        const double ta = ray.enter(a.box, best);
        const double tb = ray.enter(b.box, best);
        // The nearer child is popped first, so the farther one is often culled by `best`.
        if (ta >= 0 && tb >= 0) {
            const bool a_first = ta <= tb;
            stack[top++] = a_first ? Entry{node.first + 1, tb} : Entry{node.first, ta};
            stack[top++] = a_first ? Entry{node.first, ta} : Entry{node.first + 1, tb};
        } else if (ta >= 0) {
            stack[top++] = {node.first, ta};
        } else if (tb >= 0) {
            stack[top++] = {node.first + 1, tb};
        }
    }
    return hit;
}

}  // namespace terrain::field::detail
