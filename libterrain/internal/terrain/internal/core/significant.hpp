#pragma once
// Private: a number as text with a given count of significant digits (printf's %.Ng: no
// trailing zeros, an exponent only when it is shorter), for messages, plot labels and WKT.

#include <cstdio>
#include <string>

namespace terrain::detail {

inline std::string significant(double v, int digits) {
    char text[48];
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    return text;
}

}  // namespace terrain::detail
