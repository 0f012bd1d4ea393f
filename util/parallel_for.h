#ifndef PUZZLECAL_UTIL_PARALLEL_FOR_H_
#define PUZZLECAL_UTIL_PARALLEL_FOR_H_

// ParallelFor(n, num_threads, fn): fn(i) for every i in [0, n), spread over
// up to num_threads threads (the calling thread is one of them) in fixed
// contiguous slices. Each fn(i) must write only its own output slot; the
// caller then combines the slots in index order, so the result is the same
// for any thread count. Threads are started per call: use it for work of
// at least a few hundred microseconds per call.

#include <algorithm>
#include <thread>
#include <vector>

namespace puzzlecal {

template <typename Fn>
void ParallelFor(int n, int num_threads, Fn&& fn) {
  const int threads = std::max(1, std::min(num_threads, n));
  auto run_slice = [&fn, n, threads](int t) {
    const int begin = static_cast<int>(static_cast<long long>(n) * t / threads);
    const int end =
        static_cast<int>(static_cast<long long>(n) * (t + 1) / threads);
    for (int i = begin; i < end; ++i) fn(i);
  };
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) workers.emplace_back(run_slice, t);
  run_slice(0);
  for (std::thread& worker : workers) worker.join();
}

}  // namespace puzzlecal

#endif  // PUZZLECAL_UTIL_PARALLEL_FOR_H_
