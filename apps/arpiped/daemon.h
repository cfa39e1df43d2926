// The arpiped process: runs the pipeline from a config file, answers SIGTERM/SIGINT (drain and
// flush), SIGHUP (reload: every change that can be applied while running is; an invalid config, or
// one that changes a key needing a restart, is refused and the old one keeps running), talks to systemd.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace arpipe {

struct DaemonOptions {
  std::filesystem::path config_path;
  std::vector<std::string> overrides;  // --set key=value
};

// Exit codes: 0 finished or stopped cleanly, 2 setup error (bad config/recording/model/asset).
int run_daemon(const DaemonOptions& options);

}  // namespace arpipe
