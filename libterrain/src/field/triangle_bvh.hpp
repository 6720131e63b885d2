#pragma once
// A bounding volume hierarchy over a mesh's triangles for first-hit ray queries (the SDF's
// ray caster): a binary tree built with the binned surface-area heuristic, collapsed into a
// 4-wide tree whose four child boxes are tested together (float, conservatively rounded);
// Moeller-Trumbore intersection in double precision.
// Corners are stored as floats: the callers' points must be floats widened to double. Read-only
// after construction, so queries may run on many threads.

#include <array>
#include <cstdint>
#include <vector>

namespace terrain::field::detail {

using Vec3 = std::array<double, 3>;

inline Vec3 sub(const Vec3& a, const Vec3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

class TriangleBvh {
  public:
    // Builds over the triangles `faces` (indices into `triangles`, whose corners index
    // `points`); hits report those face indices.
    TriangleBvh(const std::vector<Vec3>& points,
                const std::vector<std::array<std::int32_t, 3>>& triangles,
                const std::vector<std::int32_t>& faces);

    struct Hit {
        std::int32_t face = -1;  // -1: nothing hit
        double t = 0;            // distance along the ray in units of |direction|
        // The ray leaves the volume through the face: it meets the face's back side (the
        // face is counter-clockwise seen from the side its normal points to).
        bool exits = false;
    };

    // The nearest triangle other than `skip` met by origin + t * direction, 0 < t <= t_max.
    // Triangles the ray only grazes in their plane are not hits.
    Hit first_hit(const Vec3& origin, const Vec3& direction, double t_max, std::int32_t skip) const;

    // Corners of the box around all the triangles.
    Vec3 lower() const { return lower_; }
    Vec3 upper() const { return upper_; }

    // Four children, their boxes as [axis][lower, upper][child] for one SIMD-friendly test.
    struct Node {
        std::array<std::array<std::array<float, 4>, 2>, 3> bounds;
        std::array<std::int32_t, 4> child;  // inner: a node; leaf: its first triangle; -1: none
        std::array<std::int32_t, 4> count;  // leaf: its number of triangles; 0: an inner node
    };
    // The corners as floats (the mesh's own precision: exact, and half the memory of
    // doubles); edges are formed in double when tested.
    struct Triangle {
        std::array<float, 9> corners;
        std::int32_t face;
    };

  private:
    std::vector<Node> nodes_;
    std::vector<Triangle> triangles_;  // in leaf order
    Vec3 lower_{0, 0, 0}, upper_{0, 0, 0};
};

}  // namespace terrain::field::detail
