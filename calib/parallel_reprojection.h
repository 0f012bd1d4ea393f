#ifndef PUZZLECAL_CALIB_PARALLEL_REPROJECTION_H_
#define PUZZLECAL_CALIB_PARALLEL_REPROJECTION_H_

// Deterministic multi-threaded evaluation of the reprojection errors of a
// Ceres problem. Ceres's own threads sum the cost, the gradient and the
// Schur complement in the order its threads finish, which changes the last
// bits of the solution from run to run. Here Ceres runs on one thread; an
// EvaluationCallback evaluates every corner's residual and Jacobian ahead of
// it (the expensive automatic differentiation), spread over threads in
// fixed slices, each corner into its own slot. Ceres then reads the slots in
// its fixed order, so the solution is bit for bit the one of a
// single-threaded solve, whatever the thread count.

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "calib/reprojection_error.h"
#include "util/parallel_for.h"

namespace puzzlecal {

template <typename Model>
class ParallelReprojection : public ceres::EvaluationCallback {
 public:
  static constexpr int kNumParams = Model::kNumParams;

  // `intrinsics`: the problem's intrinsics block, read at each evaluation.
  ParallelReprojection(const double* intrinsics, int num_threads)
      : intrinsics_(intrinsics), num_threads_(std::max(1, num_threads)) {}

  // The cost function of one corner seen from the pose block `pose`; the
  // problem takes ownership of it, this object must outlive the problem.
  ceres::CostFunction* Add(const Eigen::Vector3d& board_point,
                           const Eigen::Vector2d& pixel, const double* pose) {
    corners_.emplace_back(ReprojectionError<Model>::Create(board_point, pixel));
    poses_.push_back(pose);
    slots_.emplace_back();
    return new Cached(this, corners_.size() - 1);
  }

  void PrepareForEvaluation(bool evaluate_jacobians,
                            bool new_evaluation_point) override {
    if (!new_evaluation_point && (!evaluate_jacobians || have_jacobians_)) {
      return;
    }
    have_jacobians_ = evaluate_jacobians;
    const size_t n = corners_.size();
    // One contiguous slice of corners per thread, each corner into its slot.
    ParallelFor(static_cast<int>(n), num_threads_,
                [&](int i) { EvaluateCorner(i, evaluate_jacobians); });
  }

 private:
  struct Slot {
    bool ok = false;
    std::array<double, 2> residual;
    std::array<double, 2 * kNumParams> d_intrinsics;  // row-major 2 x N
    std::array<double, 2 * kPoseBlockSize> d_pose;    // row-major 2 x 6
  };

  // Reads slot `index`, or evaluates directly when Ceres evaluates at other
  // values than the user's blocks hold (then the slots do not describe it).
  class Cached
      : public ceres::SizedCostFunction<2, kNumParams, kPoseBlockSize> {
   public:
    Cached(const ParallelReprojection* owner, size_t index)
        : owner_(owner), index_(index) {}
    bool Evaluate(double const* const* parameters, double* residuals,
                  double** jacobians) const override {
      const bool jacobians_wanted =
          jacobians != nullptr &&
          (jacobians[0] != nullptr || jacobians[1] != nullptr);
      if (!SameValues(parameters[0], owner_->intrinsics_, kNumParams) ||
          !SameValues(parameters[1], owner_->poses_[index_], kPoseBlockSize) ||
          (jacobians_wanted && !owner_->have_jacobians_)) {
        return owner_->corners_[index_]->Evaluate(parameters, residuals,
                                                  jacobians);
      }
      const Slot& slot = owner_->slots_[index_];
      if (!slot.ok) return false;
      std::copy(slot.residual.begin(), slot.residual.end(), residuals);
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        std::copy(slot.d_intrinsics.begin(), slot.d_intrinsics.end(),
                  jacobians[0]);
      }
      if (jacobians != nullptr && jacobians[1] != nullptr) {
        std::copy(slot.d_pose.begin(), slot.d_pose.end(), jacobians[1]);
      }
      return true;
    }

   private:
    static bool SameValues(const double* a, const double* b, int n) {
      return a == b || std::equal(a, a + n, b);
    }
    const ParallelReprojection* owner_;
    size_t index_;
  };

  void EvaluateCorner(size_t i, bool evaluate_jacobians) {
    Slot& slot = slots_[i];
    const double* parameters[2] = {intrinsics_, poses_[i]};
    double* jacobians[2] = {slot.d_intrinsics.data(), slot.d_pose.data()};
    slot.ok = corners_[i]->Evaluate(parameters, slot.residual.data(),
                                    evaluate_jacobians ? jacobians : nullptr);
  }

  const double* intrinsics_;
  const int num_threads_;
  std::vector<std::unique_ptr<ceres::CostFunction>> corners_;
  std::vector<const double*> poses_;
  std::vector<Slot> slots_;
  bool have_jacobians_ = false;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_PARALLEL_REPROJECTION_H_
