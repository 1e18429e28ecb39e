#include "plslam/loop/unmapped_keyframes.h"

namespace plslam::loop {

KeyFramesByMapping split_unmapped(const std::vector<map::KeyFrame*>& keyframes) {
  KeyFramesByMapping out;
  map::KeyFrame* latest_connected = nullptr;
  for (map::KeyFrame* kf : keyframes) {
    if (kf->is_bad()) continue;
    const bool unmapped = !kf->parent() && kf->covisibles().empty();
    if (unmapped && latest_connected) {
      out.unmapped.push_back({kf, latest_connected});
      continue;
    }
    out.connected.push_back(kf);
    if (!unmapped) latest_connected = kf;
  }
  return out;
}

}  // namespace plslam::loop
