#include "plslam/loop/unmapped_keyframes.h"

namespace plslam::loop {

bool is_unmapped(const map::KeyFrame& kf) { return !kf.is_bad() && !kf.parent() && kf.covisibles().empty(); }

std::vector<UnmappedKeyFrame> unmapped_keyframes(const std::vector<map::KeyFrame*>& keyframes) {
  std::vector<UnmappedKeyFrame> out;
  map::KeyFrame* latest_connected = nullptr;
  for (map::KeyFrame* kf : keyframes) {
    if (kf->is_bad()) continue;
    if (!is_unmapped(*kf)) {
      latest_connected = kf;
    } else if (latest_connected) {
      out.push_back({kf, latest_connected});
    }
  }
  return out;
}

}  // namespace plslam::loop
