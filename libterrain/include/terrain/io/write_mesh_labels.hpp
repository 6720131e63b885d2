#pragma once
// The regions of a segmented mesh read from a file: labels.ply and faces.seg
// (docs/outputs.md). Like every writer of io/: atomic, refuses an existing file unless
// `overwrite`, throws one terrain::Error (stage "write") on failure, and writes the same bytes
// for the same input.

#include <cstdint>
#include <string>
#include <vector>

#include "terrain/mesh/triangle_mesh.hpp"

namespace terrain::io {

// labels.ply: io::write_ply's mesh with per-vertex `uint label` and `float <field_name>`.
void write_labels_ply(const TriangleMesh& mesh, const std::vector<float>& field,
                      const std::vector<std::uint32_t>& labels, const std::string& path,
                      bool overwrite, const std::string& field_name = "field");

// faces.seg: one region id per face, one per line, in face order (Princeton Segmentation
// Benchmark); a face takes the label most of its vertices have, ties to the lowest.
void write_faces_seg(const TriangleMesh& mesh, const std::vector<std::uint32_t>& labels,
                     const std::string& path, bool overwrite);
// The labels write_faces_seg writes.
std::vector<std::uint32_t> face_labels(const TriangleMesh& mesh,
                                       const std::vector<std::uint32_t>& labels);

}  // namespace terrain::io
