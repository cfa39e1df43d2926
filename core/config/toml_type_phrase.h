// How error messages name the type of a TOML value ("a string", "an array", ...): shared by the
// config loader and the simulator's scene loader so both read alike.
#pragma once

#include <toml++/toml.h>

#include <string_view>

namespace arpipe {

std::string_view toml_type_phrase(const toml::node& node);

}  // namespace arpipe
