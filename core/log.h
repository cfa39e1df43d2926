// Logging to stderr in a journald-friendly form: "<N>" priority prefixes when stderr is the journal,
// "arpiped: level: message" otherwise. Thread-safe; one line per call.
#pragma once

#include <fmt/format.h>
#include <string>
#include <string_view>

namespace arpipe::log {

enum class Level { Error = 3, Warning = 4, Notice = 5, Info = 6, Debug = 7 };

void set_program_name(std::string_view name);
void set_max_level(Level level);
void write(Level level, std::string_view message);

template <typename... Args> void error(fmt::format_string<Args...> f, Args&&... a) { write(Level::Error, fmt::format(f, std::forward<Args>(a)...)); }
template <typename... Args> void warn(fmt::format_string<Args...> f, Args&&... a) { write(Level::Warning, fmt::format(f, std::forward<Args>(a)...)); }
template <typename... Args> void notice(fmt::format_string<Args...> f, Args&&... a) { write(Level::Notice, fmt::format(f, std::forward<Args>(a)...)); }
template <typename... Args> void info(fmt::format_string<Args...> f, Args&&... a) { write(Level::Info, fmt::format(f, std::forward<Args>(a)...)); }
template <typename... Args> void debug(fmt::format_string<Args...> f, Args&&... a) { write(Level::Debug, fmt::format(f, std::forward<Args>(a)...)); }

}  // namespace arpipe::log
