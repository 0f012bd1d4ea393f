#include "calib/splined_reprojection.h"

namespace puzzlecal {

std::vector<IntrinsicsBlock> IntrinsicsBlocks(CameraModelId model) {
  const int n = CameraModelNumParams(model);
  if (!CameraModelIsSplined(model)) return {{0, n}};
  using Splined = KannalaBrandtSplinedModel;
  std::vector<IntrinsicsBlock> blocks = {{0, Splined::kSplineBegin}};
  for (int k = 0; k < kSplineValues; ++k) {
    blocks.push_back({Splined::kSplineBegin + 2 * k, 2});
  }
  if (n > Splined::kPupilIndex) {
    blocks.push_back({Splined::kPupilIndex, n - Splined::kPupilIndex});
  }
  return blocks;
}

}  // namespace puzzlecal
