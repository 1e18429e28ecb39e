// `plslam vocab train` on the real excerpts: a reproducible file that loads, whose bags of words
// rank a neighbouring frame of KITTI 06 above a frame 30 m away, and bad usage refused.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

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
