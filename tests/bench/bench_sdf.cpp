// Benchmark: our Shape Diameter Function against plain CGAL::sdf_values (default options:
// 25 rays, 120 degree cone, post-processing) on closed meshes, in faces per second, with how
// far the two agree.
//   build/tests/bench/bench_sdf MESH.off...
// `./setup.sh bench` runs it on the CGAL sample meshes of Debian's libcgal-demo.
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <vector>

#include "bench_main.hpp"
#include "support/cgal_reference_sdf.hpp"
#include "terrain/field/sdf.hpp"
#include "terrain/io/mesh_files.hpp"

using namespace terrain;

namespace {

template <class F>
double seconds(F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

static int run_bench(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: bench_sdf MESH.off...\n");
        return 2;
    }
    const int threads = tbb::info::default_concurrency();
    std::printf(
        "bench_sdf: faces/s, ours on %d threads and on 1 (best of 3), CGAL (single-"
        "threaded, 1 run);\nface diameters compared, relative to the largest\n",
        threads);
    std::printf("%-12s %7s %10s %10s %10s %8s %11s %9s\n", "mesh", "faces", "ours", "ours 1t",
                "CGAL", "speed-up", "median diff", "faces >1%");
    double ours_total = 0, single_total = 0, cgal_total = 0;
    std::size_t faces_total = 0;
    for (int i = 1; i < argc; ++i) {
        const std::string name = std::filesystem::path(argv[i]).stem().string();
        try {
            const TriangleMesh mesh = io::read_mesh(argv[i]);
            field::SdfResult ours;
            auto best_of_3 = [&] {
                double best = 1e300;
                for (int run = 0; run < 3; ++run)
                    best = std::min(best,
                                    seconds([&] { ours = field::shape_diameter_function(mesh); }));
                return best;
            };
            double single = 0;
            {
                tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
                single = best_of_3();
            }
            const double best = best_of_3();
            std::vector<double> cgal;
            const double cgal_time =
                seconds([&] { cgal = test::cgal_sdf_face_diameters(mesh, field::SdfOptions{}); });
            // Agreement of the face diameters, relative to the largest.
            std::vector<double> diff(cgal.size());
            const double scale = *std::max_element(cgal.begin(), cgal.end());
            std::size_t off = 0;
            for (std::size_t f = 0; f < cgal.size(); ++f) {
                diff[f] = std::abs(ours.face_diameters[f] - cgal[f]) / scale;
                off += diff[f] > 0.01;
            }
            std::nth_element(diff.begin(), diff.begin() + diff.size() / 2, diff.end());
            const double faces = static_cast<double>(mesh.triangle_count());
            std::printf("%-12s %7zu %10.0f %10.0f %10.0f %7.1fx %11.1e %8.2f%%\n", name.c_str(),
                        mesh.triangle_count(), faces / best, faces / single, faces / cgal_time,
                        cgal_time / best, diff[diff.size() / 2], 100.0 * off / faces);
            std::fflush(stdout);
            ours_total += best;
            single_total += single;
            cgal_total += cgal_time;
            faces_total += mesh.triangle_count();
        } catch (const std::exception& e) {
            std::printf("%-12s skipped: %s\n", name.c_str(), e.what());
        }
    }
    if (faces_total > 0)
        std::printf("%-12s %7zu %10.0f %10.0f %10.0f %7.1fx\n", "all", faces_total,
                    faces_total / ours_total, faces_total / single_total, faces_total / cgal_total,
                    cgal_total / ours_total);
    return 0;
}

int main(int argc, char** argv) {
    return terrain::bench::bench_main(argc, argv,
                                      "bench_sdf MESH.off...: our Shape Diameter Function against "
                                      "CGAL's sdf_values on closed meshes.",
                                      run_bench);
}
