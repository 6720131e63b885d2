#include <cpl_json.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <sstream>

#include "terrain/core/json_writer.hpp"

TEST_CASE("JsonWriter output parses back with the same values", "[json]") {
    std::ostringstream out;
    terrain::JsonWriter j(out);
    j.begin_object();
    j.field("name", "quote\" back\\slash\nnewline\x01");
    j.field("pi", 3.141592653589793).field("tiny", 1e-300).field("count", 42);
    j.field("flag", true).field("nan", std::numeric_limits<double>::quiet_NaN());
    j.key("list").begin_array().value(1).value(-0.0).value(0.1).end_array();
    j.key("empty").begin_object().end_object();
    j.end_object();

    CPLJSONDocument doc;
    REQUIRE(doc.LoadMemory(out.str()));
    const auto root = doc.GetRoot();
    CHECK(root.GetString("name") == "quote\" back\\slash\nnewline\x01");
    CHECK(root.GetDouble("pi") == 3.141592653589793);
    CHECK(root.GetDouble("tiny") == 1e-300);
    CHECK(root.GetInteger("count") == 42);
    CHECK(root.GetBool("flag"));
    CHECK(root.GetObj("nan").GetType() == CPLJSONObject::Type::Null);
    const auto list = root.GetArray("list");
    REQUIRE(list.Size() == 3);
    CHECK(list[2].ToDouble() == 0.1);
    CHECK(out.str().find("-0") == std::string::npos);
}

TEST_CASE("JsonWriter numbers are shortest round-trip text", "[json]") {
    CHECK(terrain::JsonWriter::number(0.1) == "0.1");
    CHECK(terrain::JsonWriter::number(1737400) == "1737400");
    CHECK(terrain::JsonWriter::number(std::numeric_limits<double>::infinity()) == "null");
}
