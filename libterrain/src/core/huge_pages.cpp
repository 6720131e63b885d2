// Transparent huge pages: what the kernel offers and what this process asked for.

#include "terrain/core/huge_pages.hpp"

#include <cstdlib>
#include <fstream>

namespace terrain {

namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";

}  // namespace

std::string transparent_huge_page_mode() {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    if (!std::getline(in, line)) return "";
    // "always [madvise] never": the mode in brackets.
    const auto open = line.find('['), close = line.find(']');
    if (open == std::string::npos || close == std::string::npos || close < open) return "";
    return line.substr(open + 1, close - open - 1);
}

std::string huge_page_use() {
    const std::string mode = transparent_huge_page_mode();
    if (mode == "always") return "huge";
    if (mode != "madvise") return "normal";
    const char* tunables = std::getenv("GLIBC_TUNABLES");
    const std::string t = tunables ? tunables : "";
    // glibc.malloc.hugetlb=1 (madvise) or =2 (reserved huge pages); 0 asks for none.
    const std::string key = std::string(kTunable) + "=";
    const auto at = t.find(key);
    if (at == std::string::npos) return "normal";
    const auto value = at + key.size();
    return value < t.size() && (t[value] == '1' || t[value] == '2') ? "huge" : "normal";
}

std::string tunables_with_huge_pages(const std::string& current) {
    if (current.find(kTunable) != std::string::npos) return "";
    const std::string setting = std::string(kTunable) + "=1";
    return current.empty() ? setting : current + ":" + setting;
}

}  // namespace terrain
