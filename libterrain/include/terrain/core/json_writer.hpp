#pragma once
// A small streaming JSON writer: correct escaping, shortest round-trip numbers (so the same
// values always print the same bytes), NaN/Inf written as null, optional indentation.

#include <cstdint>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace terrain {

class JsonWriter {
  public:
    explicit JsonWriter(std::ostream& out, bool pretty = true) : out_(out), pretty_(pretty) {}

    JsonWriter& begin_object();
    JsonWriter& end_object();
    JsonWriter& begin_array();
    JsonWriter& end_array();
    JsonWriter& key(std::string_view name);  // inside an object, before each value

    JsonWriter& value(std::string_view text);
    JsonWriter& value(const char* text) { return value(std::string_view(text)); }
    JsonWriter& value(const std::string& text) { return value(std::string_view(text)); }
    JsonWriter& value(double number);
    JsonWriter& value(std::int64_t number);
    JsonWriter& value(int number) { return value(std::int64_t{number}); }
    JsonWriter& value(std::size_t number) { return value(static_cast<std::int64_t>(number)); }
    JsonWriter& value(bool flag);
    JsonWriter& null();
    JsonWriter& raw(std::string_view json);  // an already formatted JSON value

    template <class T>
    JsonWriter& field(std::string_view name, const T& v) {
        key(name);
        return value(v);
    }

    static std::string escape(std::string_view text);
    static std::string number(double v);  // shortest round-trip text, "null" if not finite

  private:
    void before_value();
    void newline();
    std::ostream& out_;
    bool pretty_;
    std::vector<bool> first_;  // per open container: no element written yet
    bool after_key_ = false;
};

}  // namespace terrain
