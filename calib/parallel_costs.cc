#include "calib/parallel_costs.h"

#include <algorithm>
#include <utility>

#include "util/parallel_for.h"

namespace puzzlecal {
namespace {

// The size of a cost's residuals and Jacobians, laid out as in a Slot.
size_t ValuesSize(const ceres::CostFunction& cost) {
  size_t size = cost.num_residuals();
  for (int block_size : cost.parameter_block_sizes()) {
    size += static_cast<size_t>(cost.num_residuals()) * block_size;
  }
  return size;
}

bool SameValues(const double* a, const double* b, int n) {
  return a == b || std::equal(a, a + n, b);
}

}  // namespace

// Reads its slot, or evaluates directly when Ceres evaluates at other values
// than the problem's blocks hold (then the slot does not describe them).
class ParallelCosts::Cached : public ceres::CostFunction {
 public:
  Cached(const ParallelCosts* owner, size_t index)
      : owner_(owner), index_(index) {
    const ceres::CostFunction& cost = *owner->slots_[index].cost;
    set_num_residuals(cost.num_residuals());
    *mutable_parameter_block_sizes() = cost.parameter_block_sizes();
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Slot& slot = owner_->slots_[index_];
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    const int num_blocks = static_cast<int>(sizes.size());
    const bool jacobians_wanted =
        jacobians != nullptr &&
        std::any_of(jacobians, jacobians + num_blocks,
                    [](double* jacobian) { return jacobian != nullptr; });
    bool current = !jacobians_wanted || owner_->have_jacobians_;
    for (int k = 0; k < num_blocks && current; ++k) {
      current = SameValues(parameters[k], slot.blocks[k], sizes[k]);
    }
    if (!current) return slot.cost->Evaluate(parameters, residuals, jacobians);
    if (!slot.ok) return false;
    const int num_residuals = this->num_residuals();
    const double* values = slot.values.data();
    std::copy(values, values + num_residuals, residuals);
    values += num_residuals;
    for (int k = 0; k < num_blocks; ++k) {
      const int jacobian_size = num_residuals * sizes[k];
      if (jacobians != nullptr && jacobians[k] != nullptr) {
        std::copy(values, values + jacobian_size, jacobians[k]);
      }
      values += jacobian_size;
    }
    return true;
  }

 private:
  const ParallelCosts* owner_;
  size_t index_;
};

ParallelCosts::ParallelCosts(int num_threads)
    : num_threads_(std::max(1, num_threads)) {}

ParallelCosts::~ParallelCosts() = default;

ceres::CostFunction* ParallelCosts::Add(ceres::CostFunction* cost,
                                        const std::vector<double*>& blocks) {
  Slot slot;
  slot.cost.reset(cost);
  slot.blocks = blocks;
  slot.values.resize(ValuesSize(*cost));
  double* next = slot.values.data() + cost->num_residuals();
  for (int block_size : cost->parameter_block_sizes()) {
    slot.jacobians.push_back(next);
    next += static_cast<size_t>(cost->num_residuals()) * block_size;
  }
  slots_.push_back(std::move(slot));
  return new Cached(this, slots_.size() - 1);
}

void ParallelCosts::PrepareForEvaluation(bool evaluate_jacobians,
                                         bool new_evaluation_point) {
  if (!new_evaluation_point && (!evaluate_jacobians || have_jacobians_)) {
    return;
  }
  have_jacobians_ = evaluate_jacobians;
  // One contiguous slice of costs per thread, each cost into its slot.
  ParallelFor(static_cast<int>(slots_.size()), num_threads_,
              [&](int i) { EvaluateSlot(i, evaluate_jacobians); });
}

void ParallelCosts::EvaluateSlot(size_t index, bool evaluate_jacobians) {
  Slot& slot = slots_[index];
  slot.ok =
      slot.cost->Evaluate(slot.blocks.data(), slot.values.data(),
                          evaluate_jacobians ? slot.jacobians.data() : nullptr);
}

}  // namespace puzzlecal
