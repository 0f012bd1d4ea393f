#include "calib/rig_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "calib/intrinsics_manifold.h"
#include "calib/reprojection_error.h"
#include "util/angles.h"
#include "util/failure.h"
#include "util/parallel_for.h"
#include "util/statistics.h"
#include "util/string_format.h"
#include "util/timer.h"

namespace puzzlecal {
namespace {

using Pose = PoseBlock;

// The pixel error of one board corner seen by a camera that is not the
// reference: intrinsics, cam_from_rig and the frame's rig_from_board (both
// angle-axis + translation). The corner's rig-frame point p = R_f X + t_f
// is the board point of the single-camera cost (ReprojectionCost, compiled
// once per model in calib/reprojection_error*.cc) seen from cam_from_rig:
// the residual and its derivatives by the intrinsics and by cam_from_rig
// are that cost's, and the frame's pose enters by the chain rule through p
// (d pixel / d p = d pixel / d t_c R_c). No model's projection is
// differentiated here, so the rig adds no dual-number code per model.
class RigReprojectionCost : public ceres::CostFunction {
 public:
  RigReprojectionCost(CameraModelId model, const Eigen::Vector3d& board_point,
                      const Eigen::Vector2d& observed_pixel)
      : model_(model),
        num_params_(CameraModelNumParams(model)),
        board_point_(board_point),
        observed_pixel_(observed_pixel) {
    set_num_residuals(2);
    auto* sizes = mutable_parameter_block_sizes();
    sizes->push_back(num_params_);
    sizes->push_back(kPoseBlockSize);
    sizes->push_back(kPoseBlockSize);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* intrinsics = parameters[0];
    const double* cam_from_rig = parameters[1];
    const double* rig_from_board = parameters[2];
    // p and d p / d w_f, 3 wide.
    const TurnedBoardPoint turned =
        TurnBoardPoint(rig_from_board, board_point_);
    const Eigen::Vector3d point_rig =
        turned.point + Eigen::Vector3d(rig_from_board[3], rig_from_board[4],
                                       rig_from_board[5]);
    const bool want = jacobians != nullptr &&
                      (jacobians[0] != nullptr || jacobians[1] != nullptr ||
                       jacobians[2] != nullptr);
    if (!want) {
      return EvaluateReprojection(model_, intrinsics, cam_from_rig, point_rig,
                                  observed_pixel_, residuals, nullptr, nullptr);
    }
    std::vector<double> d_intrinsics(2 * num_params_);
    double d_cam[2 * kPoseBlockSize];
    if (!EvaluateReprojection(model_, intrinsics, cam_from_rig, point_rig,
                              observed_pixel_, residuals, d_intrinsics.data(),
                              d_cam)) {
      return false;
    }
    if (jacobians[0] != nullptr) {
      std::copy(d_intrinsics.begin(), d_intrinsics.end(), jacobians[0]);
    }
    if (jacobians[1] != nullptr) {
      std::copy(d_cam, d_cam + 2 * kPoseBlockSize, jacobians[1]);
    }
    if (jacobians[2] != nullptr) {
      // d pixel / d p = d pixel / d t_c * R_c (ceres's matrices are
      // column-major).
      double r_c[9];
      ceres::AngleAxisToRotationMatrix(cam_from_rig, r_c);
      for (int r = 0; r < 2; ++r) {
        double d_point[3];
        for (int j = 0; j < 3; ++j) {
          d_point[j] = 0;
          for (int k = 0; k < 3; ++k) {
            d_point[j] += d_cam[r * kPoseBlockSize + 3 + k] * r_c[j * 3 + k];
          }
        }
        PoseJacobianRow(d_point, turned, jacobians[2] + r * kPoseBlockSize);
      }
    }
    return true;
  }

 private:
  const CameraModelId model_;
  const int num_params_;
  Eigen::Vector3d board_point_;
  Eigen::Vector2d observed_pixel_;
};

// The state the joint solves share. Indices: [camera][frame][corner].
//
// The intrinsics and extrinsics of all cameras live in one buffer, in
// camera order: Ceres orders the blocks of an elimination group by address,
// so one buffer makes that order (and the sums of the reduced system) the
// same on every run.
struct JointState {
  const std::vector<RigCameraInput>* input = nullptr;
  std::vector<double> global;
  std::vector<size_t> params_offset;      // per camera, into `global`
  std::vector<size_t> extrinsics_offset;  // per camera, into `global`
  std::vector<int> num_params;            // per camera
  double* params(size_t c) { return global.data() + params_offset[c]; }
  const double* params(size_t c) const {
    return global.data() + params_offset[c];
  }
  double* cam_from_rig(size_t c) {
    return global.data() + extrinsics_offset[c];
  }
  const double* cam_from_rig(size_t c) const {
    return global.data() + extrinsics_offset[c];
  }
  std::vector<double> Params(size_t c) const {
    return std::vector<double>(params(c), params(c) + num_params[c]);
  }
  Pose CamFromRig(size_t c) const {
    Pose pose;
    std::copy(cam_from_rig(c), cam_from_rig(c) + kPoseBlockSize, pose.data());
    return pose;
  }
  std::vector<Pose> rig_from_board;
  std::vector<bool> frame_posed;  // rig_from_board has a value
  std::vector<std::vector<bool>> used;
  std::vector<std::vector<std::vector<bool>>> valid;
  std::vector<std::vector<std::vector<bool>>> inlier;
  std::vector<std::vector<bool>> fixed;
  // fy tied to fx in every camera (same_focal_length).
  bool same_focal = false;
  // The parameters of camera c without a tangent coordinate of their own:
  // the fixed ones, and fy when it is tied to fx.
  std::vector<bool> TangentFixed(size_t c) const {
    std::vector<bool> tangent_fixed = fixed[c];
    if (same_focal && tangent_fixed.size() > 1) tangent_fixed[1] = true;
    return tangent_fixed;
  }
};

bool Residual(const JointState& state, size_t c, size_t f, size_t i,
              Eigen::Vector2d* residual) {
  const CalibrationView& view = (*state.input)[c].frames[f];
  const Eigen::Vector3d point =
      IsometryFromPoseBlock(state.cam_from_rig(c)) *
      (IsometryFromPoseBlock(state.rig_from_board[f].data()) *
       view.board_points[i]);
  Eigen::Vector2d pixel;
  if (!ProjectPoint((*state.input)[c].model, state.params(c), point, &pixel)) {
    return false;
  }
  *residual = pixel - view.image_points[i];
  return residual->allFinite();
}

struct SolveOutcome {
  ceres::Solver::Summary summary;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<bool> params_in_problem;  // per camera
  std::vector<bool> frame_in_problem;
};

void SolveJoint(JointState* state, const CalibrationOptions& options,
                double trust_region_radius,
                std::unique_ptr<ceres::LossFunction>* loss,
                SolveOutcome* outcome) {
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  outcome->problem = std::make_unique<ceres::Problem>(problem_options);
  ceres::Problem& problem = *outcome->problem;
  loss->reset();
  if (options.loss == RobustLoss::kHuber) {
    loss->reset(new ceres::HuberLoss(options.loss_scale_px));
  } else if (options.loss == RobustLoss::kCauchy) {
    loss->reset(new ceres::CauchyLoss(options.loss_scale_px));
  }
  const size_t num_cameras = state->input->size();
  const size_t num_frames = state->rig_from_board.size();
  outcome->params_in_problem.assign(num_cameras, false);
  outcome->frame_in_problem.assign(num_frames, false);
  std::vector<bool> extrinsics_in_problem(num_cameras, false);
  int num_residuals = 0;
  for (size_t c = 0; c < num_cameras; ++c) {
    const RigCameraInput& camera = (*state->input)[c];
    DispatchCameraModel(camera.model, [&](auto model_struct) {
      using Model = decltype(model_struct);
      for (size_t f = 0; f < num_frames; ++f) {
        if (!state->used[c][f]) continue;
        const CalibrationView& view = camera.frames[f];
        for (size_t i = 0; i < view.board_points.size(); ++i) {
          if (!state->inlier[c][f][i]) continue;
          if (c == 0) {
            problem.AddResidualBlock(
                ReprojectionError<Model>::Create(view.board_points[i],
                                                 view.image_points[i]),
                loss->get(), state->params(c), state->rig_from_board[f].data());
          } else {
            problem.AddResidualBlock(
                new RigReprojectionCost(camera.model, view.board_points[i],
                                        view.image_points[i]),
                loss->get(), state->params(c), state->cam_from_rig(c),
                state->rig_from_board[f].data());
            extrinsics_in_problem[c] = true;
          }
          outcome->params_in_problem[c] = true;
          outcome->frame_in_problem[f] = true;
          ++num_residuals;
        }
      }
    });
  }
  if (num_residuals == 0) {
    outcome->summary = ceres::Solver::Summary();
    outcome->summary.message = "no corners left to fit";
    return;
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (size_t f = 0; f < num_frames; ++f) {
    if (outcome->frame_in_problem[f]) {
      ordering->AddElementToGroup(state->rig_from_board[f].data(), 0);
    }
  }
  for (size_t c = 0; c < num_cameras; ++c) {
    if (extrinsics_in_problem[c]) {
      ordering->AddElementToGroup(state->cam_from_rig(c), 1);
    }
    if (!outcome->params_in_problem[c]) continue;
    AddSplinePrior((*state->input)[c].model, state->params(c),
                   options.spline_prior, &problem);
    ordering->AddElementToGroup(state->params(c), 1);
    const int n = state->num_params[c];
    std::vector<int> fixed_indices;
    for (int k = 0; k < n; ++k) {
      if (state->fixed[c][k]) fixed_indices.push_back(k);
    }
    if (state->same_focal) {
      auto manifold = std::make_unique<TiedFocalManifold>(n, state->fixed[c]);
      if (manifold->TangentSize() == 0) {
        problem.SetParameterBlockConstant(state->params(c));
      } else {
        problem.SetManifold(state->params(c), manifold.release());
      }
    } else if (static_cast<int>(fixed_indices.size()) == n) {
      problem.SetParameterBlockConstant(state->params(c));
    } else if (!fixed_indices.empty()) {
      problem.SetManifold(state->params(c),
                          new ceres::SubsetManifold(n, fixed_indices));
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.initial_trust_region_radius = trust_region_radius;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering = ordering;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.num_threads = options.deterministic ? 1 : options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solve(solver_options, &problem, &outcome->summary);
}

// Where each camera's free parameters sit in the global (non-frame) part of
// the Jacobian: intrinsics (free ones only) and cam_from_rig (6, not for
// the reference camera).
struct GlobalLayout {
  std::vector<int> params_begin;      // -1 when not in the covariance
  std::vector<int> extrinsics_begin;  // -1 when not in the covariance
  int size = 0;
};

// Covariance of the global parameters (all intrinsics and extrinsics) with
// the frame poses marginalised out: the inverse of the Schur complement
// S = A - sum_f B_f C_f^-1 B_f' of J'J, summed in a fixed order. False when
// S is singular (after scaling its diagonal to 1, its smallest eigenvalue
// is below min_eigenvalue_ratio times the largest).
bool JointMarginalCovariance(const JointState& state, SolveOutcome* outcome,
                             double min_eigenvalue_ratio, GlobalLayout* layout,
                             Eigen::MatrixXd* covariance) {
  const size_t num_cameras = state.num_params.size();
  ceres::Problem::EvaluateOptions evaluate;
  layout->params_begin.assign(num_cameras, -1);
  layout->extrinsics_begin.assign(num_cameras, -1);
  layout->size = 0;
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!outcome->params_in_problem[c]) continue;
    const std::vector<bool> tangent_fixed = state.TangentFixed(c);
    const int free = static_cast<int>(
        std::count(tangent_fixed.begin(), tangent_fixed.end(), false));
    if (free > 0) {
      evaluate.parameter_blocks.push_back(const_cast<double*>(state.params(c)));
      layout->params_begin[c] = layout->size;
      layout->size += free;
    }
    if (c > 0) {
      evaluate.parameter_blocks.push_back(
          const_cast<double*>(state.cam_from_rig(c)));
      layout->extrinsics_begin[c] = layout->size;
      layout->size += kPoseBlockSize;
    }
  }
  int num_frames = 0;
  for (size_t f = 0; f < state.rig_from_board.size(); ++f) {
    if (!outcome->frame_in_problem[f]) continue;
    evaluate.parameter_blocks.push_back(
        const_cast<double*>(state.rig_from_board[f].data()));
    ++num_frames;
  }
  evaluate.num_threads = 1;
  ceres::CRSMatrix jacobian;
  if (!outcome->problem->Evaluate(evaluate, nullptr, nullptr, nullptr,
                                  &jacobian)) {
    return false;
  }
  const int n = layout->size;
  if (n == 0 || jacobian.num_cols != n + kPoseBlockSize * num_frames) {
    return false;
  }
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  std::vector<Eigen::MatrixXd> b(num_frames, Eigen::MatrixXd::Zero(n, 6));
  std::vector<Eigen::Matrix<double, 6, 6>> c(
      num_frames, Eigen::Matrix<double, 6, 6>::Zero());
  Eigen::VectorXd j_global(n);
  Eigen::Matrix<double, 6, 1> j_frame;
  std::vector<int> touched;
  for (int row = 0; row < jacobian.num_rows; ++row) {
    j_global.setZero();
    j_frame.setZero();
    touched.clear();
    int frame = -1;
    for (int e = jacobian.rows[row]; e < jacobian.rows[row + 1]; ++e) {
      const int col = jacobian.cols[e];
      if (col < n) {
        j_global(col) = jacobian.values[e];
        touched.push_back(col);
      } else {
        frame = (col - n) / kPoseBlockSize;
        j_frame((col - n) % kPoseBlockSize) = jacobian.values[e];
      }
    }
    // Only the touched columns are non-zero: update those entries.
    for (int p : touched) {
      for (int q : touched) a(p, q) += j_global(p) * j_global(q);
    }
    if (frame >= 0) {
      for (int p : touched)
        b[frame].row(p) += j_global(p) * j_frame.transpose();
      c[frame].noalias() += j_frame * j_frame.transpose();
    }
  }
  for (int f = 0; f < num_frames; ++f) {
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(c[f]);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) {
      return false;
    }
    a.noalias() -= b[f] * ldlt.solve(b[f].transpose());
  }
  // Jacobi scaling first: the parameters differ in scale by many orders
  // (focal lengths, distortion coefficients, angles, metres), and the
  // singularity test should not depend on their units.
  const Eigen::VectorXd diagonal = a.diagonal();
  if (!(diagonal.minCoeff() > 0)) return false;
  const Eigen::VectorXd scale = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * a * scale.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::VectorXd values = eig.eigenvalues();
  if (!(values(0) > min_eigenvalue_ratio * values(n - 1))) return false;
  *covariance = scale.asDiagonal() *
                (eig.eigenvectors() * values.cwiseInverse().asDiagonal() *
                 eig.eigenvectors().transpose()) *
                scale.asDiagonal();
  return true;
}

// The small rotation (rig frame of the camera, angle-axis) that takes
// R(pose) to R(pose + delta), to first order: its 3x6 Jacobian in delta.
Eigen::Matrix<double, 3, 6> RotationJacobian(const Pose& pose) {
  Eigen::Matrix<double, 3, 6> jacobian = Eigen::Matrix<double, 3, 6>::Zero();
  const Eigen::Matrix3d r0 = IsometryFromPoseBlock(pose.data()).linear();
  constexpr double kStep = 1e-7;
  for (int k = 0; k < 3; ++k) {
    Pose plus = pose, minus = pose;
    plus[k] += kStep;
    minus[k] -= kStep;
    const Eigen::AngleAxisd dp(IsometryFromPoseBlock(plus.data()).linear() *
                               r0.transpose());
    const Eigen::AngleAxisd dm(IsometryFromPoseBlock(minus.data()).linear() *
                               r0.transpose());
    jacobian.col(k) =
        (dp.angle() * dp.axis() - dm.angle() * dm.axis()) / (2 * kStep);
  }
  return jacobian;
}

// Distance of the camera centre (-R' t) from the rig origin, and its 1x6
// Jacobian.
double Baseline(const Pose& pose, Eigen::Matrix<double, 1, 6>* jacobian) {
  auto centre_norm = [](const Pose& p) {
    const Eigen::Isometry3d t = IsometryFromPoseBlock(p.data());
    return (t.linear().transpose() * t.translation()).norm();
  };
  const double value = centre_norm(pose);
  constexpr double kStep = 1e-7;
  for (int k = 0; k < 6; ++k) {
    Pose plus = pose, minus = pose;
    plus[k] += kStep;
    minus[k] -= kStep;
    (*jacobian)(k) = (centre_norm(plus) - centre_norm(minus)) / (2 * kStep);
  }
  return value;
}

// Robust relative pose from per-frame estimates: the rotation closest to
// all others (least summed angle), the quaternion mean of the estimates
// within `max_deviation_deg` of it and the per-axis median of their
// translations.
Eigen::Isometry3d RobustAverage(const std::vector<Eigen::Isometry3d>& samples,
                                double max_deviation_deg) {
  size_t best = 0;
  double best_sum = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < samples.size(); ++i) {
    double sum = 0;
    for (size_t j = 0; j < samples.size(); ++j) {
      sum += RotationDifferenceDeg(samples[i].linear(), samples[j].linear());
    }
    if (sum < best_sum) {
      best_sum = sum;
      best = i;
    }
  }
  const Eigen::Quaterniond centre(samples[best].linear());
  Eigen::Vector4d quaternion_sum = Eigen::Vector4d::Zero();
  std::array<std::vector<double>, 3> translation;
  for (const Eigen::Isometry3d& sample : samples) {
    if (RotationDifferenceDeg(sample.linear(), samples[best].linear()) >
        max_deviation_deg) {
      continue;
    }
    Eigen::Quaterniond q(sample.linear());
    if (q.dot(centre) < 0) q.coeffs() = -q.coeffs();
    quaternion_sum += q.coeffs();
    for (int k = 0; k < 3; ++k)
      translation[k].push_back(sample.translation()(k));
  }
  Eigen::Quaterniond mean;
  mean.coeffs() = quaternion_sum.normalized();
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.linear() = mean.toRotationMatrix();
  for (int k = 0; k < 3; ++k) result.translation()(k) = Median(translation[k]);
  return result;
}

std::string CameraList(const std::vector<RigCameraInput>& cameras,
                       const std::vector<bool>& member) {
  std::string list;
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (!member[c]) continue;
    if (!list.empty()) list += ", ";
    list += "'" + cameras[c].name + "'";
  }
  return list;
}

// ---- the stages of CalibrateRig ----

using CornerResiduals = std::vector<std::vector<std::vector<Eigen::Vector2d>>>;
using CornerFlags = std::vector<std::vector<std::vector<bool>>>;

// Every camera holds one (possibly empty) view per frame.
bool CheckRigInput(const std::vector<RigCameraInput>& cameras,
                   std::string* error) {
  if (cameras.size() < 2) {
    return Fail("a rig needs at least two cameras (got " +
                    std::to_string(cameras.size()) + ")",
                error);
  }
  const size_t num_frames = cameras[0].frames.size();
  for (const RigCameraInput& camera : cameras) {
    if (camera.frames.size() != num_frames) {
      return Fail("camera '" + camera.name + "' has " +
                      std::to_string(camera.frames.size()) +
                      " frames, camera '" + cameras[0].name + "' has " +
                      std::to_string(num_frames) +
                      " (give every camera one view per frame, empty where "
                      "it did not see the board)",
                  error);
    }
  }
  return true;
}

// Stage 1: each camera alone, in parallel over cameras (each solve is
// sequential, so the result does not depend on the thread count).
bool CalibrateEachCamera(const std::vector<RigCameraInput>& cameras,
                         const CalibrationOptions& options,
                         std::vector<CalibrationResult>* single,
                         std::string* error) {
  const size_t num_cameras = cameras.size();
  single->assign(num_cameras, CalibrationResult());
  std::vector<std::string> single_error(num_cameras);
  std::vector<char> single_ok(num_cameras, 0);
  ParallelFor(static_cast<int>(num_cameras), options.num_threads, [&](int c) {
    CalibrationOptions camera_options = options;
    camera_options.fixed_params.insert(camera_options.fixed_params.end(),
                                       cameras[c].fixed_params.begin(),
                                       cameras[c].fixed_params.end());
    if (!cameras[c].initial_params.empty()) {
      camera_options.initial_params = cameras[c].initial_params;
    }
    single_ok[c] = Calibrate(cameras[c].frames, cameras[c].model,
                             cameras[c].width, cameras[c].height,
                             camera_options, &(*single)[c], &single_error[c]);
  });
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!single_ok[c]) {
      return Fail("camera '" + cameras[c].name +
                      "' cannot be calibrated alone: " + single_error[c],
                  error);
    }
  }
  return true;
}

// Why the cameras outside `in_tree` cannot be placed in the rig.
bool FailUnplacedCameras(const std::vector<RigCameraInput>& cameras,
                         const std::vector<bool>& in_tree,
                         const Eigen::MatrixXi& posed_shared,
                         int min_shared_frames, std::string* error) {
  const size_t num_cameras = cameras.size();
  for (size_t c = 0; c < num_cameras; ++c) {
    if (in_tree[c]) continue;
    bool shares_any = false;
    for (size_t o = 0; o < num_cameras; ++o) {
      shares_any |= o != c && posed_shared(c, o) >= min_shared_frames;
    }
    if (!shares_any) {
      return Fail("camera '" + cameras[c].name +
                      "' shares no frame with any other camera (no instant "
                      "at which it and another camera both see the board), "
                      "so its place in the rig is undetermined: take photos "
                      "in which it and a neighbouring camera see the board "
                      "together",
                  error);
    }
    std::vector<bool> outside(num_cameras);
    for (size_t o = 0; o < num_cameras; ++o) outside[o] = !in_tree[o];
    return Fail("cameras " + CameraList(cameras, outside) +
                    " share no frame with the reference camera's group (" +
                    CameraList(cameras, in_tree) +
                    "), so their place in the rig is undetermined: take "
                    "photos in which a camera of each group sees the board",
                error);
  }
  return true;
}

// Stage 2a: the half-turn ambiguity of a symmetric board between cameras a
// (already placed) and b. Each shared frame gives b's pose relative to a
// as labelled and, for a symmetric board, with b's labels turned by half a
// turn. The candidate that the most frames agree with (one way or the
// other, within max_deviation_deg; the labels as found win ties) fixes the
// convention: a frame that agrees only with its labels turned gets b's
// labels turned (board points and b's own pose of the frame); a frame that
// agrees neither way gets a note and is left out. False, with the reason,
// when no candidate has a majority of the frames.
bool ResolveHalfTurns(int a, int b, const RigBoardSymmetry& symmetry,
                      double max_deviation_deg,
                      std::vector<RigCameraInput>* inputs,
                      std::vector<CalibrationResult>* singles,
                      std::vector<RigCameraResult>* out, std::string* error) {
  std::vector<CalibrationResult>& single = *singles;
  const size_t num_frames = (*inputs)[0].frames.size();
  Eigen::Isometry3d half_turn = Eigen::Isometry3d::Identity();
  half_turn.linear() = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  half_turn.translation() =
      Eigen::Vector3d(2 * symmetry.centre.x(), 2 * symmetry.centre.y(), 0);
  std::vector<size_t> frames;
  std::vector<Eigen::Matrix3d> as_found, turned;
  for (size_t f = 0; f < num_frames; ++f) {
    if (single[a].view_used[f] && single[b].view_used[f]) {
      frames.push_back(f);
      const Eigen::Isometry3d a_inv = single[a].cam_from_board[f].inverse();
      as_found.push_back((single[b].cam_from_board[f] * a_inv).linear());
      turned.push_back(
          (single[b].cam_from_board[f] * half_turn * a_inv).linear());
    }
  }
  if (frames.size() < 2) return true;
  std::vector<const Eigen::Matrix3d*> candidates;
  for (const Eigen::Matrix3d& r : as_found) candidates.push_back(&r);
  if (symmetry.half_turn) {
    for (const Eigen::Matrix3d& r : turned) candidates.push_back(&r);
  }
  const Eigen::Matrix3d* centre = candidates[0];
  int best_count = -1;
  for (const Eigen::Matrix3d* candidate : candidates) {
    int count = 0;
    for (size_t k = 0; k < frames.size(); ++k) {
      const bool agrees =
          RotationDifferenceDeg(as_found[k], *candidate) <= max_deviation_deg ||
          (symmetry.half_turn &&
           RotationDifferenceDeg(turned[k], *candidate) <= max_deviation_deg);
      count += agrees ? 1 : 0;
    }
    if (count > best_count) {
      best_count = count;
      centre = candidate;
    }
  }
  // The rig's relative pose is the one most frames agree on; when no
  // majority agrees on any, the frames do not show one rig (unsynchronised
  // or mismatched folders: each pair of photos shows the board at two
  // moments), and the few that agree by chance would make a rig of noise.
  if (2 * best_count <= static_cast<int>(frames.size())) {
    double spread = 0;
    for (const Eigen::Matrix3d& r : as_found) {
      spread = std::max(spread, RotationDifferenceDeg(r, *centre));
    }
    return Fail(
        StringPrintf("cameras '%s' and '%s' do not agree on one relative "
                     "pose: of the %zu frames both posed, at most %d agree "
                     "within %.1f deg (the board's pose seen by '%s' relative "
                     "to '%s' varies by up to %.0f deg); the folders' photos "
                     "do not look like the same instants: check that the same "
                     "file name (with --match_by_order, the same position) in "
                     "every folder is one instant and that the cameras were "
                     "triggered together",
                     (*out)[a].name.c_str(), (*out)[b].name.c_str(),
                     frames.size(), best_count, max_deviation_deg,
                     (*out)[b].name.c_str(), (*out)[a].name.c_str(), spread),
        error);
  }
  RigCameraResult& note_b = (*out)[b];
  for (size_t k = 0; k < frames.size(); ++k) {
    const size_t f = frames[k];
    const double before = RotationDifferenceDeg(as_found[k], *centre);
    if (before <= max_deviation_deg) continue;
    const double after = RotationDifferenceDeg(turned[k], *centre);
    if (symmetry.half_turn && after <= max_deviation_deg) {
      CalibrationView& view = (*inputs)[b].frames[f];
      for (Eigen::Vector3d& point : view.board_points)
        point = half_turn * point;
      single[b].cam_from_board[f] = single[b].cam_from_board[f] * half_turn;
      note_b.relabelled[f] = true;
      note_b.frame_note[f] = StringPrintf(
          "board labels turned by half a turn to agree with '%s' (the "
          "symmetric board's poses were %.1f deg apart, %.2f deg after)",
          (*out)[a].name.c_str(), before, after);
      continue;
    }
    // Neither way: b's view of the frame is left out of the rig.
    single[b].view_used[f] = false;
    (*inputs)[b].frames[f] = CalibrationView();
    note_b.start_disagreement_deg[f] =
        symmetry.half_turn ? std::min(before, after) : before;
    if (symmetry.half_turn) {
      note_b.frame_note[f] = StringPrintf(
          "its board pose relative to '%s' is %.1f deg from the rig's, %.1f "
          "deg with its labels turned by half a turn: not the board's "
          "symmetry",
          (*out)[a].name.c_str(), before, after);
    } else {
      note_b.frame_note[f] = StringPrintf(
          "its board pose relative to '%s' is %.1f deg from the rig's",
          (*out)[a].name.c_str(), before);
    }
  }
  return true;
}

// Stage 2: the starting cam_from_rig of every camera, from the frames two
// cameras share, chained along the maximum spanning tree of shared frames
// from the reference camera. `start_parent` receives each camera's parent
// in that tree (-1 for the reference).
bool StartCamFromRig(std::vector<RigCameraInput>* inputs,
                     std::vector<CalibrationResult>* singles,
                     const RigBoardSymmetry& symmetry,
                     const RigCalibrationOptions& options,
                     std::vector<Eigen::Isometry3d>* cam_from_rig,
                     std::vector<int>* start_parent,
                     std::vector<RigCameraResult>* out, std::string* error) {
  const std::vector<RigCameraInput>& cameras = *inputs;
  const std::vector<CalibrationResult>& single = *singles;
  const size_t num_cameras = cameras.size();
  const size_t num_frames = cameras[0].frames.size();
  Eigen::MatrixXi posed_shared =
      Eigen::MatrixXi::Zero(num_cameras, num_cameras);
  for (size_t a = 0; a < num_cameras; ++a) {
    for (size_t b = 0; b < num_cameras; ++b) {
      for (size_t f = 0; f < num_frames; ++f) {
        posed_shared(a, b) += single[a].view_used[f] && single[b].view_used[f];
      }
    }
  }
  std::vector<bool> in_tree(num_cameras, false);
  cam_from_rig->assign(num_cameras, Eigen::Isometry3d::Identity());
  start_parent->assign(num_cameras, -1);
  in_tree[0] = true;
  for (;;) {
    int best_a = -1, best_b = -1, best_count = 0;
    for (size_t a = 0; a < num_cameras; ++a) {
      if (!in_tree[a]) continue;
      for (size_t b = 0; b < num_cameras; ++b) {
        if (in_tree[b]) continue;
        const int count = posed_shared(a, b);
        if (count >= options.min_shared_frames && count > best_count) {
          best_count = count;
          best_a = static_cast<int>(a);
          best_b = static_cast<int>(b);
        }
      }
    }
    if (best_b < 0) break;
    if (!ResolveHalfTurns(best_a, best_b, symmetry,
                          options.max_start_rotation_deviation_deg, inputs,
                          singles, out, error)) {
      return false;
    }
    std::vector<Eigen::Isometry3d> samples;  // cam_b_from_cam_a per frame
    for (size_t f = 0; f < num_frames; ++f) {
      if (single[best_a].view_used[f] && single[best_b].view_used[f]) {
        samples.push_back(single[best_b].cam_from_board[f] *
                          single[best_a].cam_from_board[f].inverse());
      }
    }
    (*cam_from_rig)[best_b] =
        RobustAverage(samples, options.max_start_rotation_deviation_deg) *
        (*cam_from_rig)[best_a];
    (*start_parent)[best_b] = best_a;
    in_tree[best_b] = true;
  }
  return FailUnplacedCameras(cameras, in_tree, posed_shared,
                             options.min_shared_frames, error);
}

// Stage 3: the joint state at its start. Intrinsics from each camera's own
// calibration; rig_from_board of each frame from the camera that saw the
// most corners in it; the (camera, frame) pairs and corners that take part:
// finite corners that project with the starting state, at least
// min_corners_per_view of them.
void StartJointState(const std::vector<RigCameraInput>& cameras,
                     const std::vector<CalibrationResult>& single,
                     const std::vector<Eigen::Isometry3d>& cam_from_rig,
                     int min_corners_per_view, JointState* state) {
  const size_t num_cameras = cameras.size();
  const size_t num_frames = cameras[0].frames.size();
  state->input = &cameras;
  state->fixed.resize(num_cameras);
  for (size_t c = 0; c < num_cameras; ++c) {
    state->num_params.push_back(
        static_cast<int>(single[c].camera.params.size()));
    state->params_offset.push_back(state->global.size());
    state->global.insert(state->global.end(), single[c].camera.params.begin(),
                         single[c].camera.params.end());
    state->extrinsics_offset.push_back(state->global.size());
    const Pose pose = PoseBlockFromIsometry(cam_from_rig[c]);
    state->global.insert(state->global.end(), pose.begin(), pose.end());
    state->fixed[c] = single[c].param_fixed;
  }
  state->rig_from_board.assign(num_frames, Pose{});
  state->frame_posed.assign(num_frames, false);
  for (size_t f = 0; f < num_frames; ++f) {
    int best = -1;
    size_t best_corners = 0;
    for (size_t c = 0; c < num_cameras; ++c) {
      if (single[c].view_used[f] &&
          cameras[c].frames[f].board_points.size() > best_corners) {
        best = static_cast<int>(c);
        best_corners = cameras[c].frames[f].board_points.size();
      }
    }
    if (best < 0) continue;
    state->rig_from_board[f] = PoseBlockFromIsometry(
        cam_from_rig[best].inverse() * single[best].cam_from_board[f]);
    state->frame_posed[f] = true;
  }
  state->used.assign(num_cameras, std::vector<bool>(num_frames, false));
  state->valid.resize(num_cameras);
  for (size_t c = 0; c < num_cameras; ++c) {
    state->valid[c].resize(num_frames);
    for (size_t f = 0; f < num_frames; ++f) {
      const CalibrationView& view = cameras[c].frames[f];
      const size_t n = view.board_points.size();
      state->valid[c][f].assign(n, false);
      if (!state->frame_posed[f] || view.image_points.size() != n) continue;
      int good = 0;
      for (size_t i = 0; i < n; ++i) {
        Eigen::Vector2d r;
        const bool ok = view.board_points[i].allFinite() &&
                        view.image_points[i].allFinite() &&
                        Residual(*state, c, f, i, &r);
        state->valid[c][f][i] = ok;
        good += ok ? 1 : 0;
      }
      state->used[c][f] = good >= min_corners_per_view;
    }
  }
  state->inlier = state->valid;
}

// The residual of every valid corner of every used (camera, frame);
// `projects` is false (and the residual NaN) where the corner does not
// project with the current state.
void ComputeJointResiduals(const JointState& state, CornerResiduals* residuals,
                           CornerFlags* projects) {
  const std::vector<RigCameraInput>& cameras = *state.input;
  const size_t num_cameras = cameras.size();
  const size_t num_frames = cameras[0].frames.size();
  residuals->assign(num_cameras, {});
  projects->assign(num_cameras, {});
  for (size_t c = 0; c < num_cameras; ++c) {
    (*residuals)[c].assign(num_frames, {});
    (*projects)[c].assign(num_frames, {});
    for (size_t f = 0; f < num_frames; ++f) {
      if (!state.used[c][f]) continue;
      const size_t n = cameras[c].frames[f].board_points.size();
      (*residuals)[c][f].assign(n, Eigen::Vector2d::Zero());
      (*projects)[c][f].assign(n, false);
      for (size_t i = 0; i < n; ++i) {
        if (!state.valid[c][f][i]) continue;
        Eigen::Vector2d r;
        if (Residual(state, c, f, i, &r)) {
          (*residuals)[c][f][i] = r;
          (*projects)[c][f][i] = true;
        } else {
          (*residuals)[c][f][i].setConstant(
              std::numeric_limits<double>::quiet_NaN());
        }
      }
    }
  }
}

// One round of k-sigma rejection per camera (the threshold from the MAD of
// that camera's residual coordinates, with a floor); a (camera, frame) left
// with too few corners drops out. True when any inlier flag changed.
bool RejectJointOutliers(const CornerResiduals& residuals,
                         const CornerFlags& projects,
                         const CalibrationOptions& options, JointState* state) {
  bool changed = false;
  for (size_t c = 0; c < residuals.size(); ++c) {
    std::vector<double> coordinates;
    for (size_t f = 0; f < residuals[c].size(); ++f) {
      for (size_t i = 0; i < residuals[c][f].size(); ++i) {
        if (!projects[c][f][i]) continue;
        coordinates.push_back(residuals[c][f][i].x());
        coordinates.push_back(residuals[c][f][i].y());
      }
    }
    const double threshold =
        std::max(options.outlier_k * RobustSigmaAboutZero(coordinates),
                 options.min_outlier_threshold_px);
    for (size_t f = 0; f < residuals[c].size(); ++f) {
      if (!state->used[c][f]) continue;
      int kept = 0;
      for (size_t i = 0; i < residuals[c][f].size(); ++i) {
        const bool keep =
            projects[c][f][i] && residuals[c][f][i].norm() <= threshold;
        changed |= keep != state->inlier[c][f][i];
        state->inlier[c][f][i] = keep;
        kept += keep ? 1 : 0;
      }
      if (kept < options.min_corners_per_view) {
        state->used[c][f] = false;
        std::fill(state->inlier[c][f].begin(), state->inlier[c][f].end(),
                  false);
        changed = true;
      }
    }
  }
  return changed;
}

// Stage 4: joint solves, each followed by a rejection round, until no
// inlier changes or the round limit is reached.
struct JointSolveRun {
  std::unique_ptr<ceres::LossFunction> loss;
  SolveOutcome outcome;
  CornerResiduals residuals;
  CornerFlags projects;
  int iterations = 0;
  int rounds = 0;
};

void SolveWithOutlierRejection(const CalibrationOptions& options,
                               JointState* state, JointSolveRun* run) {
  // Each rejection round continues with the radius the solve before it
  // ended with (see CalibrationOptions::initial_trust_region_radius).
  double radius = options.initial_trust_region_radius;
  auto solve = [&] {
    SolveJoint(state, options, radius, &run->loss, &run->outcome);
    const auto& iterations = run->outcome.summary.iterations;
    run->iterations += static_cast<int>(iterations.size());
    if (!iterations.empty()) {
      radius = ContinuedTrustRegionRadius(iterations.back().trust_region_radius,
                                          options);
    }
    ComputeJointResiduals(*state, &run->residuals, &run->projects);
  };
  solve();
  while (options.outlier_k > 0 && run->rounds < options.outlier_iterations &&
         run->outcome.summary.IsSolutionUsable()) {
    if (!RejectJointOutliers(run->residuals, run->projects, options, state)) {
      break;
    }
    ++run->rounds;
    solve();
  }
}

// Stage 5: the per-camera and rig-wide figures of the final state. Returns
// the sum of squared inlier residuals over all cameras.
double FillRigResult(const JointState& state, const JointSolveRun& run,
                     RigCalibrationResult* result) {
  const size_t num_cameras = result->cameras.size();
  const size_t num_frames = result->frame_used.size();
  result->outlier_rounds = run.rounds;
  result->iterations = run.iterations;
  result->termination = run.outcome.summary.message;
  double sum2_all = 0;
  int corners_all = 0, outliers_all = 0;
  for (size_t c = 0; c < num_cameras; ++c) {
    RigCameraResult& out = result->cameras[c];
    out.camera.params = state.Params(c);
    out.param_fixed = state.fixed[c];
    out.param_stddev.assign(state.num_params[c], 0.0);
    out.cam_from_rig = IsometryFromPoseBlock(state.cam_from_rig(c));
    if (c == 0) out.cam_from_rig = Eigen::Isometry3d::Identity();
    out.frame_used = state.used[c];
    out.residuals = run.residuals[c];
    out.inlier.resize(num_frames);
    double sum2 = 0;
    for (size_t f = 0; f < num_frames; ++f) {
      out.inlier[f] = state.used[c][f]
                          ? state.inlier[c][f]
                          : std::vector<bool>(state.inlier[c][f].size(), false);
      if (!state.used[c][f]) continue;
      ++out.num_frames_used;
      result->frame_used[f] = true;
      for (size_t i = 0; i < run.residuals[c][f].size(); ++i) {
        if (state.inlier[c][f][i]) {
          sum2 += run.residuals[c][f][i].squaredNorm();
          ++out.num_corners_used;
        } else if (state.valid[c][f][i]) {
          ++out.num_outliers;
        }
      }
    }
    out.rms_px = out.num_corners_used > 0
                     ? std::sqrt(sum2 / (2.0 * out.num_corners_used))
                     : 0.0;
    Eigen::Matrix<double, 1, 6> g;
    out.baseline_m = Baseline(state.CamFromRig(c), &g);
    if (c == 0) out.baseline_m = 0;
    sum2_all += sum2;
    corners_all += out.num_corners_used;
    outliers_all += out.num_outliers;
  }
  for (size_t a = 0; a < num_cameras; ++a) {
    for (size_t b = 0; b < num_cameras; ++b) {
      for (size_t f = 0; f < num_frames; ++f) {
        result->shared_frames(a, b) += state.used[a][f] && state.used[b][f];
      }
    }
  }
  for (size_t f = 0; f < num_frames; ++f) {
    if (!result->frame_used[f]) continue;
    ++result->num_frames_used;
    result->rig_from_board[f] =
        IsometryFromPoseBlock(state.rig_from_board[f].data());
  }
  result->num_corners_used = corners_all;
  result->num_outliers = outliers_all;
  result->rms_px =
      corners_all > 0 ? std::sqrt(sum2_all / (2.0 * corners_all)) : 0.0;
  return sum2_all;
}

// Why each camera's view of a frame that is not used was left out.
void NoteUnusedViews(const std::vector<RigCameraInput>& cameras,
                     const std::vector<CalibrationResult>& single,
                     const JointState& state, RigCalibrationResult* result) {
  for (size_t c = 0; c < cameras.size(); ++c) {
    RigCameraResult& out = result->cameras[c];
    for (size_t f = 0; f < cameras[c].frames.size(); ++f) {
      if (state.used[c][f] || cameras[c].frames[f].board_points.empty()) {
        continue;
      }
      std::string why;
      if (!out.frame_note[f].empty() && !out.relabelled[f]) {
        why = out.frame_note[f];
      } else if (!single[c].view_used[f]) {
        why = "its own calibration left the view out";
        if (f < single[c].view_reason.size() &&
            !single[c].view_reason[f].empty()) {
          why += " (" + single[c].view_reason[f] + ")";
        }
      } else if (!state.frame_posed[f]) {
        why = "no camera posed the board in this frame";
      } else {
        why =
            "too few of its corners fit the rig (outliers of the joint "
            "solve)";
      }
      out.frame_note[f] = "not used: " + why;
    }
  }
}

// Stage 6: σ of every free intrinsic and of each cam_from_rig (rotation in
// degrees, translation, baseline), from the joint covariance scaled by the
// residual variance (from `sum2_all`, the sum of squared inlier residuals).
// Leaves covariance_ok false when it is singular.
void FillRigCovariance(const JointState& state, double sum2_all,
                       double min_eigenvalue_ratio, SolveOutcome* outcome,
                       RigCalibrationResult* result) {
  GlobalLayout layout;
  Eigen::MatrixXd covariance;
  if (!JointMarginalCovariance(state, outcome, min_eigenvalue_ratio, &layout,
                               &covariance)) {
    return;
  }
  const int corners_all = result->num_corners_used;
  const int free_params =
      layout.size + kPoseBlockSize * result->num_frames_used;
  if (2 * corners_all <= free_params) return;
  covariance *= sum2_all / (2.0 * corners_all - free_params);
  result->covariance_ok = true;
  for (size_t c = 0; c < result->cameras.size(); ++c) {
    RigCameraResult& out = result->cameras[c];
    if (layout.params_begin[c] >= 0) {
      int index = layout.params_begin[c];
      const std::vector<bool> tangent_fixed = state.TangentFixed(c);
      for (int k = 0; k < state.num_params[c]; ++k) {
        if (tangent_fixed[k]) continue;
        out.param_stddev[k] =
            std::sqrt(std::max(0.0, covariance(index, index)));
        ++index;
      }
      // fy is fx.
      if (state.same_focal) out.param_stddev[1] = out.param_stddev[0];
    }
    if (layout.extrinsics_begin[c] < 0) continue;
    const int e = layout.extrinsics_begin[c];
    out.extrinsics_covariance = covariance.block<6, 6>(e, e);
    const Eigen::Matrix<double, 3, 6> jr =
        RotationJacobian(state.CamFromRig(c));
    out.rotation_stddev_deg =
        std::sqrt(std::max(
            0.0, (jr * out.extrinsics_covariance * jr.transpose()).trace())) /
        kDegree;
    for (int k = 0; k < 3; ++k) {
      out.translation_stddev_m(k) =
          std::sqrt(std::max(0.0, out.extrinsics_covariance(3 + k, 3 + k)));
    }
    Eigen::Matrix<double, 1, 6> g;
    Baseline(state.CamFromRig(c), &g);
    out.baseline_stddev_m = std::sqrt(
        std::max(0.0, (g * out.extrinsics_covariance * g.transpose())(0, 0)));
  }
}

// Stage 7: a result the user can rely on, or the reason it is not one:
// the solve converged, every camera still reaches the reference through
// shared frames after outlier rejection, every RMS is within its limit and
// every free focal length is determined.
bool CheckRigResult(const std::vector<RigCameraInput>& cameras,
                    const ceres::Solver::Summary& summary,
                    const CalibrationOptions& options,
                    const RigCalibrationResult& result, std::string* error) {
  if (!summary.IsSolutionUsable()) {
    return Fail("the joint bundle adjustment failed: " + summary.message,
                error);
  }
  if (summary.termination_type == ceres::NO_CONVERGENCE) {
    return Fail("the joint bundle adjustment did not converge within " +
                    std::to_string(options.max_iterations) +
                    " iterations (RMS " + StringPrintf("%.3f", result.rms_px) +
                    " px): raise the iteration limit or check the "
                    "correspondences",
                error);
  }
  const size_t num_cameras = cameras.size();
  std::vector<bool> reached(num_cameras, false);
  reached[0] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (size_t a = 0; a < num_cameras; ++a) {
      for (size_t b = 0; b < num_cameras; ++b) {
        if (reached[a] && !reached[b] && result.shared_frames(a, b) > 0) {
          reached[b] = true;
          grew = true;
        }
      }
    }
  }
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!reached[c]) {
      return Fail("camera '" + cameras[c].name +
                      "' shares no frame with the reference camera's group "
                      "after outlier rejection, so its place in the rig is "
                      "undetermined: take photos in which it and a "
                      "neighbouring camera see the board together",
                  error);
    }
  }
  for (const RigCameraResult& out : result.cameras) {
    if (!(out.rms_px <= options.max_rms_px)) {
      return Fail("camera '" + out.name +
                      "': the reprojection RMS of the "
                      "joint solve is " +
                      StringPrintf("%.2f", out.rms_px) + " px (limit " +
                      StringPrintf("%.2f", options.max_rms_px) +
                      " px): the frames of the folders may not be the same "
                      "instants, or the rig moved between photos",
                  error);
    }
    for (int k = 0; k < 2; ++k) {
      if (result.covariance_ok && !out.param_fixed[k] &&
          !(out.param_stddev[k] <= options.max_focal_relative_stddev *
                                       std::abs(out.camera.params[k]))) {
        return Fail("camera '" + out.name +
                        "': the frames do not determine the focal length (" +
                        StringPrintf("%.1f", out.camera.params[k]) + " +- " +
                        StringPrintf("%.3g", out.param_stddev[k]) +
                        " px): add photos with the board tilted",
                    error);
      }
    }
  }
  return true;
}

}  // namespace

double RotationDifferenceDeg(const Eigen::Matrix3d& a,
                             const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() / kDegree;
}

bool RigCalibrationOptions::Check(std::string* why) const {
  if (min_shared_frames < 1) {
    return Fail("min_shared_frames must be >= 1", why);
  }
  if (!(max_start_rotation_deviation_deg > 0)) {
    return Fail("max_start_rotation_deviation_deg must be > 0", why);
  }
  return camera.Check(why);
}

bool CalibrateRig(const std::vector<RigCameraInput>& cameras,
                  const RigCalibrationOptions& options,
                  RigCalibrationResult* result, std::string* error) {
  return CalibrateRig(cameras, RigBoardSymmetry(), options, result, error);
}

bool CalibrateRig(const std::vector<RigCameraInput>& input_cameras,
                  const RigBoardSymmetry& symmetry,
                  const RigCalibrationOptions& options,
                  RigCalibrationResult* result, std::string* error) {
  *result = RigCalibrationResult();
  // A copy: a symmetric board's views may be relabelled.
  std::vector<RigCameraInput> cameras = input_cameras;
  std::string why;
  if (!options.Check(&why))
    return Fail("rig calibration options: " + why, error);
  if (!CheckRigInput(cameras, error)) return false;
  const size_t num_cameras = cameras.size();
  const size_t num_frames = cameras[0].frames.size();
  const CalibrationOptions& copt = options.camera;
  result->cameras.resize(num_cameras);
  result->frame_used.assign(num_frames, false);
  result->rig_from_board.assign(num_frames, Eigen::Isometry3d::Identity());
  result->shared_frames = Eigen::MatrixXi::Zero(num_cameras, num_cameras);
  for (size_t c = 0; c < num_cameras; ++c) {
    result->cameras[c].name = cameras[c].name;
    result->cameras[c].camera.model = cameras[c].model;
    result->cameras[c].camera.width = cameras[c].width;
    result->cameras[c].camera.height = cameras[c].height;
    result->cameras[c].relabelled.assign(num_frames, false);
    result->cameras[c].frame_note.assign(num_frames, "");
    result->cameras[c].start_disagreement_deg.assign(num_frames, 0.0);
  }

  const Timer single_timer;
  std::vector<CalibrationResult> single;
  const bool single_ok = CalibrateEachCamera(cameras, copt, &single, error);
  result->seconds_single = single_timer.Seconds();
  for (size_t c = 0; c < num_cameras && c < single.size(); ++c) {
    result->cameras[c].single = single[c];
    result->cameras[c].single_rms_px = single[c].rms_px;
    result->cameras[c].single_views_used = single[c].num_views_used;
  }
  if (!single_ok) return false;

  const Timer joint_timer;
  std::vector<Eigen::Isometry3d> cam_from_rig;
  if (!StartCamFromRig(&cameras, &single, symmetry, options, &cam_from_rig,
                       &result->start_parent, &result->cameras, error)) {
    return false;
  }
  for (size_t c = 0; c < num_cameras; ++c) {
    result->cameras[c].alone_cam_from_board = single[c].cam_from_board;
    result->cameras[c].alone_posed = single[c].view_used;
  }
  if (symmetry.half_turn) {
    result->half_turn.linear() = Eigen::Vector3d(-1, -1, 1).asDiagonal();
    result->half_turn.translation() =
        Eigen::Vector3d(2 * symmetry.centre.x(), 2 * symmetry.centre.y(), 0);
  }
  JointState state;
  state.same_focal = copt.same_focal_length;
  StartJointState(cameras, single, cam_from_rig, copt.min_corners_per_view,
                  &state);
  JointSolveRun run;
  SolveWithOutlierRejection(copt, &state, &run);
  const double sum2_all = FillRigResult(state, run, result);
  NoteUnusedViews(input_cameras, single, state, result);
  if (copt.compute_covariance && run.outcome.problem &&
      run.outcome.summary.IsSolutionUsable()) {
    FillRigCovariance(state, sum2_all, copt.covariance_min_eigenvalue_ratio,
                      &run.outcome, result);
  }
  result->seconds_joint = joint_timer.Seconds();
  return CheckRigResult(cameras, run.outcome.summary, copt, *result, error);
}

std::string RigCalibrationReport(const RigCalibrationResult& result) {
  std::ostringstream out;
  out << "rig: " << result.cameras.size() << " cameras, "
      << result.num_frames_used << " of " << result.frame_used.size()
      << " frames used, " << result.num_corners_used << " corners, "
      << result.num_outliers << " outliers (" << result.outlier_rounds
      << " rejection rounds), RMS " << StringPrintf("%.4f", result.rms_px)
      << " px per coordinate\n";
  for (size_t c = 0; c < result.cameras.size(); ++c) {
    const RigCameraResult& cam = result.cameras[c];
    const std::vector<std::string> names =
        CameraModelParamNames(cam.camera.model);
    out << "camera " << c << " '" << cam.name << "' ("
        << CameraModelName(cam.camera.model) << ", " << cam.camera.width << "x"
        << cam.camera.height << ")" << (c == 0 ? ", the rig frame" : "")
        << "\n";
    for (size_t k = 0; k < names.size() && k < cam.camera.params.size(); ++k) {
      out << "  " << names[k] << " = "
          << StringPrintf("%.10g", cam.camera.params[k]);
      if (cam.param_fixed[k]) {
        out << " (fixed)";
      } else if (result.covariance_ok) {
        out << " +- " << StringPrintf("%.3g", cam.param_stddev[k]);
      }
      out << "\n";
    }
    if (c > 0) {
      const Eigen::AngleAxisd rotation(cam.cam_from_rig.linear());
      const Eigen::Vector3d t = cam.cam_from_rig.translation();
      out << "  cam_from_rig: rotation "
          << StringPrintf("%.5f", rotation.angle() / kDegree) << " deg";
      if (result.covariance_ok) {
        out << " +- " << StringPrintf("%.2g", cam.rotation_stddev_deg);
      }
      out << ", t = (" << StringPrintf("%.6f", t.x()) << ", "
          << StringPrintf("%.6f", t.y()) << ", " << StringPrintf("%.6f", t.z())
          << ") m, baseline " << StringPrintf("%.3f", 1000 * cam.baseline_m)
          << " mm";
      if (result.covariance_ok) {
        out << " +- " << StringPrintf("%.3g", 1000 * cam.baseline_stddev_m)
            << " mm";
      }
      out << " (started from camera " << result.start_parent[c] << ")\n";
    }
    out << "  joint: " << cam.num_frames_used << " frames, "
        << cam.num_corners_used << " corners, " << cam.num_outliers
        << " outliers, RMS " << StringPrintf("%.4f", cam.rms_px)
        << " px; alone: " << cam.single_views_used << " views, RMS "
        << StringPrintf("%.4f", cam.single_rms_px) << " px\n";
  }
  if (!result.covariance_ok) {
    out << "covariance: not available (the problem is rank deficient)\n";
  }
  out << "shared frames:";
  for (int a = 0; a < result.shared_frames.rows(); ++a) {
    for (int b = a + 1; b < result.shared_frames.cols(); ++b) {
      out << " " << a << "-" << b << ": " << result.shared_frames(a, b);
    }
  }
  out << "\nsolver: " << result.iterations << " iterations, "
      << result.termination << "; "
      << StringPrintf("%.3f", result.seconds_single) << " s alone, "
      << StringPrintf("%.3f", result.seconds_joint) << " s joint\n";
  return out.str();
}

}  // namespace puzzlecal
