// Replays the detect_fuzzer corpus (seeds and every crash input kept from
// fuzzing, fuzz/corpus/detect_fuzzer/) through the same code path as the
// fuzz target, in the normal build: each must run without a sanitizer
// finding and keep DetectCorners' promises.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz/corpus_replay.h"
#include "fuzz/detect_case.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

TEST(DetectFuzzRegressionTest, CorpusKeepsDetectorPromises) {
  const int replayed = fuzz::ReplayCorpus(
      "fuzz/corpus/detect_fuzzer",
      [](const std::string& name, const std::vector<uint8_t>& bytes) {
        EXPECT_EQ(fuzz::RunDetectCase(bytes.data(), bytes.size()), "") << name;
      });
  ASSERT_NE(replayed, -1) << "run from the repository root (ctest does)";
  EXPECT_GE(replayed, 5);
}

// The seed layout decodes to the images it claims: the 64x64 raw checkerboard
// seed (tile 9 px, corners inside) yields its inner corners.
TEST(DetectFuzzRegressionTest, RawSeedDecodesToACheckerboard) {
  std::ifstream in("fuzz/corpus/detect_fuzzer/raw8_checker", std::ios::binary);
  ASSERT_TRUE(in);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  fuzz::ByteReader reader(bytes.data(), bytes.size());
  const uint8_t mode = reader.Byte();
  reader.Byte();
  const cv::Mat image = fuzz::DetectImageFromBytes(&reader, mode);
  ASSERT_EQ(image.cols, 64);
  ASSERT_EQ(image.rows, 64);
  ASSERT_EQ(image.type(), CV_8UC1);
  DetectorSummary summary;
  const std::vector<Corner> corners = DetectCorners(image, {}, &summary);
  EXPECT_TRUE(summary.ok) << summary.message;
  // A 64 px square with 9 px tiles holds about (64 / 9 - 1)^2 = 37 inner
  // corners away from the border; at least half must be found.
  EXPECT_GE(corners.size(), 18u);
}

}  // namespace
}  // namespace puzzlecal
