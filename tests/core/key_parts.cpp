// A serial scatter made parallel by parts of the keys (core/key_parts.hpp): the same writes, in
// the same order at each place, as the serial pass, at one thread and at several.

#include <tbb/global_control.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <random>
#include <vector>

#include "terrain/internal/core/key_parts.hpp"

namespace {

// Items grouped by key (count_by_key_parts, place_by_key_parts): each key's items listed in
// the order seen.
std::vector<std::int32_t> grouped(const std::vector<std::int64_t>& keys, std::size_t buckets,
                                  std::vector<std::int32_t>& offsets) {
    const terrain::ProgressFn none;
    const terrain::detail::PassProgress pass(none, 0, 1, "test");
    const auto key = [&](std::size_t i) { return keys[i]; };
    offsets.assign(buckets + 1, 0);
    terrain::detail::count_by_key_parts(keys.size(), offsets, pass, key);
    std::vector<std::int32_t> items(static_cast<std::size_t>(offsets.back()), -1);
    terrain::detail::place_by_key_parts(
        keys.size(), offsets, pass, key,
        [&](std::size_t i, std::size_t slot) { items[slot] = static_cast<std::int32_t>(i); });
    return items;
}

}  // namespace

TEST_CASE("A scatter by parts of the keys writes what the serial pass writes, in its order",
          "[core]") {
    // More items than one chunk (2^22) and than the smallest parted pass, skipped items (-1),
    // keys crowded at both ends of their range (the parts' edges) and buckets left empty.
    std::mt19937_64 random(42);
    const std::size_t n = (std::size_t{1} << 22) + 12345, buckets = 1000003;
    std::vector<std::int64_t> keys(n);
    for (std::size_t i = 0; i < n; ++i) {
        const auto r = random() % 10;
        keys[i] = r == 0   ? -1
                  : r == 1 ? static_cast<std::int64_t>(random() % 3)
                  : r == 2 ? static_cast<std::int64_t>(buckets - 1 - random() % 3)
                           : static_cast<std::int64_t>(random() % (buckets / 2) * 2);
    }
    // The serial pass.
    std::vector<std::int32_t> serial_offsets(buckets + 1, 0);
    for (const auto k : keys)
        if (k >= 0) ++serial_offsets[static_cast<std::size_t>(k) + 1];
    for (std::size_t k = 0; k < buckets; ++k) serial_offsets[k + 1] += serial_offsets[k];
    std::vector<std::int32_t> fill(serial_offsets.begin(), serial_offsets.end() - 1);
    std::vector<std::int32_t> serial(static_cast<std::size_t>(serial_offsets.back()));
    for (std::size_t i = 0; i < n; ++i)
        if (keys[i] >= 0)
            serial[static_cast<std::size_t>(fill[static_cast<std::size_t>(keys[i])]++)] =
                static_cast<std::int32_t>(i);
    REQUIRE(serial_offsets[1] > 0);                       // the first key used
    REQUIRE(serial_offsets[4] - serial_offsets[3] == 0);  // an odd key: empty
    for (const int threads : {1, 2, 3}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                  static_cast<std::size_t>(threads));
        std::vector<std::int32_t> offsets;
        const auto items = grouped(keys, buckets, offsets);
        CHECK(offsets == serial_offsets);
        CHECK(items == serial);
    }
}
