#include "plslam/place/descriptor256.h"

#include <stdexcept>

namespace plslam::place {

std::vector<Descriptor256> descriptors_from_mat(const cv::Mat& descriptors) {
  if (descriptors.empty()) return {};
  if (descriptors.type() != CV_8UC1 || descriptors.cols != 32) {
    throw std::invalid_argument("descriptors_from_mat: expected N x 32 CV_8U descriptors");
  }
  std::vector<Descriptor256> out(static_cast<std::size_t>(descriptors.rows));
  for (int r = 0; r < descriptors.rows; ++r) out[static_cast<std::size_t>(r)] = descriptor_from_row(descriptors, r);
  return out;
}

}  // namespace plslam::place
