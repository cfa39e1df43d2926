#include "render/gl/pass_times.h"

#include <GLES3/gl3.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>

namespace arpipe::pass_times {
namespace {

struct Totals {
  std::mutex mutex;
  std::map<std::string, std::pair<double, long>> ms_and_count;
  std::string kind;
  std::chrono::steady_clock::time_point since = std::chrono::steady_clock::now();
  ~Totals() {
    for (const auto& [name, total] : ms_and_count)
      std::fprintf(stderr, "gl pass %-28s %8.3f ms mean over %ld\n", name.c_str(), total.first / double(total.second),
                   total.second);
  }
};

Totals& totals() {
  static Totals instance;
  return instance;
}

}  // namespace

bool enabled() {
  static const bool on = std::getenv("ARPIPE_GL_PASS_TIMES") != nullptr;
  return on;
}

void set_frame_kind(int samples, bool shadows) {
  if (!enabled()) return;
  std::lock_guard lock(totals().mutex);
  totals().kind = std::to_string(samples) + (shadows ? " samples, shadows: " : " samples: ");
}

void start() {
  if (!enabled()) return;
  glFinish();
  std::lock_guard lock(totals().mutex);
  totals().since = std::chrono::steady_clock::now();
}

void mark(const char* name) {
  if (!enabled()) return;
  glFinish();
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(totals().mutex);
  auto& total = totals().ms_and_count[totals().kind + name];
  total.first += std::chrono::duration<double, std::milli>(now - totals().since).count();
  ++total.second;
  totals().since = now;
}

}  // namespace arpipe::pass_times
