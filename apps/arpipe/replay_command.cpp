// arpipe replay: the daemon's pipeline, run once over a recording as fast as possible.
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "apps/common/pipeline_assembly.h"
#include "core/log.h"

namespace arpipe {

namespace {

struct ReplayOptions {
  std::string dir, config_path;
  std::vector<std::string> overrides;
};

int replay(ReplayOptions options) {
  const std::string& dir = options.dir;
  const std::string& config_path = options.config_path;
  std::vector<std::string>& overrides = options.overrides;
  // The recording and "as fast as possible" come last, so they win over the file.
  overrides.push_back("source.type=" + toml_string(std::string(choice_name(kSourceTypeNames, SourceType::Replay))));
  overrides.push_back("source.pacing=" +
                      toml_string(std::string(choice_name(kReplayPacingNames, ReplayPacing::Fast))));
  overrides.push_back(fmt::format("source.path={}", toml_string(dir)));
  const Config config = config_path.empty() ? parse_config("", "(defaults)", overrides)
                                            : load_config(config_path, overrides);
  auto runner = assemble_pipeline(config);
  runner->start();
  runner->wait();
  log::info("{}", describe_metrics(runner->metrics()));
  return 0;
}

}  // namespace

void add_replay_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand("replay", "run the pipeline on a recording as fast as possible");
  auto options = std::make_shared<ReplayOptions>();
  command->add_option("DIR", options->dir, "the recording")->required();
  command->add_option("--config", options->config_path, "the config (default: every key at its default)")
      ->type_name("FILE");
  command->add_option("--set", options->overrides, "override one config key (VALUE in TOML syntax); repeatable")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  cli::on_run(command, [options] { return replay(*options); }, cli::Failure{.status = 2});
}

}  // namespace arpipe
