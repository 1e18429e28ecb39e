// Tracks a recorded stereo sequence with plslam's public API and writes the trajectory.
//   embed <sequence folder> <trajectory.tum>
// Prints one summary line: frames, tracked frames, keyframes, loops and, when the sequence has
// ground truth, the ATE.
#include <cstdio>
#include <exception>
#include <fstream>
#include <iomanip>

#include <Eigen/Geometry>
#include <plslam/plslam.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <sequence folder> <trajectory.tum>\n", argv[0]);
    return 2;
  }
  try {
    const plslam::Sequence sequence(argv[1]);
    plslam::SlamOptions options;
    options.preset = sequence.preset();
    options.sequential = true;  // the same poses on every run
    plslam::Slam slam(sequence.calibration(), options);

    for (std::size_t i = 0; i < sequence.size(); ++i) {
      const auto images = sequence.frame(i);
      const auto f = slam.track(images.left, images.right, images.timestamp);
      if (f.new_map_segment) std::fprintf(stderr, "frame %zu: lost, a new map segment starts\n", i);
    }
    slam.shutdown();  // local mapping and loop closing finish: the poses are final

    const auto trajectory = slam.trajectory();
    std::ofstream out(argv[2]);
    out << std::setprecision(9);
    for (const auto& p : trajectory) {
      const Eigen::Quaterniond q(p.T.rotation());
      const Eigen::Vector3d t = p.T.translation();
      out << p.t << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z()
          << ' ' << q.w() << '\n';
    }
    if (!out.flush()) {
      std::fprintf(stderr, "%s: cannot write\n", argv[2]);
      return 1;
    }

    const auto stats = slam.stats();
    std::printf("frames %ld tracked %ld keyframes %zu points %zu lines %zu loops %ld", stats.frames, stats.tracked,
                stats.keyframes, stats.points, stats.lines, stats.loops);
    if (const auto* gt = sequence.ground_truth()) {
      const auto errors = plslam::evaluate_trajectory(*gt, trajectory);
      std::printf(" ate_rmse_m %.6f", errors.ate_rmse_m);
    }
    std::printf("\n");
    return stats.tracked == stats.frames ? 0 : 3;
  } catch (const plslam::InputError& e) {
    std::fprintf(stderr, "embed: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "embed: internal error: %s\n", e.what());
    return 1;
  }
}
