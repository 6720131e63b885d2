#pragma once
// Private: a set of indices as one bit each, with the count of the members before each 64-bit
// word, so that a member's rank (the members below it) is one word's popcount away: a
// renumbering of a subset in 1/8 + 1/16 byte an index instead of 4. Not installed.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace terrain::detail {

class RankedBits {
  public:
    RankedBits() = default;
    explicit RankedBits(std::size_t n) : words_((n + 63) / 64, 0) {}

    void set(std::size_t i) { words_[i / 64] |= std::uint64_t{1} << (i % 64); }
    // The words themselves (to set bits on several threads, a word each or atomically).
    std::vector<std::uint64_t>& words() { return words_; }
    // Counts the members before each word: after the last set(), before rank().
    void count() {
        before_.assign(words_.size() + 1, 0);
        for (std::size_t w = 0; w < words_.size(); ++w)
            before_[w + 1] = before_[w] + static_cast<std::uint32_t>(std::popcount(words_[w]));
    }
    std::size_t members() const { return before_.empty() ? 0 : before_.back(); }
    bool test(std::size_t i) const { return (words_[i / 64] >> (i % 64)) & 1; }
    // The members below i (i's new number when i is a member).
    std::uint32_t rank(std::size_t i) const {
        const std::uint64_t lower = words_[i / 64] & ((std::uint64_t{1} << (i % 64)) - 1);
        return before_[i / 64] + static_cast<std::uint32_t>(std::popcount(lower));
    }
    void prefetch(std::size_t i) const {
        __builtin_prefetch(&words_[i / 64]);
        __builtin_prefetch(&before_[i / 64]);
    }

  private:
    std::vector<std::uint64_t> words_;
    std::vector<std::uint32_t> before_;
};

}  // namespace terrain::detail
