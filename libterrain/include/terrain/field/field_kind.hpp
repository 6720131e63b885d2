#pragma once
// The scalar fields the Reeb graph can be built on, and their names (--field, run.json).

#include <string>

#include "terrain/core/names.hpp"

namespace terrain::field {

enum class FieldKind { shape_index, sdf, height };

inline constexpr Named<FieldKind> kFieldKindNames[] = {
    {"shape-index", FieldKind::shape_index},
    {"sdf", FieldKind::sdf},
    {"height", FieldKind::height},
};

// "shape-index", "sdf" or "height"; throws terrain::Error (stage "field") for anything else.
FieldKind parse_field_kind(const std::string& name);
const char* to_string(FieldKind kind);

}  // namespace terrain::field
