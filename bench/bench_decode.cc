// Decoding figures: time per image, agreement statistics. Prints JSON.
#include <cstdio>
#include "decode/decoder.h"
#include "tests/decode/truth_components.h"
using namespace puzzlecal;
using namespace puzzlecal::decode_testing;
int main() {
  const Board board = MakePuzzleBoard(23, 16, 50, 100, 0.03);
  const Camera camera = PinholeCamera(1280, 960, 800);
  RenderOptions ro;
  RenderTruth truth;
  cv::Mat image = RenderBoard(board, camera, LookAt(board, {61, 107.5}, 1.0, 20, 10), ro, &truth);
  std::printf("image %dx%d\n", image.cols, image.rows);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 8; ++trial) {
    Eigen::Matrix2i l = RandomSignedPermutation(&rng);
    TruthGrid grid = OneComponentFromTruth(truth, l, {7, -3});
    DecodeResult r = DecodeBoard(board, grid.corners, grid.components, image);
    const ComponentDecoding& c = r.components[0];
    int wrong = 0;
    for (size_t k = 0; k < r.observation.id.size(); ++k) {
      if (r.observation.id[k] != grid.truth_id[r.corner_index[k]]) ++wrong;
    }
    std::printf("det %d decoded %d n %zu wrong %d reason '%s' read %d/%d agree %.3f margin %d nfa %.1f hyp %d\n",
      l.determinant(), r.decoded, r.observation.id.size(), wrong, r.reason.c_str(), c.bits_read, c.edges, c.agreement, c.margin, c.log10_nfa, c.hypotheses);
  }
}
