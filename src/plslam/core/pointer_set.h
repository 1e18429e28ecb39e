#pragma once
// A set of pointers for the deduplication loops that build local maps and BA windows: open
// addressing with linear probing in one flat array. std::unordered_set allocates a node per
// element; with tens of thousands of landmarks per frame that was 1.5 % of a street loop's CPU,
// on the tracking thread.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <vector>

namespace plslam::core {

class PointerSet {
 public:
  // Empties the set, with room for `expected` elements before it grows.
  void clear(std::size_t expected = 0) {
    const std::size_t capacity = std::bit_ceil(std::max<std::size_t>(16, 2 * expected));
    if (slots_.size() < capacity) slots_.resize(capacity);
    std::fill(slots_.begin(), slots_.end(), nullptr);
    size_ = 0;
  }

  // Empties the set and inserts `items` (pointers; nulls are skipped), with room for `extra` more.
  template <typename Range>
  void assign(const Range& items, std::size_t extra = 0) {
    clear(std::size(items) + extra);
    for (const auto* p : items) insert(p);
  }

  // True when `p` was not in the set yet. A null pointer is never inserted (returns false).
  bool insert(const void* p) {
    if (!p) return false;
    if (2 * (size_ + 1) > slots_.size()) grow();
    std::size_t i = slot_of(p);
    while (slots_[i]) {
      if (slots_[i] == p) return false;
      i = (i + 1) & (slots_.size() - 1);
    }
    slots_[i] = p;
    ++size_;
    return true;
  }

  bool contains(const void* p) const {
    if (!p || slots_.empty()) return false;
    for (std::size_t i = slot_of(p); slots_[i]; i = (i + 1) & (slots_.size() - 1))
      if (slots_[i] == p) return true;
    return false;
  }

  std::size_t size() const { return size_; }

 private:
  // Fibonacci hashing of the address: heap pointers share their low bits, so those are mixed in
  // by the multiplication and the top bits index the table.
  std::size_t slot_of(const void* p) const {
    const std::uint64_t h = static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(p)) * 0x9E3779B97F4A7C15ull;
    return static_cast<std::size_t>(h >> (64 - std::countr_zero(slots_.size())));
  }

  void grow() {
    std::vector<const void*> old = std::move(slots_);
    slots_.assign(std::max<std::size_t>(16, 2 * old.size()), nullptr);
    size_ = 0;
    for (const void* p : old)
      if (p) insert(p);
  }

  std::vector<const void*> slots_;
  std::size_t size_ = 0;
};

}  // namespace plslam::core
