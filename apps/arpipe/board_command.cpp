// arpipe board: writes the printable picture of a calibration board file (configs/boards/).
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <string>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "calib/board_printout.h"
#include "calib/calibration_board.h"

namespace arpipe {

namespace {

struct BoardOptions {
  std::string board_path, out;
  double dpi = 300;
};

int draw_board(const BoardOptions& options) {
  const std::string& board_path = options.board_path;
  const std::string& out = options.out;
  const double dpi = options.dpi;
  const calib::CalibrationBoard board = calib::load_board(board_path);
  const calib::PrintedBoard printed = calib::write_board_png(board, out, dpi);
  const bool tags = board.kind == calib::BoardKind::apriltag_grid;
  fmt::print("wrote {}: {}x{} px; print at {:g} dpi, 100 % scale: {:.1f} x {:.1f} mm with the margin; {} {:.1f} mm",
             out, printed.width_px, printed.height_px, dpi, 1e3 * printed.width_m, 1e3 * printed.height_m,
             tags ? "each tag's black square must measure" : "each square must measure",
             1e3 * (tags ? board.tag_size_m : board.spacing_m));
  if (board.kind == calib::BoardKind::charuco)
    fmt::print(", each marker's black square {:.1f} mm", 1e3 * board.marker_m);
  fmt::print("\n");
  return 0;
}

}  // namespace

void add_board_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand("board", "draw a board file's printable picture");
  command->footer(
      "Print it at that resolution and 100 % scale (not fitted to the page), glue it to something flat and rigid,\n"
      "then measure a square or a tag and correct the board file if the printer scaled it.");
  auto options = std::make_shared<BoardOptions>();
  command->add_option("FILE", options->board_path, "the board file (configs/boards/*.toml)")->required();
  command->add_option("--out", options->out, "the picture")->type_name("BOARD.png")->required();
  command->add_option("--dpi", options->dpi, "pixels per inch")->check(CLI::PositiveNumber);
  cli::on_run(command, [options] { return draw_board(*options); }, cli::Failure{.status = 1});
}

}  // namespace arpipe
