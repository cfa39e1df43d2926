// mrcal's corners cache: what mrgingham prints ("filename x y level"), with weights in the last
// column (mrcal-calibrate-cameras --corners-cache-has-weights), read by mrcal.compute_chessboard_corners.
#include "calib/corners_vnl.h"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace arpipe::calib {

namespace {

// mrcal's reader: a row is "\s*(\S+)\s+(.*)", and a row starting with '#' is a comment.
std::string vnl_name(std::string name) {
  for (char& c : name)
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f') c = '_';
  if (name.empty()) name = "unnamed";
  if (name[0] == '#') name[0] = '_';
  return name;
}

}  // namespace

std::string corners_vnl(const std::vector<BoardObservation>& views, const CalibrationBoard& board,
                        const std::vector<std::string>& file_names) {
  if (!file_names.empty() && file_names.size() != views.size())
    throw std::invalid_argument(
        fmt::format("corners.vnl: {} file names for {} views", file_names.size(), views.size()));
  std::string text = "# filename x y weight\n";
  for (size_t v = 0; v < views.size(); ++v) {
    const BoardObservation& view = views[v];
    const std::string name = vnl_name(file_names.empty() ? view.image : file_names[v]);
    if (int(view.pixels.size()) != board.point_count() || view.weights.size() != view.pixels.size())
      throw std::invalid_argument(fmt::format("corners.vnl: {} has {} points, board '{}' has {}", name,
                                              view.pixels.size(), board.name, board.point_count()));
    for (size_t i = 0; i < view.pixels.size(); ++i) {
      const Vec2& q = view.pixels[i];
      // mrcal's reader drops points with a negative coordinate anyway; say so explicitly.
      if (view.weights[i] > 0 && std::isfinite(q[0]) && std::isfinite(q[1]) && q[0] >= 0 && q[1] >= 0)
        text += fmt::format("{} {:.17g} {:.17g} {:.17g}\n", name, q[0], q[1], view.weights[i]);
      else
        text += fmt::format("{} - - -\n", name);
    }
  }
  return text;
}

void write_corners_vnl(const std::filesystem::path& path, const std::vector<BoardObservation>& views,
                       const CalibrationBoard& board, const std::vector<std::string>& file_names) {
  const std::string text = corners_vnl(views, board, file_names);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (out) out << text;
  if (!out) throw std::runtime_error(fmt::format("{}: cannot write: {}", path.string(), std::strerror(errno)));
}

}  // namespace arpipe::calib
