#pragma once
// How well the keyframe database recognises revisited places, against exact ground truth (issue
// 14's measure). Keyframes are taken in time order; each one queries a database of the keyframes
// before it, without the last `exclude_recent_s` seconds (those are the same place by continuity,
// not a recognition). Its true matches are those database keyframes whose camera centre lies
// within `max_distance_m` and whose viewing direction lies within `max_angle_deg`. The
// database's top candidate is accepted when its score reaches a threshold; sweeping the threshold
// gives the precision-recall curve, recall counted over the keyframes that have a true match. The
// score thresholded is DBoW2's normalised one: the top candidate's L1 score divided by the query's
// score with the sample just before it.
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "plslam/place/vocabulary.h"

namespace plslam::place {

struct PlaceSample {
  double timestamp = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();     // camera centre, world frame
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ(); // optical axis, world frame, unit
  cv::Mat descriptors;                                  // N x 32 CV_8U
};

struct RecognitionEvalOptions {
  double max_distance_m = 2.0;
  double max_angle_deg = 30.0;
  double exclude_recent_s = 2.0;
};

struct RecognitionQuery {
  std::size_t sample = 0;
  bool has_true_match = false;
  long top = -1;         // sample index of the top candidate, -1 when the database returned none
  double raw_score = 0;  // its L1 score
  double score = 0;      // normalised: raw_score / the L1 score of the query with the sample before it
  bool correct = false;  // the top candidate is a true match
  double top_distance_m = 0, top_angle_deg = 0;  // between the query's camera and the top candidate's
};

struct PrPoint {
  double threshold = 0;  // accept top candidates scoring at least this
  int accepted = 0, correct = 0;
  double precision = 1, recall = 0;
};

struct RecognitionEvalResult {
  std::vector<RecognitionQuery> queries;  // samples that had a database to query
  std::vector<std::size_t> ranked;        // indices into queries of the answered ones, best score first
  int with_true_match = 0;
  std::vector<PrPoint> curve;             // one point per distinct score, thresholds descending
  // The highest recall at a threshold whose precision is at least `precision` (0 if none).
  double recall_at_precision(double precision) const;
};

// Samples must be in time order.
RecognitionEvalResult evaluate_place_recognition(const std::vector<PlaceSample>& samples,
                                                 std::shared_ptr<const Vocabulary> vocabulary,
                                                 const RecognitionEvalOptions& options = {});

}  // namespace plslam::place
