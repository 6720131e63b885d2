#pragma once
// The names of an enumeration's values, read both ways from one table: how an option given as
// text at the edges (the command line, the Python module) becomes a value, and how a value is
// written back (run.json, the preview, messages). Each enumeration that an option takes keeps
// its table beside it (field::kFieldKindNames, segment::kGrowCostNames, ...).

#include <cstddef>
#include <optional>
#include <string_view>

namespace terrain {

template <class T>
struct Named {
    const char* name;
    T value;
};

// The value `name` names in `table`, or nothing.
template <class T, std::size_t N>
constexpr std::optional<T> value_named(const Named<T> (&table)[N], std::string_view name) {
    for (const auto& entry : table)
        if (name == entry.name) return entry.value;
    return std::nullopt;
}

// The name of `value` in `table` (the first that names it), or "" when none does.
template <class T, std::size_t N>
constexpr const char* name_of(const Named<T> (&table)[N], const T& value) {
    for (const auto& entry : table)
        if (entry.value == value) return entry.name;
    return "";
}

}  // namespace terrain
