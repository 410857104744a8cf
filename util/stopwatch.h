// Wall-clock timing of phases, in seconds, for reports.
#pragma once

#include <chrono>

namespace polydg {

/// Started when made; seconds() is the wall time since then (or since the last restart()).
class Stopwatch {
 public:
  Stopwatch() : start_(Clock::now()) {}
  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  void restart() { start_ = Clock::now(); }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
};

}  // namespace polydg
