// ProgressBar: drawing.
#include "apps/cli/progress_bar.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

namespace arpipe {

ProgressBar::ProgressBar(std::string what) : what_(std::move(what)), terminal_(isatty(STDERR_FILENO) == 1) {}

void ProgressBar::update(int done, int total) {
  if (total <= 0) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  const double per_item = done > 0 ? elapsed / done : 0.0;
  const double remaining = per_item * (total - done);
  if (terminal_) {
    constexpr int kWidth = 30;
    const int filled = done * kWidth / total;
    fmt::print(stderr, "\r[{}{}] {}/{} {}  {:.2f} s each, {:.0f} s left ", std::string(size_t(filled), '#'),
               std::string(size_t(kWidth - filled), '-'), done, total, what_, per_item, remaining);
    drawn_ = true;
  } else {
    const int decile = done * 10 / total;
    if (decile == last_decile_) return;
    last_decile_ = decile;
    fmt::print(stderr, "{}/{} {} ({:.2f} s each, {:.0f} s left)\n", done, total, what_, per_item, remaining);
  }
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (terminal_ && drawn_) std::fputc('\n', stderr);
  drawn_ = false;
}

}  // namespace arpipe
