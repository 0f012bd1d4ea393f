// Parameters held fixed, as the command line and the options file name
// them (`--fix k3,p1,p2`, `--fix focal`; OpenCV's CALIB_FIX_K3,
// CALIB_ZERO_TANGENT_DIST, CALIB_FIX_FOCAL_LENGTH, CALIB_FIX_PRINCIPAL_POINT,
// and all intrinsics held for extrinsics only).

#ifndef PUZZLECAL_APPS_FIXED_PARAMS_H_
#define PUZZLECAL_APPS_FIXED_PARAMS_H_

#include <string>
#include <vector>

#include "camera/camera_models.h"

namespace puzzlecal {

// The parameter names of `model` that `list` stands for: comma-separated
// parameter names (CameraModelParamNames) and the groups `focal` (fx, fy),
// `principal-point` (cx, cy), `distortion` (every parameter after them) and
// `all`. Empty `list`: none. False with a message naming the unknown name
// and the model's names.
bool ExpandFixedParams(const std::string& list, CameraModelId model,
                       std::vector<std::string>* names, std::string* error);

// Appends the names of `add` that `fixed` does not hold yet.
void AddFixedParams(const std::vector<std::string>& add,
                    std::vector<std::string>* fixed);

}  // namespace puzzlecal

#endif  // PUZZLECAL_APPS_FIXED_PARAMS_H_
