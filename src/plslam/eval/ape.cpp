#include "plslam/eval/ape.h"

#include <stdexcept>

namespace plslam::eval {

std::vector<double> ape_translation(const Trajectory& gt, const Trajectory& est) {
  if (gt.size() != est.size()) throw std::invalid_argument("ape_translation: unpaired trajectories");
  std::vector<double> err(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    err[i] = (est[i].T.translation() - gt[i].T.translation()).norm();
  }
  return err;
}

}  // namespace plslam::eval
