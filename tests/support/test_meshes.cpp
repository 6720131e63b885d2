#include "support/test_meshes.hpp"

#include <cmath>
#include <numbers>
#include <queue>
#include <random>

#include "terrain/geo/body.hpp"

namespace terrain::test {

Dem grid_dem(int w, int h, const std::function<double(int, int)>& height) {
    Dem dem;
    dem.width = w;
    dem.height = h;
    dem.body = geo::body_from_crs("");
    dem.values.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) dem.values[dem.index(c, r)] = height(c, r);
    return dem;
}

TriangleMesh make_mesh(const std::vector<std::array<double, 3>>& points,
                       const std::vector<std::array<std::int32_t, 3>>& triangles) {
    TriangleMesh mesh;
    set_positions(mesh, points);
    mesh.edit_triangles() = triangles;
    finish_mesh(mesh);
    return mesh;
}

TriangleMesh torus_mesh(double R, double r, int nu, int nv, bool upright) {
    std::vector<std::array<double, 3>> pts;
    std::vector<std::array<std::int32_t, 3>> tris;
    auto id = [&](int i, int j) { return static_cast<std::int32_t>((i % nu) * nv + (j % nv)); };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const double u = 2 * std::numbers::pi * i / nu, v = 2 * std::numbers::pi * j / nv;
            const double ring = R + r * std::cos(v);
            if (upright)  // axis along y: the wheel stands on the xz plane
                pts.push_back({ring * std::cos(u), r * std::sin(v), ring * std::sin(u)});
            else
                pts.push_back({ring * std::cos(u), ring * std::sin(u), r * std::sin(v)});
        }
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return make_mesh(pts, tris);
}

TriangleMesh plate_mesh(int w, int h, int holes) {
    // Holes: 2x2 cells, centred on the middle row, evenly spaced along x.
    auto solid = [&](int i, int j) {
        if (i < 0 || j < 0 || i >= w || j >= h) return false;
        for (int k = 0; k < holes; ++k) {
            const int hx = (k + 1) * w / (holes + 1) - 1, hy = h / 2 - 1;
            if (i >= hx && i < hx + 2 && j >= hy && j < hy + 2) return false;
        }
        return true;
    };
    std::vector<std::int32_t> top((w + 1) * (h + 1), -1), bottom((w + 1) * (h + 1), -1);
    std::vector<std::array<double, 3>> pts;
    auto vid = [&](std::vector<std::int32_t>& layer, int i, int j, double zz) {
        auto& slot = layer[static_cast<std::size_t>(j * (w + 1) + i)];
        if (slot < 0) {
            slot = static_cast<std::int32_t>(pts.size());
            pts.push_back({double(i), double(j), zz});
        }
        return slot;
    };
    std::vector<std::array<std::int32_t, 3>> tris;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            if (!solid(i, j)) continue;
            const int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
            std::int32_t t[4], b[4];
            for (int k = 0; k < 4; ++k) {
                t[k] = vid(top, ci[k], cj[k], 0.5);
                b[k] = vid(bottom, ci[k], cj[k], -0.5);
            }
            tris.push_back({t[0], t[1], t[2]});
            tris.push_back({t[0], t[2], t[3]});
            tris.push_back({b[0], b[2], b[1]});
            tris.push_back({b[0], b[3], b[2]});
            // Walls where the neighbour across a side is not solid; side k runs corner k -> k+1.
            const int ni[4] = {i, i + 1, i, i - 1}, nj[4] = {j - 1, j, j + 1, j};
            for (int k = 0; k < 4; ++k) {
                if (solid(ni[k], nj[k])) continue;
                const int p = k, q = (k + 1) % 4;
                tris.push_back({t[q], t[p], b[p]});
                tris.push_back({t[q], b[p], b[q]});
            }
        }
    return make_mesh(pts, tris);
}

TriangleMesh permute_mesh(const TriangleMesh& mesh, const std::vector<std::int32_t>& perm) {
    std::vector<std::array<double, 3>> pts(mesh.vertex_count());
    for (std::size_t v = 0; v < pts.size(); ++v)
        pts[static_cast<std::size_t>(perm[v])] = mesh.position(v);
    std::vector<std::array<std::int32_t, 3>> tris;
    for (std::size_t t = mesh.triangle_count(); t-- > 0;) {
        const auto& tr = mesh.triangles()[t];
        const std::size_t k = t % 3;  // rotate the corners, keeping the orientation
        tris.push_back({perm[static_cast<std::size_t>(tr[k])],
                        perm[static_cast<std::size_t>(tr[(k + 1) % 3])],
                        perm[static_cast<std::size_t>(tr[(k + 2) % 3])]});
    }
    return make_mesh(pts, tris);
}

std::vector<float> permute_field(const std::vector<float>& field,
                                 const std::vector<std::int32_t>& perm) {
    std::vector<float> out(field.size());
    for (std::size_t v = 0; v < field.size(); ++v)
        out[static_cast<std::size_t>(perm[v])] = field[v];
    return out;
}

std::vector<float> noise_field(std::size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<float> out(n);
    for (auto& x : out) x = static_cast<float>(rng() % 1000000u) * 1e-4f;
    return out;
}

std::vector<int> region_pieces(const TriangleMesh& mesh, const std::vector<std::uint32_t>& labels,
                               std::uint32_t count) {
    std::vector<int> pieces(count, 0);
    std::vector<char> seen(mesh.vertex_count(), 0);
    for (std::size_t v0 = 0; v0 < mesh.vertex_count(); ++v0) {
        if (seen[v0]) continue;
        ++pieces[labels[v0] - 1];
        std::queue<std::size_t> q;
        q.push(v0);
        seen[v0] = 1;
        while (!q.empty()) {
            const auto v = q.front();
            q.pop();
            for (const auto nb : mesh.neighbors_of(v)) {
                const auto w = static_cast<std::size_t>(nb);
                if (!seen[w] && labels[w] == labels[v]) {
                    seen[w] = 1;
                    q.push(w);
                }
            }
        }
    }
    return pieces;
}

}  // namespace terrain::test
