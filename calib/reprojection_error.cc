#include "calib/reprojection_error.h"

namespace puzzlecal {

template class ReprojectionCost<PinholeRadtanModel>;
template class ReprojectionCost<PinholeRationalModel>;
template class ReprojectionCost<KannalaBrandtModel>;
template class ReprojectionCost<KannalaBrandtNoncentralModel>;

}  // namespace puzzlecal
