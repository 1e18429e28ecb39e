#include "plslam/map/map_snapshot.h"

#include <mutex>

namespace plslam::map {

MapSnapshot take_snapshot(const Map& map) {
  const auto hold = map.hold_objects();  // nothing is freed while the points are read
  std::lock_guard lock(map.update_mutex());
  MapSnapshot s;
  s.changes = map.changes();
  for (const auto* kf : map.keyframes()) {
    KeyframeSnapshot k;
    k.id = kf->id();
    k.timestamp = kf->timestamp();
    k.T_wc = kf->pose_inverse();
    if (const auto* parent = kf->parent()) k.parent = parent->id();
    for (const auto* other : kf->loop_edges()) k.loop_edges.push_back(other->id());
    for (const auto* other : kf->covisibles()) {
      // A connection erased between the two calls weighs 0: the edge is gone.
      if (const int w = kf->weight(other); w > 0) k.covisibility.emplace_back(other->id(), w);
    }
    s.keyframes.push_back(std::move(k));
  }
  for (const auto* p : map.points()) s.points.push_back({p->id(), p->position()});
  for (const auto* l : map.lines()) s.lines.push_back({l->id(), l->start(), l->end()});
  return s;
}

}  // namespace plslam::map
