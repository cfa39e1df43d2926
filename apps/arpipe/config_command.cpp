// arpipe config: print the defaults, or check a config file the way arpiped would read it, and
// that every input file it names exists and is a regular, readable file.
#include <cstdio>
#include <memory>
#include <new>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "core/config/config.h"
#include "core/config/config_files.h"
#include "core/log.h"

namespace arpipe {

namespace {

int check(const std::string& file) {
  try {
    check_config_files(load_config(file));
    std::printf("%s: ok\n", file.c_str());
    return 0;
  } catch (const std::bad_alloc&) {  // the loaders cap what they allocate; this names the file if one did not
    log::error("{}: out of memory while checking the config", file);
    return 2;
  }
}

}  // namespace

void add_config_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand("config", "print the default config, or check a config file");
  auto check_file = std::make_shared<std::string>();
  auto defaults = std::make_shared<bool>(false);
  CLI::Option* print_defaults = command->add_flag("--defaults", *defaults, "print a config with every key at its default");
  CLI::Option* checked = command->add_option("--check", *check_file,
                                             "validate FILE as arpiped reads it, and the input files it names");
  checked->type_name("FILE");
  print_defaults->excludes(checked);
  command->require_option(1);
  cli::on_run(command, [defaults, check_file] {
    if (*defaults) {
      std::fputs(default_config_toml().c_str(), stdout);
      return 0;
    }
    return check(*check_file);
  }, cli::Failure{.status = 2});
}

}  // namespace arpipe
