// arpipe replay: the daemon's pipeline, run once over a recording as fast as possible.
#include <fmt/format.h>

#include <cstdio>
#include <exception>

#include "apps/arpipe/commands.h"
#include "apps/common/pipeline_assembly.h"
#include "core/log.h"

namespace arpipe {

namespace {
constexpr const char* kUsage = "usage: arpipe replay DIR [--config FILE] [--set KEY=VALUE]...\n";
}  // namespace

int run_replay(const Args& args) {
  std::string dir, config_path;
  std::vector<std::string> overrides;
  for (size_t i = 0; i < args.size(); ++i) {
    const bool has_value = i + 1 < args.size();
    if (args[i] == "--config" && has_value) {
      config_path = args[++i];
    } else if (args[i] == "--set" && has_value) {
      overrides.push_back(args[++i]);
    } else if (dir.empty() && !args[i].starts_with("-")) {
      dir = args[i];
    } else {
      std::fputs(kUsage, stderr);
      return 2;
    }
  }
  if (dir.empty()) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  // The recording and "as fast as possible" come last, so they win over the file.
  overrides.push_back("source.type=\"replay\"");
  overrides.push_back("source.pacing=\"fast\"");
  overrides.push_back(fmt::format("source.path={}", toml_string(dir)));
  try {
    const Config config = config_path.empty() ? parse_config("", "(defaults)", overrides)
                                              : load_config(config_path, overrides);
    auto runner = assemble_pipeline(config);
    runner->start();
    runner->wait();
    log::info("{}", describe_metrics(runner->metrics()));
    return 0;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 2;
  }
}

}  // namespace arpipe
