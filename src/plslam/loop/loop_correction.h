#pragma once
// Loop correction (ORB-SLAM2's LoopClosing::CorrectLoop, in SE(3), with lines): the verified
// relative pose moves the query keyframe's neighbourhood onto the place it recognised, with its
// map points and lines; the landmarks of the recognised place are fused with their duplicates on
// the query side; the new connections become loop edges; the essential graph spreads the loop
// error over the rest of the map, and every other landmark moves with the keyframe it is anchored to.
#include "plslam/loop/essential_graph.h"
#include "plslam/loop/loop_verifier.h"
#include "plslam/loop/unmapped_keyframes.h"
#include "plslam/map/map.h"
#include "plslam/mapping/keyframe_projection.h"

namespace plslam::loop {

struct LoopCorrectionOptions {
  EssentialGraphOptions graph;
  // Search radius of the fusion (ORB-SLAM2's SearchAndFuse uses 4 px at the predicted level).
  mapping::ProjectionMatchOptions fusion{.point_radius = 4.0};
  bool lines = true;
};

struct LoopCorrectionResult {
  int neighbourhood = 0;   // keyframes moved by the verified pose before the graph optimisation
  int fused_points = 0;    // duplicates replaced by the recognised place's points
  int added_points = 0;    // new observations of the place's points on the query side
  int fused_lines = 0;
  int added_lines = 0;
  int loop_connections = 0;  // new keyframe pairs across the loop
  int unmapped_keyframes = 0;  // still in local mapping's queue: moved with their anchor
  EssentialGraphResult graph;
};

// Call with local mapping paused and the map's update lock held: tracking must not see the map
// between the first pose written and the last landmark moved.
LoopCorrectionResult correct_loop(map::Map& map, const LoopConstraint& loop, const LoopCorrectionOptions& options = {});

// correct_loop in three steps, for the deterministic pipeline, where the essential graph is solved
// beside tracking and local mapping. The first moves the query's neighbourhood onto the place,
// fuses and connects (map lock held); the second is the solver alone, reading only the plan's
// problem; the third moves the rest of the map (map lock held). Between the first and the third,
// local mapping may have moved keyframes of the graph (each then keeps its local change on top of
// the optimised pose) and added keyframes and landmarks (each moves with the keyframe it was made
// from). Landmarks and keyframes the plan holds must stay allocated until the third step.
struct LoopCorrectionPlan {
  EssentialGraphInput graph;
  EssentialGraphProblem problem;
  std::vector<UnmappedKeyFrame> unmapped;
  map::IdMap<map::MapPoint, map::KeyFrame*> point_corrected_by;
  map::IdMap<map::MapLine, map::KeyFrame*> line_corrected_by;
  LoopCorrectionResult result;  // the counts of the first step
};
LoopCorrectionPlan begin_loop_correction(map::Map& map, const LoopConstraint& loop, const LoopCorrectionOptions& options = {});
// Returns plan.result with the graph's result; unusable: the map keeps the first step's edits.
LoopCorrectionResult finish_loop_correction(map::Map& map, LoopCorrectionPlan& plan, EssentialGraphResult graph);

}  // namespace plslam::loop
