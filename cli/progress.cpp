#include "cli/progress.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include <unistd.h>

namespace polydg::cli {

ProgressBar::ProgressBar(std::string label, bool quiet) : label_(std::move(label)) {
  const char* ci = std::getenv("CI");
  enabled_ = !quiet && ::isatty(STDERR_FILENO) && !(ci && *ci);
}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double fraction, const std::string& note) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && now - last_ < std::chrono::milliseconds(100) && fraction < 1.0) return;
  last_ = now;
  constexpr int kWidth = 30;
  const double f = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(f * kWidth);
  const std::string text = note.empty() ? note : ", " + note;
  noteWidth_ = std::max(noteWidth_, text.size());  // padded: a shorter note clears a longer one
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%%-*s", label_.c_str(), filled,
               "##############################", kWidth - filled, "", static_cast<int>(100 * f),
               static_cast<int>(noteWidth_), text.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (!enabled_ || !drawn_) return;
  std::fprintf(stderr, "\r%*s\r", static_cast<int>(label_.size() + 40 + noteWidth_), "");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace polydg::cli
