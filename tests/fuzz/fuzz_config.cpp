// libFuzzer target: core/config's TOML config parser (parse_config, the text behind load_config).
// Each input is parsed twice: as a config file, and as one `--set section.key=value` override
// applied to a small valid config. Bad input must be a ConfigError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/config/config.h"

namespace {

// A config with arrays of tables, so that indexed overrides (render.objects.0.scale=2) resolve.
constexpr const char* kBaseConfig = R"(
[source]
type = "replay"
path = "recording"
[[track.bundle]]
id = 0
size_m = 0.1
[[render.objects]]
mesh = "builtin:cube"
scale = 1.0
[sinks.results]
path = "out/results.jsonl"
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)arpipe::parse_config(text, "fuzz.toml");
  } catch (const arpipe::ConfigError&) {
  }
  try {
    (void)arpipe::parse_config(kBaseConfig, "base.toml", {text});
  } catch (const arpipe::ConfigError&) {
  }
  return 0;
}
