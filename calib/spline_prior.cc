#include "calib/spline_prior.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "util/failure.h"

namespace puzzlecal {
namespace {

constexpr int kK = kSplineKnots;
constexpr int kSecondDifferences = 2 * kK * (kK - 2);
constexpr int kPerComponent = kSecondDifferences + kSplineValues;

// One residual: a weighted sum of control values (their indices within the
// component's K x K values).
struct PriorRow {
  int count = 0;
  int index[3] = {0, 0, 0};
  double weight[3] = {0, 0, 0};
};

// The rows of one component, in the order of SplinePriorResidualCount.
std::vector<PriorRow> ComponentRows(double smoothness, double zero) {
  std::vector<PriorRow> rows;
  rows.reserve(kPerComponent);
  auto second_difference = [&](int a, int b, int c) {
    PriorRow row;
    row.count = 3;
    row.index[0] = a;
    row.index[1] = b;
    row.index[2] = c;
    row.weight[0] = smoothness;
    row.weight[1] = -2 * smoothness;
    row.weight[2] = smoothness;
    rows.push_back(row);
  };
  for (int r = 0; r < kK; ++r) {
    for (int c = 1; c + 1 < kK; ++c) {
      second_difference(r * kK + c - 1, r * kK + c, r * kK + c + 1);
    }
  }
  for (int c = 0; c < kK; ++c) {
    for (int r = 1; r + 1 < kK; ++r) {
      second_difference((r - 1) * kK + c, r * kK + c, (r + 1) * kK + c);
    }
  }
  for (int i = 0; i < kSplineValues; ++i) {
    PriorRow row;
    row.count = 1;
    row.index[0] = i;
    row.weight[0] = zero;
    rows.push_back(row);
  }
  return rows;
}

// The prior over either one block holding a splined model's whole
// intrinsics (`whole_block`) or the knot rows' blocks (each row's (du, dv)
// pairs).
class SplinePriorCost : public ceres::CostFunction {
 public:
  SplinePriorCost(int num_params, bool whole_block, double fx, double fy,
                  const SplinePriorOptions& options)
      : num_params_(num_params),
        whole_block_(whole_block),
        rows_(ComponentRows(options.smoothness_weight, options.zero_weight)),
        scale_{fx, fy} {
    set_num_residuals(SplinePriorResidualCount());
    if (whole_block) {
      mutable_parameter_block_sizes()->push_back(num_params);
    } else {
      mutable_parameter_block_sizes()->assign(kK, 2 * kK);
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    constexpr int kBegin = KannalaBrandtSplinedModel::kSplineBegin;
    // Where value `component` of knot `knot` lives: block and offset.
    auto block_of = [&](int knot) { return whole_block_ ? 0 : knot / kK; };
    auto offset_of = [&](int knot, int component) {
      return whole_block_ ? kBegin + 2 * knot + component
                          : 2 * (knot % kK) + component;
    };
    const int block_width = whole_block_ ? num_params_ : 2 * kK;
    if (jacobians != nullptr) {
      for (int b = 0; b < static_cast<int>(parameter_block_sizes().size());
           ++b) {
        if (jacobians[b] != nullptr) {
          std::fill(jacobians[b], jacobians[b] + num_residuals() * block_width,
                    0.0);
        }
      }
    }
    int out = 0;
    for (int component = 0; component < 2; ++component) {
      for (const PriorRow& row : rows_) {
        double sum = 0;
        for (int k = 0; k < row.count; ++k) {
          const int knot = row.index[k];
          const int block = block_of(knot);
          const int offset = offset_of(knot, component);
          const double w = scale_[component] * row.weight[k];
          sum += w * parameters[block][offset];
          if (jacobians != nullptr && jacobians[block] != nullptr) {
            jacobians[block][out * block_width + offset] = w;
          }
        }
        residuals[out++] = sum;
      }
    }
    return true;
  }

 private:
  const int num_params_;
  const bool whole_block_;
  const std::vector<PriorRow> rows_;
  const double scale_[2];
};

}  // namespace

bool SplinePriorOptions::Check(std::string* why) const {
  if (!(smoothness_weight > 0)) {
    return Fail("spline smoothness_weight must be > 0", why);
  }
  if (!(zero_weight > 0)) return Fail("spline zero_weight must be > 0", why);
  return true;
}

int SplinePriorResidualCount() { return 2 * kPerComponent; }

ceres::CostFunction* CreateSplinePriorCost(CameraModelId model, double fx,
                                           double fy,
                                           const SplinePriorOptions& options,
                                           bool per_knot_blocks) {
  return new SplinePriorCost(CameraModelNumParams(model), !per_knot_blocks,
                             std::abs(fx), std::abs(fy), options);
}

void AddSplinePrior(CameraModelId model, double* intrinsics,
                    const SplinePriorOptions& options,
                    ceres::Problem* problem) {
  if (!CameraModelIsSplined(model)) return;
  problem->AddResidualBlock(
      CreateSplinePriorCost(model, intrinsics[0], intrinsics[1], options),
      nullptr, intrinsics);
}

void AddSplinePriorOnKnots(CameraModelId model, double* intrinsics,
                           const SplinePriorOptions& options,
                           ceres::Problem* problem) {
  if (!CameraModelIsSplined(model)) return;
  std::vector<double*> knots(kK);
  for (int row = 0; row < kK; ++row) {
    knots[row] =
        intrinsics + KannalaBrandtSplinedModel::kSplineBegin + 2 * kK * row;
  }
  problem->AddResidualBlock(
      CreateSplinePriorCost(model, intrinsics[0], intrinsics[1], options,
                            /*per_knot_blocks=*/true),
      nullptr, knots);
}

Eigen::MatrixXd SplinePriorInformation(CameraModelId model, double fx,
                                       double fy,
                                       const SplinePriorOptions& options) {
  const int n = CameraModelNumParams(model);
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(n, n);
  if (!CameraModelIsSplined(model)) return information;
  const std::unique_ptr<ceres::CostFunction> cost(
      CreateSplinePriorCost(model, fx, fy, options));
  const int m = cost->num_residuals();
  const std::vector<double> params(n, 0.0);
  std::vector<double> residuals(m);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>
      jacobian(m, n);
  const double* parameters[1] = {params.data()};
  double* jacobians[1] = {jacobian.data()};
  if (!cost->Evaluate(parameters, residuals.data(), jacobians)) {
    return information;
  }
  information = jacobian.transpose() * jacobian;
  return information;
}

}  // namespace puzzlecal
