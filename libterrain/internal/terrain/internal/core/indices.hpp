#pragma once
// Private: the 32-bit indices of the graph code (vertices, nodes, arcs, triangles) and their
// conversion to std::size_t for subscripts. Not installed.

#include <cstddef>
#include <cstdint>

namespace terrain::detail {

using i32 = std::int32_t;
inline constexpr i32 kNone = -1;  // no vertex, node, arc or triangle

// A 32-bit index as a subscript: v[idx(i)].
inline std::size_t idx(i32 i) {
    return static_cast<std::size_t>(i);
}

}  // namespace terrain::detail
