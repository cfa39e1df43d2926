// arpiped: the arpipe daemon. Runs capture -> track -> render -> composite -> sinks from a config.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "apps/arpiped/daemon.h"
#include "core/frame_memory.h"

namespace {

constexpr const char* kUsage = R"(usage: arpiped [--config FILE] [--set KEY=VALUE]...

Runs the arpipe pipeline described by FILE (TOML, default /etc/arpipe/arpipe.toml).
  --config FILE      the config file; relative paths inside it are relative to the working directory
  --set KEY=VALUE    overrides one config key (VALUE in TOML syntax, e.g. --set pipeline.max_frames=10)
  --help             this text
Signals: SIGTERM/SIGINT drain the queues and flush the outputs (during setup: exit at once);
  SIGHUP reloads the config file in the background (the running config stays until it is loaded).
Exit status: 0 when the stream ended or the daemon was stopped, 2 on a setup error.
)";

}  // namespace

int main(int argc, char** argv) {
  arpipe::keep_frame_memory_resident();
  arpipe::DaemonOptions options;
  options.config_path = "/etc/arpipe/arpipe.toml";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "arpiped: %s needs a value\n%s", name, kUsage);
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--config") options.config_path = value("--config");
    else if (arg == "--set") options.overrides.emplace_back(value("--set"));
    else if (arg == "--help" || arg == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    } else {
      std::fprintf(stderr, "arpiped: unknown argument '%s'\n%s", arg.c_str(), kUsage);
      return 2;
    }
  }
  return arpipe::run_daemon(options);
}
