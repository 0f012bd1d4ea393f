#include "calib/splined_reprojection.h"

namespace puzzlecal {

std::vector<IntrinsicsBlock> IntrinsicsBlocks(CameraModelId model) {
  const int n = CameraModelNumParams(model);
  if (!CameraModelIsSplined(model)) return {{0, n}};
  using Splined = KannalaBrandtSplinedModel;
  std::vector<IntrinsicsBlock> blocks = {{0, Splined::kSplineBegin}};
  for (int row = 0; row < kSplineKnots; ++row) {
    blocks.push_back(
        {Splined::kSplineBegin + 2 * kSplineKnots * row, 2 * kSplineKnots});
  }
  if (n > Splined::kPupilIndex) {
    blocks.push_back({Splined::kPupilIndex, n - Splined::kPupilIndex});
  }
  return blocks;
}

}  // namespace puzzlecal
