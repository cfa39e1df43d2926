// arpipe config: print the defaults, or check a config file the way arpiped would read it, and
// that every input file it names exists and is a regular, readable file.
#include <cstdio>
#include <exception>
#include <new>

#include "apps/arpipe/commands.h"
#include "core/config/config.h"
#include "core/config/config_files.h"
#include "core/log.h"

namespace arpipe {

int run_config(const Args& args) {
  if (args.size() == 1 && args[0] == "--defaults") {
    std::fputs(default_config_toml().c_str(), stdout);
    return 0;
  }
  if (args.size() == 2 && args[0] == "--check") {
    try {
      check_config_files(load_config(args[1]));
      std::printf("%s: ok\n", args[1].c_str());
      return 0;
    } catch (const std::bad_alloc&) {  // the loaders cap what they allocate; this names the file if one did not
      log::error("{}: out of memory while checking the config", args[1]);
      return 2;
    } catch (const std::exception& e) {
      log::error("{}", e.what());
      return 2;
    }
  }
  std::fputs("usage: arpipe config --defaults | --check FILE\n", stderr);
  return 2;
}

}  // namespace arpipe
