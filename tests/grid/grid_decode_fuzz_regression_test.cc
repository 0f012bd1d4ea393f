// Replays the grid_decode_fuzzer corpus (seeds and every crash input kept
// from fuzzing, fuzz/corpus/grid_decode_fuzzer/) through the same code path as
// the fuzz target, in the normal build: BuildGrid and DecodeBoard must keep
// their promises (valid indices, one label per corner, ids inside the board).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/corpus_replay.h"
#include "fuzz/grid_decode_case.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

TEST(GridDecodeFuzzRegressionTest, CorpusKeepsGridAndDecodePromises) {
  const int replayed = fuzz::ReplayCorpus(
      "fuzz/corpus/grid_decode_fuzzer",
      [](const std::string& name, const std::vector<uint8_t>& bytes) {
        EXPECT_EQ(fuzz::RunGridDecodeCase(bytes.data(), bytes.size()), "")
            << name;
      });
  ASSERT_NE(replayed, -1) << "run from the repository root (ctest does)";
  EXPECT_GE(replayed, 5);
}

// The clean-lattice seed describes an 11 x 8 lattice on a checkerboard
// image: the grid must hold all 88 corners in one component, and the
// checkerboard decoder must give them the board's 88 ids.
TEST(GridDecodeFuzzRegressionTest, CleanLatticeSeedIsTheWholeBoard) {
  const std::vector<uint8_t> bytes =
      fuzz::ReadCorpusFile("fuzz/corpus/grid_decode_fuzzer/checker_11x8_clean");
  ASSERT_FALSE(bytes.empty());
  fuzz::ByteReader reader(bytes.data(), bytes.size());
  const Board board = fuzz::BoardFromByte(reader.Byte());
  ASSERT_EQ(board.type, BoardType::kCheckerboard);
  reader.Byte();  // image selector
  reader.Byte();  // options
  const uint8_t mode = reader.Byte();
  fuzz::LatticeParams lattice;
  lattice.origin_x = reader.DoubleInRange(-40, fuzz::kGridImageWidth + 40);
  lattice.origin_y = reader.DoubleInRange(-40, fuzz::kGridImageHeight + 40);
  lattice.spacing = reader.DoubleInRange(0.5, 60);
  lattice.angle = reader.DoubleInRange(-M_PI, M_PI);
  const std::vector<Corner> corners =
      fuzz::CornersFromBytes(&reader, mode, lattice);
  ASSERT_EQ(corners.size(), 88u);
  const cv::Mat image = fuzz::LatticeImage(lattice, CV_8U);
  GridSummary summary;
  const std::vector<GridComponent> components =
      BuildGrid(corners, image, GridOptions(), &summary);
  ASSERT_EQ(components.size(), 1u) << summary.message;
  EXPECT_EQ(components[0].corner.size(), 88u);
  const DecodeResult result = DecodeBoard(board, corners, components, image);
  EXPECT_TRUE(result.absolute_ids) << result.reason;
  EXPECT_EQ(result.observation.id.size(), 88u);
}

}  // namespace
}  // namespace puzzlecal
