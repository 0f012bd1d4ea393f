#include "util/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <vector>

namespace puzzlecal {
namespace {

TEST(ParallelForTest, EveryIndexRunsExactlyOnceForAnyThreadCount) {
  for (int n : {0, 1, 2, 7, 64, 1001}) {
    for (int threads : {1, 2, 3, 8, 2000}) {
      std::vector<std::atomic<int>> runs(n);
      ParallelFor(n, threads, [&](int i) { runs[i].fetch_add(1); });
      for (int i = 0; i < n; ++i) {
        EXPECT_EQ(runs[i].load(), 1) << "n " << n << " threads " << threads;
      }
    }
  }
}

}  // namespace
}  // namespace puzzlecal
