// `--set` overrides of the config: "section.key=value" (value in TOML syntax; a bare word such as
// fast or out/run1 is taken as a string), merged into the parsed file before the schema walk.
// Elements of arrays of tables are addressed by index: render.objects.0.scale=2.
#pragma once

#include <toml++/toml.h>

#include <string>

namespace arpipe {

// Merges one assignment into root; throws TomlInputError naming the override on any problem.
void apply_override(toml::table& root, const std::string& assignment);

}  // namespace arpipe
