// A one-line progress bar on stderr for long work: shown only on a terminal, never in CI
// (CI set) or with --quiet, and redrawn at most every 100 ms.
#pragma once

#include <chrono>
#include <string>

namespace polydg::cli {

class ProgressBar {
 public:
  ProgressBar(std::string label, bool quiet);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// Fraction done in [0, 1], and a note after the percentage (e.g. a rate).
  void update(double fraction, const std::string& note = "");
  /// Clears the line.
  void finish();
  bool enabled() const { return enabled_; }

 private:
  std::string label_;
  bool enabled_ = false;
  bool drawn_ = false;
  std::size_t noteWidth_ = 0;  ///< the widest note drawn, to clear
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace polydg::cli
