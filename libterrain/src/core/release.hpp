#pragma once
// Private: give a container's memory back. `v = {}` on a std::vector picks the
// initializer-list assignment, which empties it but keeps its capacity. Not installed.

namespace terrain::detail {

template <class Container>
void release(Container& c) {
    Container().swap(c);
}

}  // namespace terrain::detail
