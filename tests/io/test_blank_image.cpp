// A uniform image is reported as blank (with the file named); any texture, even one pixel, is not.
#include <gtest/gtest.h>

#include "plslam/io/image_loading.h"

namespace plslam::io {
namespace {

TEST(BlankImage, UniformImageIsReportedWithItsFile) {
  const cv::Mat grey(370, 1226, CV_8U, cv::Scalar(128));
  const auto problem = blank_image_problem(grey, "seq/image_0/000006.png");
  EXPECT_EQ(problem, "seq/image_0/000006.png: blank image (every pixel is 128)");
  EXPECT_FALSE(blank_image_problem(cv::Mat::zeros(10, 10, CV_8U), "z.png").empty());
}

TEST(BlankImage, OneDifferentPixelIsNotBlank) {
  cv::Mat img(370, 1226, CV_8U, cv::Scalar(0));
  img.at<unsigned char>(369, 1225) = 1;
  EXPECT_TRUE(blank_image_problem(img, "x.png").empty());
}

}  // namespace
}  // namespace plslam::io
