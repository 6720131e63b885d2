#pragma once
// A Residency for tests (terrain/core/residency.hpp): records the stages an algorithm enters,
// runs the test's work on entering one, and takes stashed arrays away (empty until taken back,
// so that reading one while stashed would show).
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

#include "terrain/core/residency.hpp"

namespace terrain::test {

class RecordingResidency : public Residency {
  public:
    std::vector<Stage> entered;
    std::map<Stage, std::function<void()>> on_entry;
    // Called with each array taken back, after its values are put back (a test may spoil them).
    std::function<void(std::vector<std::int32_t>&)> on_take_back;
    std::size_t stashes = 0, taken_back = 0;
    std::vector<std::size_t> stashed_sizes;

    void enter(Stage stage, const ProgressFn& = {}) override {
        if (!entered.empty() && entered.back() == stage) return;
        entered.push_back(stage);
        if (auto it = on_entry.find(stage); it != on_entry.end()) it->second();
    }
    void stash(std::vector<std::int32_t>& v) override { keep(ints_, v); }
    void stash(std::vector<float>& v) override { keep(floats_, v); }
    void take_back(std::vector<std::int32_t>& v) override {
        give(ints_, v);
        if (on_take_back) on_take_back(v);
    }
    void take_back(std::vector<float>& v) override { give(floats_, v); }
    // Arrays stashed and not taken back.
    std::size_t away() const { return ints_.size() + floats_.size(); }

  private:
    template <class T>
    void keep(std::map<const void*, std::vector<T>>& aside, std::vector<T>& v) {
        ++stashes;
        stashed_sizes.push_back(v.size());
        aside[&v].swap(v);
    }
    template <class T>
    void give(std::map<const void*, std::vector<T>>& aside, std::vector<T>& v) {
        auto it = aside.find(&v);
        if (it == aside.end()) return;
        ++taken_back;
        v.swap(it->second);
        aside.erase(it);
    }
    std::map<const void*, std::vector<std::int32_t>> ints_;
    std::map<const void*, std::vector<float>> floats_;
};

}  // namespace terrain::test
