// arpipe: the utility beside the daemon: inspect and replay recordings, simulate captures, check
// configs, calibrate, and run the benchmarks. `arpipe --help` lists the commands, `arpipe COMMAND
// --help` their options.
#include <csignal>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "core/system/frame_memory.h"
#include "core/log.h"

int main(int argc, char** argv) {
  arpipe::keep_frame_memory_resident();
  arpipe::log::set_program_name("arpipe");
  std::signal(SIGPIPE, SIG_IGN);  // a reader that goes away (a FIFO output) is EPIPE for the sink, not death
  CLI::App app("arpipe: the utility beside the arpiped daemon.", "arpipe");
  arpipe::cli::setup(app);
  app.require_subcommand(1);
  for (const arpipe::AddCommand add_command : arpipe::kCommands) add_command(app);
  return arpipe::cli::parse_and_run(app, argc, argv);
}
