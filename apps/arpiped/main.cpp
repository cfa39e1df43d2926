// arpiped: the arpipe daemon. Runs capture -> track -> render -> composite -> sinks from a config.
#include "apps/arpiped/daemon.h"
#include "apps/cli/command_line.h"
#include "core/system/frame_memory.h"

int main(int argc, char** argv) {
  arpipe::keep_frame_memory_resident();
  arpipe::DaemonOptions options;
  options.config_path = "/etc/arpipe/arpipe.toml";
  CLI::App app("arpiped: runs the arpipe pipeline that the config describes.", "arpiped");
  arpipe::cli::setup(app);
  app.add_option("--config", options.config_path,
                 "the config file (TOML); relative paths inside it are relative to the working directory")
      ->type_name("FILE");
  app.add_option("--set", options.overrides,
                 "override one config key (VALUE in TOML syntax, e.g. --set pipeline.max_frames=10); repeatable")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  app.footer(
      "Signals: SIGTERM/SIGINT drain the queues and flush the outputs (during setup: exit at once);\n"
      "  SIGHUP reloads the config file in the background (the running config stays until it is loaded).\n"
      "Exit status: 0 when the stream ended or the daemon was stopped, 2 on a setup error.");
  arpipe::cli::on_run(&app, [&options] { return arpipe::run_daemon(options); });
  return arpipe::cli::parse_and_run(app, argc, argv);
}
