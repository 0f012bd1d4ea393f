#ifndef PUZZLECAL_CALIB_PARALLEL_COSTS_H_
#define PUZZLECAL_CALIB_PARALLEL_COSTS_H_

// Deterministic multi-threaded evaluation of the cost functions of a Ceres
// problem. Ceres's own threads sum the cost, the gradient and the Schur
// complement in the order its threads finish, which changes the last bits of
// the solution from run to run. Here Ceres runs on one thread; an
// EvaluationCallback evaluates every cost's residuals and Jacobians ahead of
// it (the expensive part: automatic differentiation of the projection),
// spread over threads in fixed slices, each cost into its own slot. Ceres
// then reads the slots in its fixed order, so the solution is bit for bit
// the one of a single-threaded solve, whatever the thread count.

#include <ceres/ceres.h>

#include <cstddef>
#include <memory>
#include <vector>

namespace puzzlecal {

class ParallelCosts : public ceres::EvaluationCallback {
 public:
  explicit ParallelCosts(int num_threads);
  ~ParallelCosts() override;
  ParallelCosts(const ParallelCosts&) = delete;
  ParallelCosts& operator=(const ParallelCosts&) = delete;

  // Takes ownership of `cost`, whose parameter blocks are `blocks` (the
  // problem's memory, in the cost's order), and returns the cost function to
  // add to the problem over those blocks in its place. The problem takes
  // ownership of the returned function; this object must outlive the
  // problem.
  ceres::CostFunction* Add(ceres::CostFunction* cost,
                           const std::vector<double*>& blocks);

  void PrepareForEvaluation(bool evaluate_jacobians,
                            bool new_evaluation_point) override;

 private:
  // One cost, and its residuals and Jacobians at the blocks' values.
  struct Slot {
    std::unique_ptr<ceres::CostFunction> cost;
    std::vector<double*> blocks;
    // The residuals, then each block's row-major Jacobian.
    std::vector<double> values;
    // Where each block's Jacobian starts in `values`.
    std::vector<double*> jacobians;
    bool ok = false;
  };
  class Cached;

  void EvaluateSlot(size_t index, bool evaluate_jacobians);

  const int num_threads_;
  std::vector<Slot> slots_;
  bool have_jacobians_ = false;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_CALIB_PARALLEL_COSTS_H_
