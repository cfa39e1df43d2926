// pipeline.log_level ("error", "warning", "info", "debug") as the logger's level, for arpiped's
// start and its reloads.
#pragma once

#include <string>

#include "core/log.h"

namespace arpipe {

inline log::Level log_level_from_name(const std::string& name) {
  if (name == "error") return log::Level::Error;
  if (name == "warning") return log::Level::Warning;
  if (name == "debug") return log::Level::Debug;
  return log::Level::Info;
}

}  // namespace arpipe
