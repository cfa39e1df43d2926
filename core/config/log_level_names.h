// pipeline.log_level's name table: the logger's own levels (core/log.h) by the names the config uses.
#pragma once

#include "core/config/choice_names.h"
#include "core/log.h"

namespace arpipe {

inline constexpr ChoiceName<log::Level> kLogLevelNames[] = {{"error", log::Level::Error},
                                                             {"warning", log::Level::Warning},
                                                             {"info", log::Level::Info},
                                                             {"debug", log::Level::Debug}};

}  // namespace arpipe
