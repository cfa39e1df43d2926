// arpipe config: print the defaults, or check a config file the way arpiped would read it.
#include <cstdio>
#include <exception>

#include "apps/arpipe/commands.h"
#include "core/config/config.h"
#include "core/log.h"

namespace arpipe {

int run_config(const Args& args) {
  if (args.size() == 1 && args[0] == "--defaults") {
    std::fputs(default_config_toml().c_str(), stdout);
    return 0;
  }
  if (args.size() == 2 && args[0] == "--check") {
    try {
      load_config(args[1]);
      std::printf("%s: ok\n", args[1].c_str());
      return 0;
    } catch (const std::exception& e) {
      log::error("{}", e.what());
      return 2;
    }
  }
  std::fputs("usage: arpipe config --defaults | --check FILE\n", stderr);
  return 2;
}

}  // namespace arpipe
