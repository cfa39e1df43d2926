// The rules a config row can carry besides a number range (core/config/value_ranges.h): what the
// schema visitors (config_reader.cpp, config_defaults.cpp) check and print for a key.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/config/value_ranges.h"

namespace arpipe {

// One of a few names, kept as the string.
struct OneOf {
  std::vector<std::string_view> names;
};

// A camera response curve's name: "srgb", "linear" or "gamma:<g>" (core/image/camera_response.h).
struct CameraResponseName {};

// One of a few integers (msaa_samples: 0, 1, 2, 4); phrase overrides "one of 0, 1, 2, 4".
struct OneOfInts {
  std::vector<int64_t> values;
  std::string phrase;
};

// A string that must not be empty; phrase says what it names.
struct NotEmpty {
  std::string phrase;
};

// The name of one of libapriltag's tag families (core/track/tag_family.h).
struct TagFamilyName {};

// A number in degrees in the file, radians in the struct (the default is kept bit for bit).
struct Degrees {
  NumberRange range;
};

// A number of milliseconds in the file, whole nanoseconds (at least 1) in the struct.
struct MillisecondsAsNs {
  NumberRange range;
};

// A list of numbers whose length is one of `counts` (0 allowed when the empty list means "not
// set"), each in range; phrase says what the list is ("[] or 1 or 4 raw codes").
struct NumberCount {
  std::vector<size_t> counts;
  NumberRange range;
  std::string phrase;
};

}  // namespace arpipe
