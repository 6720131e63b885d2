// Names read both ways from one table (terrain/core/names.hpp).
#include <catch2/catch.hpp>

#include <string>

#include "terrain/core/names.hpp"

namespace {

enum class Colour { red, green, blue };

constexpr terrain::Named<Colour> kColours[] = {
    {"red", Colour::red},
    {"green", Colour::green},
    {"vert", Colour::green},  // a second name: read, never written
};

}  // namespace

TEST_CASE("value_named and name_of read a table both ways", "[core][names]") {
    using terrain::name_of;
    using terrain::value_named;
    CHECK(value_named(kColours, "red") == Colour::red);
    CHECK(value_named(kColours, "green") == Colour::green);
    CHECK(value_named(kColours, "vert") == Colour::green);
    CHECK_FALSE(value_named(kColours, "Red"));  // names are matched exactly
    CHECK_FALSE(value_named(kColours, ""));
    CHECK_FALSE(value_named(kColours, "red "));
    CHECK(std::string(name_of(kColours, Colour::red)) == "red");
    CHECK(std::string(name_of(kColours, Colour::green)) == "green");  // the first name
    CHECK(std::string(name_of(kColours, Colour::blue)).empty());      // not in the table
    static_assert(*value_named(kColours, "vert") == Colour::green);
}
