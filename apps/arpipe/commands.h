// The subcommands of the `arpipe` utility; each takes its own arguments (after the subcommand name)
// and returns the process exit status (0 ok, 1 failure, 2 usage or setup error).
#pragma once

#include <string>
#include <vector>

namespace arpipe {

using Args = std::vector<std::string>;

// A TOML basic string holding `text`, for a --set style config override ("source.path=" + ...).
std::string toml_string(const std::string& text);

int run_inspect(const Args& args);   // arpipe inspect DIR
int run_replay(const Args& args);    // arpipe replay DIR [--config FILE] [--set K=V]...
int run_simulate(const Args& args);  // arpipe simulate --scene FILE --out DIR [--frames N] [--seed S] ...
int run_config(const Args& args);    // arpipe config --defaults | --check FILE
int run_board(const Args& args);     // arpipe board FILE --out BOARD.png [--dpi N]
int run_calib(const Args& args);
int run_bench(const Args& args);       // arpipe bench blur [...]
int run_sun(const Args& args);
int run_cameras(const Args& args);  // arpipe cameras [DEVICE]...
int run_record(const Args& args);   // arpipe record --camera CAMERA --out DIR [--frames N | --seconds S] ...  // arpipe sun --lat .. --lon .. --time ISO8601
int run_bench_shadows(const Args& args);  // arpipe bench shadows [--frames N] [--scenes DIR]
int run_bench_sh(const Args& args);   // arpipe bench sh [--samples N] [--seed S]
int run_bench_prt(const Args& args);  // arpipe bench prt [...]
int run_sh(const Args& args);         // arpipe sh --probe FILE --layout L [--bands N] [--normal X,Y,Z]...
int run_bake(const Args& args);       // arpipe bake MODEL [--kind K] [--bands N] [--samples N] ...
int run_bench_blur(const Args& args);  // arpipe bench blur [--capture DIR | --scene FILE] [--out DIR] ...     // arpipe calib (--images GLOB | --recording DIR) --board FILE --out FILE ...

}  // namespace arpipe
