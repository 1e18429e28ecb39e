// `plslam vocab train` on the real excerpts: a reproducible file that loads, whose bags of words
// rank a neighbouring frame of KITTI 06 above a frame 30 m away, and bad usage refused.
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "plslam/core/error.h"
#include "plslam/features/orb_extractor.h"
#include "plslam/io/dataset.h"
#include "plslam/place/vocabulary.h"
#include "support/test_support.h"

namespace plslam::place {
namespace {

namespace fs = std::filesystem;

TEST(VocabCli, TrainsAReproducibleVocabularyThatRecognisesANeighbouringFrame) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const auto kitti = data / "kitti/sequences/06", euroc = data / "euroc/V1_01_easy_micro";
  const std::string args = "vocab train \"" + kitti.string() + "\" \"" + euroc.string() +
                           "\" --k 6 --levels 3 --max-images 30 --seed 4 --out ";
  const auto a = test::run_cli(args + "\"" + (tmp.path() / "a.voc").string() + "\"");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_NE(a.out.find("words"), std::string::npos) << a.out;
  EXPECT_NE(a.err.find("ETA"), std::string::npos) << "no progress: " << a.err;
  const auto b = test::run_cli(args + "\"" + (tmp.path() / "b.voc").string() + "\"");
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(test::read_file(tmp.path() / "a.voc"), test::read_file(tmp.path() / "b.voc")) << "same seed, different vocabulary";

  const Vocabulary voc = Vocabulary::load(tmp.path() / "a.voc");
  EXPECT_EQ(voc.k(), 6);
  EXPECT_GT(voc.size(), 100u);
  EXPECT_LE(voc.size(), 216u);
  const auto ds = io::open_dataset(kitti);
  const features::OrbExtractor ex(features::OrbOptions::kitti());
  auto bow = [&](std::size_t i) { return voc.transform(ex.extract(ds->load(i).left).descriptors); };
  const BowVector f10 = bow(10), f11 = bow(11), f40 = bow(40);
  const double neighbour = l1_score(f10, f11), far = l1_score(f10, f40);
  EXPECT_GT(neighbour, far) << "frame 11: " << neighbour << ", frame 40: " << far;
}

TEST(VocabCli, BadUsageIsRefused) {
  test::TempDir tmp;
  const std::string out = " --out \"" + (tmp.path() / "v.voc").string() + "\"";
  EXPECT_EQ(test::run_cli("vocab train /nonexistent" + out).exit_code, 2);
  EXPECT_EQ(test::run_cli("vocab train /tmp --k 1" + out).exit_code, 2);
  EXPECT_EQ(test::run_cli("vocab train /tmp --levels 0" + out).exit_code, 2);
  EXPECT_EQ(test::run_cli("vocab train /tmp --max-images -1" + out).exit_code, 2);
  EXPECT_EQ(test::run_cli("vocab train /tmp --k 100 --levels 5" + out).exit_code, 2);  // 10^10 words
  EXPECT_FALSE(fs::exists(tmp.path() / "v.voc"));
  const auto refused = test::run_cli("vocab train /tmp --k 100 --levels 5" + out);
  EXPECT_NE(refused.err.find("more than 2^24"), std::string::npos) << refused.err;
}

TEST(VocabCli, DamagedVocabularyFileIsRefusedByName) {
  test::TempDir tmp;
  std::ofstream(tmp.path() / "junk.voc") << "not a vocabulary at all, but long enough for a header";
  try {
    Vocabulary::load(tmp.path() / "junk.voc");
    FAIL() << "accepted junk";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.voc"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Vocabulary::load(tmp.path() / "missing.voc"), InputError);
  EXPECT_THROW(Vocabulary::load(tmp.path()), InputError);
}

}  // namespace
}  // namespace plslam::place

namespace plslam::place {
namespace {

// vocab eval on the KITTI 06 excerpt: it never revisits a place (every query is a non-revisit),
// and the JSON says so; a dataset without ground truth cannot be scored.
TEST(VocabCli, EvalReportsThePrecisionRecallOfADataset) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto seq = data / "kitti" / "sequences" / "06";
  const auto r = test::run_cli("vocab eval \"" + seq.string() + "\" --every 5 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["keyframes"], 11);
  EXPECT_EQ(j["every"], 5);
  // 10 m between keyframes 5 frames apart: nothing within 2 m over 2 s earlier.
  EXPECT_EQ(j["queries_with_true_match"], 0);
  EXPECT_EQ(j["recall_at_precision"], 0.0);
  EXPECT_GT(j["queries"].get<int>(), 0);
  EXPECT_TRUE(j["curve"].is_array());
  // Every answered query, best score first, each false (no revisit here) and so, by the
  // definition, more than 2 m or 30 degrees from its top candidate, which is an earlier frame.
  const auto& answers = j["answers"];
  ASSERT_TRUE(answers.is_array());
  EXPECT_EQ(answers.size(), j["curve"].back()["accepted"].get<std::size_t>());
  for (std::size_t i = 0; i < answers.size(); ++i) {
    const auto& a = answers[i];
    EXPECT_FALSE(a["correct"].get<bool>());
    EXPECT_FALSE(a["has_true_match"].get<bool>());
    EXPECT_TRUE(a["distance_m"].get<double>() > 2.0 || a["angle_deg"].get<double>() > 30.0) << a.dump();
    EXPECT_LT(a["top_frame"].get<int>(), a["frame"].get<int>());
    EXPECT_EQ(a["frame"].get<int>() % 5, 0);
    if (i > 0) {
      EXPECT_LE(a["score"].get<double>(), answers[i - 1]["score"].get<double>());
    }
  }
  test::TempDir tmp;
  fs::create_directories(tmp.path() / "seq" / "image_0");
  fs::create_directories(tmp.path() / "seq" / "image_1");
  fs::copy_file(seq / "calib.txt", tmp.path() / "seq" / "calib.txt");
  std::ofstream(tmp.path() / "seq" / "times.txt") << "0.0\n0.1\n0.2\n";
  for (int i = 0; i < 3; ++i) {
    const auto name = fmt::format("{:06d}.png", i);
    fs::copy_file(seq / "image_0" / name, tmp.path() / "seq" / "image_0" / name);
    fs::copy_file(seq / "image_1" / name, tmp.path() / "seq" / "image_1" / name);
  }
  const auto no_gt = test::run_cli("vocab eval \"" + (tmp.path() / "seq").string() + "\"");
  EXPECT_EQ(no_gt.exit_code, 2);
  EXPECT_NE(no_gt.err.find("no ground truth"), std::string::npos) << no_gt.err;
}

}  // namespace
}  // namespace plslam::place
