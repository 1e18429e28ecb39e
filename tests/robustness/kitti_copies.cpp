#include "robustness/kitti_copies.h"

#include <fstream>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

namespace plslam::test {

namespace fs = std::filesystem;

fs::path make_copy(const fs::path& data, const fs::path& root, const std::vector<int>& frames,
                   const std::map<std::size_t, Damage>& damage, const std::string& id, bool times_at_10hz) {
  const fs::path src = data / "kitti" / "sequences" / id;
  const fs::path seq = root / "sequences" / id;
  fs::create_directories(seq / "image_0");
  fs::create_directories(seq / "image_1");
  fs::create_directories(root / "poses");
  fs::create_symlink(src / "calib.txt", seq / "calib.txt");
  std::vector<std::string> times, poses;
  {
    std::ifstream t(src / "times.txt"), p(data / "kitti" / "poses" / (id + ".txt"));
    for (std::string l; std::getline(t, l);) times.push_back(l);
    for (std::string l; std::getline(p, l);) poses.push_back(l);
  }
  // KITTI 01 has no times.txt: 10 Hz by index, as the reader assumes.
  if (times.empty()) {
    for (std::size_t i = 0; i < poses.size(); ++i) times.push_back(fmt::format("{:e}", 0.1 * static_cast<double>(i)));
  }
  const cv::Mat black = cv::Mat::zeros(cv::imread((src / "image_0" / "000000.png").string(), cv::IMREAD_GRAYSCALE).size(), CV_8U);
  std::ofstream times_out(seq / "times.txt"), poses_out(root / "poses" / (id + ".txt"));
  int last_source = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::string name = fmt::format("{:06d}.png", i);
    const std::string time = times_at_10hz ? fmt::format("{:e}", 0.1 * static_cast<double>(i)) : "";
    if (frames[i] < 0) {
      cv::imwrite((seq / "image_0" / name).string(), black);
      cv::imwrite((seq / "image_1" / name).string(), black);
      times_out << (times_at_10hz ? time : times.at(static_cast<std::size_t>(last_source))) << "\n";
      poses_out << poses.at(static_cast<std::size_t>(last_source)) << "\n";
      continue;
    }
    last_source = frames[i];
    const std::string src_name = fmt::format("{:06d}.png", frames[i]);
    const auto it = damage.find(i);
    const Damage d = it == damage.end() ? Damage::kNone : it->second;
    if (d == Damage::kEmptyFile) {
      std::ofstream(seq / "image_0" / name);
    } else if (d == Damage::kBlank) {
      const cv::Mat img = cv::imread((src / "image_0" / src_name).string(), cv::IMREAD_GRAYSCALE);
      cv::imwrite((seq / "image_0" / name).string(), cv::Mat(img.size(), CV_8U, cv::Scalar(128)));
    } else {
      fs::create_symlink(src / "image_0" / src_name, seq / "image_0" / name);
    }
    fs::create_symlink(src / "image_1" / src_name, seq / "image_1" / name);
    times_out << (times_at_10hz ? time : times.at(static_cast<std::size_t>(frames[i]))) << "\n";
    poses_out << poses.at(static_cast<std::size_t>(frames[i])) << "\n";
  }
  return seq;
}

std::vector<int> range(int from, int to, int step) {
  std::vector<int> v;
  for (int i = from; i < to; i += step) v.push_back(i);
  return v;
}

Run run(const fs::path& seq, const fs::path& out, const std::string& extra) {
  Run r;
  r.out = out;
  r.cli = run_cli("run \"" + seq.string() + "\" --out \"" + out.string() + "\" --quiet --sequential " + extra);
  if (fs::exists(out / "stats.json")) {
    std::ifstream in(out / "stats.json");
    r.stats = nlohmann::json::parse(in);
  }
  return r;
}

}  // namespace plslam::test
