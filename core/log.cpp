#include "core/log.h"

#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>

namespace arpipe::log {

namespace {
std::mutex g_mutex;
std::string g_program = "arpipe";
Level g_max_level = Level::Info;

// journald parses "<N>" priority prefixes on stdout/stderr streams it owns (sd-daemon(3)).
bool stderr_is_journal() {
  static const bool is_journal = std::getenv("JOURNAL_STREAM") != nullptr;
  return is_journal;
}

const char* level_word(Level level) {
  switch (level) {
    case Level::Error: return "error";
    case Level::Warning: return "warning";
    case Level::Notice: return "notice";
    case Level::Info: return "info";
    case Level::Debug: return "debug";
  }
  return "?";
}
}  // namespace

void set_program_name(std::string_view name) {
  std::lock_guard lock(g_mutex);
  g_program = name;
}

void set_max_level(Level level) {
  std::lock_guard lock(g_mutex);
  g_max_level = level;
}

void write(Level level, std::string_view message) {
  std::lock_guard lock(g_mutex);
  if (static_cast<int>(level) > static_cast<int>(g_max_level)) return;
  if (stderr_is_journal())
    std::fprintf(stderr, "<%d>%.*s\n", static_cast<int>(level), int(message.size()), message.data());
  else
    std::fprintf(stderr, "%s: %s: %.*s\n", g_program.c_str(), level_word(level), int(message.size()), message.data());
}

}  // namespace arpipe::log
