#ifndef PUZZLECAL_UTIL_TIMER_H_
#define PUZZLECAL_UTIL_TIMER_H_

// Wall-clock timing on the monotonic clock: `Timer timer; ...;
// timer.Seconds()`. For reports and benches only; never for decisions.

#include <chrono>

namespace puzzlecal {

class Timer {
 public:
  Timer() : start_(std::chrono::steady_clock::now()) {}
  // Starts again from now.
  void Restart() { start_ = std::chrono::steady_clock::now(); }
  // Seconds since construction or the last Restart().
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start_)
        .count();
  }
  double Milliseconds() const { return 1e3 * Seconds(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_UTIL_TIMER_H_
