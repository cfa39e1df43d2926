// The subcommands of the `arpipe` utility. Each add_*_command declares its command on `arpipe`
// (its options, each with its help) and what it runs; the run's result is the exit status
// (0 ok, 1 failure, 2 usage or setup error).
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace arpipe {

// A TOML basic string holding `text`, for a --set style config override ("source.path=" + ...).
std::string toml_string(const std::string& text);

void add_inspect_command(CLI::App& arpipe);   // arpipe inspect DIR
void add_replay_command(CLI::App& arpipe);    // arpipe replay DIR [--config FILE] [--set K=V]...
void add_simulate_command(CLI::App& arpipe);  // arpipe simulate --scene FILE --out DIR [--frames N] ...
void add_calib_command(CLI::App& arpipe);     // arpipe calib (--images GLOB | --recording DIR) --board FILE --out FILE ...
void add_board_command(CLI::App& arpipe);     // arpipe board FILE --out BOARD.png [--dpi N]
void add_bench_command(CLI::App& arpipe);     // arpipe bench NAME [OPTIONS] (bench/benchmarks.h)
void add_sh_command(CLI::App& arpipe);        // arpipe sh --environment FILE --layout L [--bands N] [--normal X,Y,Z]...
void add_bake_command(CLI::App& arpipe);      // arpipe bake MODEL [--kind K] [--bands N] [--samples N] ...
void add_sun_command(CLI::App& arpipe);       // arpipe sun --lat DEG --lon DEG --time ISO8601 ...
void add_cameras_command(CLI::App& arpipe);   // arpipe cameras [--v4l2-only | --libcamera-only] [DEVICE]...
void add_record_command(CLI::App& arpipe);    // arpipe record --camera CAMERA --out DIR [--frames N | --seconds S] ...
void add_config_command(CLI::App& arpipe);    // arpipe config --defaults | --check FILE
void add_ctl_command(CLI::App& arpipe);       // arpipe ctl [--socket PATH] status | reload | set K=V... | snapshot FILE | record start DIR | record stop
void add_proxy_command(CLI::App& arpipe);     // arpipe proxy simplify IN --out OUT.glb [--ratio R] [--camera FILE] ...

// Every command, in the order `arpipe --help` lists them.
using AddCommand = void (*)(CLI::App& arpipe);
inline constexpr AddCommand kCommands[] = {
    add_inspect_command, add_replay_command, add_simulate_command, add_calib_command,
    add_board_command,   add_bench_command,  add_sh_command,       add_bake_command,
    add_sun_command,     add_cameras_command, add_record_command,  add_config_command,
    add_ctl_command,     add_proxy_command,
};

}  // namespace arpipe
