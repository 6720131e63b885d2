#pragma once
// A bounding volume hierarchy over a mesh's triangles for first-hit ray queries (the SDF's
// ray caster): binned surface-area-heuristic build, Moeller-Trumbore intersection, all in
// double precision. Read-only after construction, so queries may run on many threads.

#include <array>
#include <cstdint>
#include <vector>

namespace terrain::field::detail {

using Vec3 = std::array<double, 3>;

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
    Vec3 lower() const { return nodes_.empty() ? Vec3{0, 0, 0} : nodes_[0].box[0]; }
    Vec3 upper() const { return nodes_.empty() ? Vec3{0, 0, 0} : nodes_[0].box[1]; }

    struct Node {
        std::array<Vec3, 2> box;  // lower and upper corner
        std::int32_t first = 0;   // leaf: first triangle; inner: the left child (right = +1)
        std::int32_t count = 0;   // leaf: number of triangles; 0 for an inner node
    };

  private:
    struct Triangle {
        Vec3 v0, e1, e2;  // corner and the two edges from it
        std::int32_t face;
    };
    std::vector<Node> nodes_;
    std::vector<Triangle> triangles_;  // in leaf order
};

}  // namespace terrain::field::detail
