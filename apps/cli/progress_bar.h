// A progress bar on stderr for long utility jobs: redrawn in place on a terminal, a line every
// tenth of the work otherwise (so CI logs stay short).
#pragma once

#include <chrono>
#include <string>

namespace arpipe {

class ProgressBar {
 public:
  explicit ProgressBar(std::string what);  // "frames"
  ~ProgressBar() { finish(); }             // a job that fails midway still ends the bar's line
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  void update(int done, int total);
  void finish();  // ends the line on a terminal

 private:
  std::string what_;
  bool terminal_;
  int last_decile_ = -1;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
};

}  // namespace arpipe
