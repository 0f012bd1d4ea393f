// The splined models' reprojection cost over their whole intrinsics block
// (the rig's joint solve and the capture advice use it; the single-camera
// solve uses calib/splined_reprojection.h): compiled apart from the other
// models' (calib/reprojection_error.cc), its 212-wide dual numbers are the
// heaviest code of the folder.

#include "calib/reprojection_cost_impl.h"
#include "calib/reprojection_error.h"

namespace puzzlecal {

template class ReprojectionCost<KannalaBrandtSplinedModel>;
template class ReprojectionCost<KannalaBrandtSplinedNoncentralModel>;

}  // namespace puzzlecal
