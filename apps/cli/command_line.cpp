// The command-line conventions both programs share (see command_line.h).
#include "apps/cli/command_line.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <utility>

#include "arpipe_version.h"  // generated: apps/CMakeLists.txt
#include "core/log.h"

namespace arpipe::cli {

namespace {

// The command a subcommand of which none was chosen: `arpipe bench blur` -> blur's App.
const CLI::App* chosen_command(const CLI::App* app) {
  for (;;) {
    const std::vector<const CLI::App*> chosen = app->get_subcommands([](const CLI::App* sub) { return sub->parsed(); });
    if (chosen.empty()) return app;
    app = chosen.front();
  }
}

// "arpipe bench blur": the program and the commands chosen on this command line.
std::string command_path(const CLI::App* app) {
  std::string path = app->get_name();
  for (const CLI::App* at = app; at != chosen_command(at);) {
    at = at->get_subcommands([](const CLI::App* sub) { return sub->parsed(); }).front();
    path += " " + at->get_name();
  }
  return path;
}

// "arpipe bake": the command's name after those of the commands it belongs to.
std::string name_with_parents(const CLI::App* command) {
  std::string name = command->get_name();
  for (const CLI::App* parent = command->get_parent(); parent != nullptr; parent = parent->get_parent())
    name = parent->get_name() + " " + name;
  return name;
}

// The help shows defaults that say something: none for a required option or an empty value.
void drop_empty_defaults(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string shown = option->get_default_str();
    if (option->get_required() || shown == "[]" || shown == "\"\"")
      option->default_str("");
  }
  for (CLI::App* command : app.get_subcommands({})) drop_empty_defaults(*command);
}

}  // namespace

const char* version() { return ARPIPE_VERSION_STRING; }

void setup(CLI::App& app) {
  app.set_version_flag("--version", std::string(app.get_name()) + " " + version());
  app.option_defaults()->always_capture_default();
  app.failure_message([](const CLI::App* top, const CLI::Error& e) {
    const CLI::App* command = chosen_command(top);
    const std::string path = command_path(top);
    std::string message = e.what();
    // CLI11 says only "A subcommand is required" when the word given is not a command.
    const std::vector<std::string> extra = command->remaining();
    if (!command->get_subcommands({}).empty() && !extra.empty() && !extra.front().starts_with("-"))
      message = "unknown command '" + extra.front() + "'";
    return path + ": " + message + "\nRun '" + path + " --help' for the options.\n";
  });
}

void on_run(CLI::App* command, std::function<int()> run) {
  command->callback([run = std::move(run)] {
    const int status = run();
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

void on_run(CLI::App* command, std::function<int()> run, Failure failure) {
  on_run(command, [command, run = std::move(run), failure] {
    try {
      return run();
    } catch (const CLI::Error&) {
      throw;  // a usage error: parse_and_run reports it
    } catch (const std::exception& e) {
      if (failure.message == Failure::Message::logged)
        log::error("{}", e.what());
      else
        fmt::print(stderr, "{}: {}\n", name_with_parents(command), e.what());
      return failure.status;
    }
  });
}

int parse_and_run(CLI::App& app, int argc, char** argv) {
  drop_empty_defaults(app);
  try {
    app.parse(argc, argv);
    return 0;
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a command's own exit status (on_run)
  } catch (const CLI::Error& e) {
    // --help and --version are "errors" with status 0; every other one is a usage error.
    return app.exit(e) == 0 ? 0 : 2;
  }
}

void usage_error(const std::string& message) { throw CLI::ValidationError(message); }

CLI::Validator accepted_by(std::function<bool(const std::string&)> parse, const std::string& expected) {
  return CLI::Validator(
      [parse = std::move(parse), expected](std::string& text) {
        return parse(text) ? std::string() : "expected " + expected + ", got \"" + text + "\"";
      },
      "");
}

CLI::Validator finite_number() {
  return CLI::Validator(
      [](std::string& text) {
        double value = 0;
        return CLI::detail::lexical_cast(text, value) && std::isfinite(value) ? std::string()
                                                                               : "expected a finite number, got \"" + text + "\"";
      },
      "");
}

}  // namespace arpipe::cli
