// The pixel formats the V4L2 output sink (sinks.v4l2.format) can write, with their one name table.
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class V4l2OutputFormat {
  Yuyv,   // 4:2:2, what browsers and video-call programs take from a camera
  Rgb24,  // the composite's own bytes, exact
};

inline constexpr ChoiceName<V4l2OutputFormat> kV4l2OutputFormatNames[] = {{"yuyv", V4l2OutputFormat::Yuyv},
                                                                          {"rgb24", V4l2OutputFormat::Rgb24}};

}  // namespace arpipe
