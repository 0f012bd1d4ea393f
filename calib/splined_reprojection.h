#ifndef PUZZLECAL_CALIB_SPLINED_REPROJECTION_H_
#define PUZZLECAL_CALIB_SPLINED_REPROJECTION_H_

// The reprojection error of one corner under a splined model
// (camera/splined_model.h), with the intrinsics split into parameter blocks
// so that a corner touches only the 4 knot rows around it: kannala-brandt's
// part (fx fy cx cy k1..k4 grid_radius), the view's pose, the 4 rows of
// knots' (du, dv) values over the corner's cell, and (non-central form) the
// pupil e1 e2. With one 209-value intrinsics block every corner would add a
// dense 209 x 209 product to the reduced system and differentiate 212-wide
// dual numbers; here it is 89 values in 6 or 7 blocks and 14-wide dual
// numbers (the knots' derivatives are the B-spline weights, exact and
// cheap). (One block per knot, 16 per corner, cost more: the solver's work
// per pair of blocks outweighed the smaller products; deltille photos,
// 0.55 -> see bench_lens_models.) The cell is fixed
// when the cost is made (from the estimate then); should the corner's ray
// leave it during the solve, the cell's polynomial continues, and the
// solver rebuilds the problem and solves again (calib/calibrate.cc), so
// that the result is the model's own projection.

#include <ceres/cost_function.h>
#include <ceres/jet.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <vector>

#include "calib/reprojection_error.h"
#include "camera/camera_models.h"

namespace puzzlecal {

// The parameter blocks of a model's intrinsics vector: [begin, begin + size)
// each. One block for the models without a spline; for a splined model
// kannala-brandt's part with the grid radius, then one block per row of
// knots (the row's (du, dv) pairs), then (non-central form) the pupil.
struct IntrinsicsBlock {
  int begin = 0;
  int size = 0;
};
std::vector<IntrinsicsBlock> IntrinsicsBlocks(CameraModelId model);

// The cell (row, col) of the spline grid that a camera-frame point falls in
// under a splined model's intrinsics; {0, 0} when it has no ray.
template <typename Model>
std::array<int, 2> SplineCellOf(const double* intrinsics,
                                const Eigen::Vector3d& point_cam) {
  double mx = 0, my = 0, ex = 0, ey = 0;
  if (!Model::KannalaBrandtPart(intrinsics, intrinsics + Model::kPupilIndex,
                                point_cam.data(), &mx, &my, &ex, &ey)) {
    return {0, 0};
  }
  const double radius = intrinsics[Model::kGridRadiusIndex];
  return {internal::SplineCell(ey, radius), internal::SplineCell(ex, radius)};
}

template <typename Model>
class SplinedReprojectionCost : public ceres::CostFunction {
 public:
  static constexpr int kBase = Model::kSplineBegin;
  static constexpr int kPupilSize = Model::kHasPupil ? 2 : 0;
  static constexpr int kFirstKnotBlock = 2;
  static constexpr int kNumKnotBlocks = 4;  // knot rows
  static constexpr int kKnotRowSize = 2 * kSplineKnots;
  static constexpr int kPupilBlock = kFirstKnotBlock + kNumKnotBlocks;
  // Dual numbers over kannala-brandt's part, the pupil and the point.
  static constexpr int kJetWidth = kBase + kPupilSize + 3;

  SplinedReprojectionCost(const Eigen::Vector3d& board_point,
                          const Eigen::Vector2d& observed_pixel,
                          std::array<int, 2> cell)
      : board_point_(board_point), observed_(observed_pixel), cell_(cell) {
    set_num_residuals(2);
    auto* sizes = mutable_parameter_block_sizes();
    sizes->push_back(kBase);
    sizes->push_back(kPoseBlockSize);
    for (int j = 0; j < kNumKnotBlocks; ++j) sizes->push_back(kKnotRowSize);
    if (kPupilSize > 0) sizes->push_back(kPupilSize);
  }

  const std::array<int, 2>& cell() const { return cell_; }

  // The parameter blocks of this cost within the intrinsics vector
  // `intrinsics` and the pose block `pose`, in the cost's order.
  std::vector<double*> Blocks(double* intrinsics, double* pose) const {
    std::vector<double*> blocks = {intrinsics, pose};
    for (int j = 0; j < kNumKnotBlocks; ++j) {
      blocks.push_back(intrinsics + Model::kSplineBegin +
                       kKnotRowSize * (cell_[0] + j));
    }
    if (kPupilSize > 0) blocks.push_back(intrinsics + Model::kPupilIndex);
    return blocks;
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* base = parameters[0];
    const double* pose = parameters[1];
    const double* pupil = kPupilSize > 0 ? parameters[kPupilBlock] : nullptr;
    const bool want_jacobians =
        jacobians != nullptr &&
        std::any_of(jacobians, jacobians + parameter_block_sizes().size(),
                    [](double* j) { return j != nullptr; });
    if (!want_jacobians) {
      double point[3];
      const double board[3] = {board_point_.x(), board_point_.y(),
                               board_point_.z()};
      ceres::AngleAxisRotatePoint(pose, board, point);
      for (int j = 0; j < 3; ++j) point[j] += pose[3 + j];
      double pixel[2];
      if (!ProjectInCell(base, pupil, parameters, point, pixel)) return false;
      residuals[0] = pixel[0] - observed_.x();
      residuals[1] = pixel[1] - observed_.y();
      return true;
    }
    // p and d p / d w, 3 wide (as ReprojectionCost).
    const TurnedBoardPoint turned = TurnBoardPoint(pose, board_point_);
    using Jet = ceres::Jet<double, kJetWidth>;
    Jet jet_base[kBase];
    for (int k = 0; k < kBase; ++k) jet_base[k] = Jet(base[k], k);
    Jet jet_pupil[2];
    for (int k = 0; k < kPupilSize; ++k) {
      jet_pupil[k] = Jet(pupil[k], kBase + k);
    }
    constexpr int kPointBegin = kBase + kPupilSize;
    Jet point[3];
    for (int j = 0; j < 3; ++j) {
      point[j] = Jet(turned.point(j) + pose[3 + j], kPointBegin + j);
    }
    Jet pixel[2];
    if (!ProjectInCell(jet_base, jet_pupil, parameters, point, pixel)) {
      return false;
    }
    residuals[0] = pixel[0].a - observed_.x();
    residuals[1] = pixel[1].a - observed_.y();
    for (int r = 0; r < 2; ++r) {
      if (jacobians[0] != nullptr) {
        for (int k = 0; k < kBase; ++k) {
          jacobians[0][r * kBase + k] = pixel[r].v[k];
        }
      }
      if (jacobians[1] != nullptr) {
        const double d_pixel_d_point[3] = {pixel[r].v[kPointBegin],
                                           pixel[r].v[kPointBegin + 1],
                                           pixel[r].v[kPointBegin + 2]};
        PoseJacobianRow(d_pixel_d_point, turned,
                        jacobians[1] + r * kPoseBlockSize);
      }
      if (kPupilSize > 0 && jacobians[kPupilBlock] != nullptr) {
        for (int k = 0; k < kPupilSize; ++k) {
          jacobians[kPupilBlock][r * kPupilSize + k] = pixel[r].v[kBase + k];
        }
      }
    }
    // The knots: d u / d du = fx * weight, d v / d dv = fy * weight, for the
    // 4 x 4 knots of the cell in the 4 row blocks.
    double mx = 0, my = 0, ex = 0, ey = 0;
    const double plain_point[3] = {point[0].a, point[1].a, point[2].a};
    Model::KannalaBrandtPart(base, pupil, plain_point, &mx, &my, &ex, &ey);
    double wx[4], wy[4];
    Model::CellWeights(ex, ey, base[Model::kGridRadiusIndex], cell_[0],
                       cell_[1], wx, wy);
    for (int a = 0; a < kNumKnotBlocks; ++a) {
      double* jacobian = jacobians[kFirstKnotBlock + a];
      if (jacobian == nullptr) continue;
      std::fill(jacobian, jacobian + 2 * kKnotRowSize, 0.0);
      for (int b = 0; b < 4; ++b) {
        const double weight = wy[a] * wx[b];
        const int du = 2 * (cell_[1] + b);
        jacobian[du] = base[0] * weight;                     // d u / d du
        jacobian[kKnotRowSize + du + 1] = base[1] * weight;  // d v / d dv
      }
    }
    return true;
  }

 private:
  // The model's projection with the correction of this cost's cell (the
  // knots' values from the parameter blocks, constants to the dual numbers).
  template <typename T>
  bool ProjectInCell(const T* base, const T* pupil,
                     double const* const* parameters, const T* point,
                     T* pixel) const {
    T mx, my, ex, ey;
    if (!Model::KannalaBrandtPart(base, pupil, point, &mx, &my, &ex, &ey)) {
      return false;
    }
    const int row = cell_[0], col = cell_[1];
    auto knot = [&](int k) {
      const int a = k / kSplineKnots - row;
      return parameters[kFirstKnotBlock + a] + 2 * (k % kSplineKnots);
    };
    T du, dv;
    Model::CorrectionInCell(ex, ey, base[Model::kGridRadiusIndex], row, col,
                            knot, &du, &dv);
    pixel[0] = base[0] * (mx + du) + base[2];
    pixel[1] = base[1] * (my + dv) + base[3];
    return true;
  }

  Eigen::Vector3d board_point_;
  Eigen::Vector2d observed_;
  std::array<int, 2> cell_;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_SPLINED_REPROJECTION_H_
