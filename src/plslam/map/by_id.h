#pragma once
// Ordered containers of map objects keyed by id, never by address. Addresses change from run to
// run (allocator state, other threads), so iterating a pointer-ordered std::map would make
// sums, tie-breaks and "the first observation" differ between identical runs.
#include <map>
#include <set>

namespace plslam::map {

struct ById {
  template <class T>
  bool operator()(const T* a, const T* b) const { return a->id() < b->id(); }
};

template <class T, class V>
using IdMap = std::map<T*, V, ById>;
template <class T>
using IdSet = std::set<T*, ById>;

}  // namespace plslam::map
