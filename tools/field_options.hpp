#pragma once
// The field options shared by `field`, `reeb`, `segment` and `sweep`.

#include <string>

#include "cli.hpp"
#include "terrain/field/vertex_field.hpp"

namespace terrain::cli {

struct FieldOptionValues {
    std::string name = "shape-index";
    field::FieldOptions options;
};

// Adds --field, --rings, --radius bound to `values`.
void add_field_options(po::options_description& options, FieldOptionValues& values);

// The library's options from the parsed values; throws UsageError for contradictions.
field::FieldOptions to_field_options(const FieldOptionValues& values, const po::variables_map& vm);

}  // namespace terrain::cli
