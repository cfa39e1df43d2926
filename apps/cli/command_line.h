// How arpipe and arpiped read their command lines (CLI11): every option declared once with its
// help, `--help` on every command, `--version` from the build, and usage errors that exit 2 naming
// the command and the option.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>

namespace arpipe::cli {

// "0.1.0 (v0.1.0-12-gabcdef0-dirty)": the CMake project version and, when the build was
// configured from a git checkout, `git describe --always --dirty` at configure time.
const char* version();

// Adds --version, shows defaults in the help and makes `parse_and_run` report usage errors by name.
void setup(CLI::App& app);

// What a command does once its options are read; the function's result is the exit status.
void on_run(CLI::App* command, std::function<int()> run);

// What an error that escapes a command's run function (a file it cannot read, a solve that fails)
// becomes: the exit status, and how the message is written.
struct Failure {
  enum class Message {
    logged,              // log::error: "arpipe: error: <what>"
    after_command_name,  // stderr: "arpipe bake: <what>", like the messages such a command prints itself
  };
  int status = 1;
  Message message = Message::logged;
};

// on_run for a command whose errors are exceptions: one that escapes `run` is reported as
// `failure` says, so the command needs no catch of its own. Usage errors (usage_error) still exit 2.
void on_run(CLI::App* command, std::function<int()> run, Failure failure);

// Parses the command line and runs the chosen command: its exit status, 0 after --help or
// --version, 2 after a usage error (printed to stderr with the command's name).
int parse_and_run(CLI::App& app, int argc, char** argv);

// A usage error a command finds itself after parsing (two options that do not go together): exits 2
// like the errors CLI11 finds. Throws; call it from a command's run function.
[[noreturn]] void usage_error(const std::string& message);

// A check for an option whose text `parse` must accept (a name of a choice, a list): the
// message says what was expected.
CLI::Validator accepted_by(std::function<bool(const std::string&)> parse, const std::string& expected);

// A check for a number option: a finite number (CLI11 itself reads "nan" and "inf" as numbers).
CLI::Validator finite_number();

}  // namespace arpipe::cli
