#include "calib/spline_prior.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "util/failure.h"

namespace puzzlecal {
namespace {

constexpr int kK = kSplineKnots;

// One residual: a weighted sum of control values of one component (0: du,
// 1: dv); the indices are knots (row-major within the K x K grid).
struct PriorRow {
  int component = 0;
  int count = 0;
  int index[3] = {0, 0, 0};
  double weight[3] = {0, 0, 0};
};

PriorRow SecondDifference(int component, int a, int b, int c,
                          double smoothness) {
  PriorRow row;
  row.component = component;
  row.count = 3;
  row.index[0] = a;
  row.index[1] = b;
  row.index[2] = c;
  row.weight[0] = smoothness;
  row.weight[1] = -2 * smoothness;
  row.weight[2] = smoothness;
  return row;
}

PriorRow PullToZero(int component, int knot, double zero) {
  PriorRow row;
  row.component = component;
  row.count = 1;
  row.index[0] = knot;
  row.weight[0] = zero;
  return row;
}

// Appends component `component`'s second differences along knot row r.
void AppendAlongRow(int component, int r, double smoothness,
                    std::vector<PriorRow>* rows) {
  for (int c = 1; c + 1 < kK; ++c) {
    rows->push_back(SecondDifference(component, r * kK + c - 1, r * kK + c,
                                     r * kK + c + 1, smoothness));
  }
}

// Appends its second differences down the columns across knot rows r - 1,
// r, r + 1.
void AppendAcrossRows(int component, int r, double smoothness,
                      std::vector<PriorRow>* rows) {
  for (int c = 0; c < kK; ++c) {
    rows->push_back(SecondDifference(component, (r - 1) * kK + c, r * kK + c,
                                     (r + 1) * kK + c, smoothness));
  }
}

// Appends its pulls towards zero of knot row r's values.
void AppendPullsOfRow(int component, int r, double zero,
                      std::vector<PriorRow>* rows) {
  for (int c = 0; c < kK; ++c) {
    rows->push_back(PullToZero(component, r * kK + c, zero));
  }
}

// Every row of the prior, in the order of SplinePriorResidualCount: per
// component the second differences along each knot row, then down the
// columns (triple of rows by triple), then the pulls towards zero.
std::vector<PriorRow> AllRows(const SplinePriorOptions& options) {
  std::vector<PriorRow> rows;
  rows.reserve(SplinePriorResidualCount());
  for (int component = 0; component < 2; ++component) {
    for (int r = 0; r < kK; ++r) {
      AppendAlongRow(component, r, options.smoothness_weight, &rows);
    }
    for (int r = 1; r + 1 < kK; ++r) {
      AppendAcrossRows(component, r, options.smoothness_weight, &rows);
    }
    for (int r = 0; r < kK; ++r) {
      AppendPullsOfRow(component, r, options.zero_weight, &rows);
    }
  }
  return rows;
}

// Some rows of the prior over either one block holding a splined model's
// whole intrinsics (`first_knot_row` < 0) or the consecutive knot rows'
// blocks first_knot_row, first_knot_row + 1, ... (each row's (du, dv)
// pairs), as many as the rows reach.
class SplinePriorCost : public ceres::CostFunction {
 public:
  SplinePriorCost(int num_params, int first_knot_row, int num_knot_rows,
                  std::vector<PriorRow> rows, double fx, double fy)
      : num_params_(num_params),
        first_knot_row_(first_knot_row),
        rows_(std::move(rows)),
        scale_{fx, fy} {
    set_num_residuals(static_cast<int>(rows_.size()));
    if (first_knot_row_ < 0) {
      mutable_parameter_block_sizes()->push_back(num_params);
    } else {
      mutable_parameter_block_sizes()->assign(num_knot_rows, 2 * kK);
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    constexpr int kBegin = KannalaBrandtSplinedModel::kSplineBegin;
    const bool whole_block = first_knot_row_ < 0;
    // Where value `component` of knot `knot` lives: block and offset.
    auto block_of = [&](int knot) {
      return whole_block ? 0 : knot / kK - first_knot_row_;
    };
    auto offset_of = [&](int knot, int component) {
      return whole_block ? kBegin + 2 * knot + component
                         : 2 * (knot % kK) + component;
    };
    const int block_width = whole_block ? num_params_ : 2 * kK;
    if (jacobians != nullptr) {
      for (int b = 0; b < static_cast<int>(parameter_block_sizes().size());
           ++b) {
        if (jacobians[b] != nullptr) {
          std::fill(jacobians[b], jacobians[b] + num_residuals() * block_width,
                    0.0);
        }
      }
    }
    for (size_t out = 0; out < rows_.size(); ++out) {
      const PriorRow& row = rows_[out];
      double sum = 0;
      for (int k = 0; k < row.count; ++k) {
        const int knot = row.index[k];
        const int block = block_of(knot);
        const int offset = offset_of(knot, row.component);
        const double w = scale_[row.component] * row.weight[k];
        sum += w * parameters[block][offset];
        if (jacobians != nullptr && jacobians[block] != nullptr) {
          jacobians[block][out * block_width + offset] = w;
        }
      }
      residuals[out] = sum;
    }
    return true;
  }

 private:
  const int num_params_;
  const int first_knot_row_;
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

int SplinePriorResidualCount() {
  return 2 * (2 * kK * (kK - 2) + kSplineValues);
}

ceres::CostFunction* CreateSplinePriorCost(CameraModelId model, double fx,
                                           double fy,
                                           const SplinePriorOptions& options) {
  return new SplinePriorCost(CameraModelNumParams(model),
                             /*first_knot_row=*/-1, 0, AllRows(options),
                             std::abs(fx), std::abs(fy));
}

void AddSplinePrior(CameraModelId model, double* intrinsics,
                    const SplinePriorOptions& options,
                    ceres::Problem* problem) {
  if (!CameraModelIsSplined(model)) return;
  problem->AddResidualBlock(
      CreateSplinePriorCost(model, intrinsics[0], intrinsics[1], options),
      nullptr, intrinsics);
}

// One residual block per knot row (its second differences along the row and
// its pulls towards zero) and one per triple of consecutive rows (the second
// differences down the columns through the middle one). One block over all
// rows would add a dense 200 x 200 product of its 520 rows to the reduced
// system at every iteration (a quarter of the corners' share on the
// deltille photos); these add 20 x 20 products of a few rows.
void AddSplinePriorOnKnots(CameraModelId model, double* intrinsics,
                           const SplinePriorOptions& options,
                           ceres::Problem* problem) {
  if (!CameraModelIsSplined(model)) return;
  const double fx = std::abs(intrinsics[0]), fy = std::abs(intrinsics[1]);
  const int num_params = CameraModelNumParams(model);
  auto knot_row = [&](int row) {
    return intrinsics + KannalaBrandtSplinedModel::kSplineBegin + 2 * kK * row;
  };
  for (int r = 0; r < kK; ++r) {
    std::vector<PriorRow> rows;
    for (int component = 0; component < 2; ++component) {
      AppendAlongRow(component, r, options.smoothness_weight, &rows);
      AppendPullsOfRow(component, r, options.zero_weight, &rows);
    }
    problem->AddResidualBlock(
        new SplinePriorCost(num_params, r, 1, std::move(rows), fx, fy), nullptr,
        knot_row(r));
  }
  for (int r = 1; r + 1 < kK; ++r) {
    std::vector<PriorRow> rows;
    for (int component = 0; component < 2; ++component) {
      AppendAcrossRows(component, r, options.smoothness_weight, &rows);
    }
    problem->AddResidualBlock(
        new SplinePriorCost(num_params, r - 1, 3, std::move(rows), fx, fy),
        nullptr, knot_row(r - 1), knot_row(r), knot_row(r + 1));
  }
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
