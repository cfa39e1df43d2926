// arpipe board: writes the printable picture of a calibration board file (configs/boards/).
#include <fmt/format.h>

#include <charconv>
#include <cstdio>
#include <exception>

#include "apps/arpipe/commands.h"
#include "calib/board_printout.h"
#include "calib/calibration_board.h"
#include "core/log.h"

namespace arpipe {

namespace {
constexpr const char* kUsage =
    "usage: arpipe board FILE --out BOARD.png [--dpi N]\n"
    "  Draws the board that FILE (configs/boards/*.toml) describes, at N pixels per inch (default 300).\n"
    "  Print it at that resolution and 100 % scale (not fitted to the page), glue it to something flat\n"
    "  and rigid, then measure a square or a tag and correct the board file if the printer scaled it.\n";
}  // namespace

int run_board(const Args& args) {
  std::string board_path;
  std::string out;
  double dpi = 300;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (args[i] == "--out" || args[i] == "--dpi") {
      if (i + 1 >= args.size()) {
        fmt::print(stderr, "arpipe board: {} needs a value\n{}", args[i], kUsage);
        return 2;
      }
      const std::string& value = args[++i];
      if (args[i - 1] == "--out") {
        out = value;
      } else {
        const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), dpi);
        if (ec != std::errc() || end != value.data() + value.size()) {
          fmt::print(stderr, "arpipe board: bad value '{}' for --dpi\n{}", value, kUsage);
          return 2;
        }
      }
    } else if (board_path.empty() && args[i].rfind("--", 0) != 0) {
      board_path = args[i];
    } else {
      fmt::print(stderr, "arpipe board: unexpected argument {}\n{}", args[i], kUsage);
      return 2;
    }
  }
  if (board_path.empty() || out.empty()) {
    fmt::print(stderr, "arpipe board: a board file and --out are required\n{}", kUsage);
    return 2;
  }
  try {
    const calib::CalibrationBoard board = calib::load_board(board_path);
    const calib::PrintedBoard printed = calib::write_board_png(board, out, dpi);
    fmt::print("wrote {}: {}x{} px; print at {:g} dpi, 100 % scale: {:.1f} x {:.1f} mm with the margin; {} {:.1f} mm\n",
               out, printed.width_px, printed.height_px, dpi, 1e3 * printed.width_m, 1e3 * printed.height_m,
               board.kind == calib::BoardKind::chessboard ? "each square must measure" : "each tag's black square must measure",
               1e3 * (board.kind == calib::BoardKind::chessboard ? board.spacing_m : board.tag_size_m));
    return 0;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 1;
  }
}

}  // namespace arpipe
