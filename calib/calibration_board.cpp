// Board files with toml++: the kind decides which keys belong; every key is checked for type and
// range, unknown keys are errors, and every message names the file, the place and the key.
#include "calib/calibration_board.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <tuple>

#include "core/config/toml_stray_key.h"
#include "core/config/text_file.h"
#include "core/config/toml_type_phrase.h"
#include "core/track/tag_family.h"

namespace arpipe::calib {

namespace {

namespace fs = std::filesystem;

// Larger grids are certainly a typo: mrcal's pool is rows x cols points per image.
constexpr int64_t kMaxGridPoints = 1000;

std::string join(const std::vector<std::string_view>& items) {
  std::string out;
  for (const auto item : items) out += fmt::format("{}{}", out.empty() ? "" : ", ", item);
  return out;
}

class BoardReader {
 public:
  BoardReader(std::string source, const toml::table& root) : source_(std::move(source)), root_(root) {}

  // "file:line:col"; nodes without a place (the root table) point at the start of the file.
  std::string place(const toml::source_region& region) const {
    if (region.begin.line == 0) return fmt::format("{}:1:1", source_);
    return fmt::format("{}:{}:{}", source_, region.begin.line, region.begin.column);
  }
  [[noreturn]] void fail(const toml::source_region& at, std::string_view key, const std::string& what) const {
    throw BoardError(fmt::format("{}: {}: {}", place(at), key, what));
  }
  [[noreturn]] void fail(std::string_view key, const std::string& what) const {
    const toml::node* n = root_.get(key);
    fail(n != nullptr ? n->source() : root_.source(), key, what);
  }
  [[noreturn]] void fail(std::string_view key, const std::string& expected, const std::string& found) const {
    fail(key, fmt::format("expected {}, found {}", expected, found));
  }

  bool has(std::string_view key) const { return root_.contains(key); }

  // The first key in file order that is not allowed for this kind: unknown, or one of the other kind.
  void allow(const std::vector<std::string_view>& allowed, const std::vector<std::string_view>& other_kind,
             std::string_view kind) const {
    const auto stray = first_stray_key(root_, allowed);
    if (!stray) return;
    if (std::find(other_kind.begin(), other_kind.end(), stray->name) != other_kind.end())
      fail(stray->where, stray->name,
           fmt::format("not allowed with kind = \"{}\"; expected one of {}", kind, join(allowed)));
    fail(stray->where, stray->name, fmt::format("unknown key; expected one of {}", join(allowed)));
  }

  const toml::node& required(std::string_view key, const std::string& expected) const {
    const toml::node* n = root_.get(key);
    if (n == nullptr) fail(key, fmt::format("missing; expected {}", expected));
    return *n;
  }

  // A string; required when there is no fallback.
  std::string string(std::string_view key, std::optional<std::string> fallback,
                     const std::string& expected = "a string") const {
    const toml::node* n = root_.get(key);
    if (n == nullptr) {
      if (fallback) return *fallback;
      n = &required(key, expected);
    }
    if (!n->is_string()) fail(key, expected, std::string(toml_type_phrase(*n)));
    return n->as_string()->get();
  }

  // A length in metres, > 0 (or >= 0 when zero_ok).
  double metres(std::string_view key, bool zero_ok = false) const {
    const std::string expected = zero_ok ? "a length in metres >= 0" : "a length in metres > 0";
    const toml::node& n = required(key, expected);
    double value = 0;
    if (n.is_integer())
      value = static_cast<double>(n.as_integer()->get());
    else if (n.is_floating_point())
      value = n.as_floating_point()->get();
    else
      fail(key, expected, std::string(toml_type_phrase(n)));
    if (!std::isfinite(value) || value < 0 || (value == 0 && !zero_ok)) fail(key, expected, fmt::format("{}", value));
    return value;
  }

  int64_t integer(std::string_view key, int64_t fallback, int64_t min, int64_t max) const {
    const toml::node* n = root_.get(key);
    if (n == nullptr) return fallback;
    const std::string expected = fmt::format("an integer in [{}, {}]", min, max);
    if (!n->is_integer()) fail(key, expected, std::string(toml_type_phrase(*n)));
    const int64_t value = n->as_integer()->get();
    if (value < min || value > max) fail(key, expected, fmt::format("{}", value));
    return value;
  }

  // [rows, cols], each >= 2 (a single row or column gives the solve no board pose).
  std::pair<int, int> grid(std::string_view key, std::string_view what) const {
    const std::string expected = fmt::format("[rows, cols] of {}, two integers >= 2", what);
    const toml::node& n = required(key, expected);
    if (!n.is_array()) fail(key, expected, std::string(toml_type_phrase(n)));
    const toml::array& array = *n.as_array();
    if (array.size() != 2) fail(key, expected, fmt::format("{} items", array.size()));
    int64_t values[2]{};
    for (size_t i = 0; i < 2; ++i) {
      const std::string item = fmt::format("{}[{}]", key, i);
      if (!array[i].is_integer()) fail(array[i].source(), item, fmt::format("expected an integer >= 2, found {}",
                                                                            toml_type_phrase(array[i])));
      values[i] = array[i].as_integer()->get();
      if (values[i] < 2 || values[i] > kMaxGridPoints)
        fail(array[i].source(), item, fmt::format("expected an integer in [2, {}], found {}", kMaxGridPoints, values[i]));
    }
    if (values[0] * values[1] > kMaxGridPoints)
      fail(key, fmt::format("at most {} points", kMaxGridPoints), fmt::format("{} x {}", values[0], values[1]));
    return {static_cast<int>(values[0]), static_cast<int>(values[1])};
  }

 private:
  std::string source_;
  const toml::table& root_;
};

const std::vector<std::string_view> kChessboardKeys{"kind", "description", "inner_corners", "square_m"};
const std::vector<std::string_view> kAprilGridKeys{"kind",          "description", "tags",    "tag_size_m",
                                                   "tag_spacing_m", "family",      "first_id"};

void read_chessboard(const BoardReader& r, CalibrationBoard& board) {
  r.allow(kChessboardKeys, kAprilGridKeys, "chessboard");
  std::tie(board.rows, board.cols) = r.grid("inner_corners", "inner corners (squares - 1 each way)");
  board.spacing_m = r.metres("square_m");
}

void read_apriltag_grid(const BoardReader& r, CalibrationBoard& board) {
  r.allow(kAprilGridKeys, kChessboardKeys, "apriltag_grid");
  std::tie(board.rows, board.cols) = r.grid("tags", "tags");
  board.tag_size_m = r.metres("tag_size_m");
  const double gap = r.metres("tag_spacing_m", true);
  board.family = r.string("family", std::string("tag36h11"));
  const TagFamilyPtr family = create_tag_family(board.family);
  if (!family) r.fail("family", fmt::format("one of {}", joined_tag_family_names()), fmt::format("\"{}\"", board.family));
  // Neighbouring tags' printed patterns (quiet zone or outer code ring included) must not overlap,
  // or the detector cannot find the quads.
  const int outside_cells = family->total_width - family->width_at_border;
  const double min_gap = board.tag_size_m * outside_cells / family->width_at_border;
  if (gap < min_gap * (1 - 1e-9))
    r.fail("tag_spacing_m",
           fmt::format("a gap of at least {:g} m ({} cells of a {} tag of {:g} m, so that printed tags do not "
                       "overlap)",
                       min_gap, outside_cells, board.family, board.tag_size_m),
           fmt::format("{:g}", gap));
  board.spacing_m = board.tag_size_m + gap;
  const int64_t codes = static_cast<int64_t>(family->ncodes);
  const int64_t count = static_cast<int64_t>(board.rows) * board.cols;
  const int64_t last_first_id = std::max<int64_t>(codes - count, 0);
  if (count > codes)
    r.fail("tags", fmt::format("at most {} tags (family {} has {} ids)", codes, board.family, codes),
           fmt::format("{} x {}", board.rows, board.cols));
  board.first_id = static_cast<int>(
      r.integer("first_id", 0, 0, last_first_id));  // ids first_id .. first_id + rows*cols - 1 must exist
}

}  // namespace

std::vector<Vec3> CalibrationBoard::points() const {
  std::vector<Vec3> out;
  out.reserve(static_cast<size_t>(point_count()));
  for (int row = 0; row < rows; ++row)
    for (int col = 0; col < cols; ++col) out.push_back(point(row, col));
  return out;
}

CalibrationBoard parse_board(const std::string& text, const std::string& source_name) {
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    const auto& at = e.source().begin;
    throw BoardError(fmt::format("{}:{}:{}: TOML syntax error: {}", source_name, std::max<uint32_t>(at.line, 1),
                                 std::max<uint32_t>(at.column, 1), e.description()));
  }
  const BoardReader r(source_name, root);
  CalibrationBoard board;
  board.name = fs::path(source_name).stem().string();
  const std::string expected_kind = "\"chessboard\" or \"apriltag_grid\"";
  const std::string kind = r.string("kind", std::nullopt, expected_kind);
  if (kind == "chessboard") {
    board.kind = BoardKind::chessboard;
    read_chessboard(r, board);
  } else if (kind == "apriltag_grid") {
    board.kind = BoardKind::apriltag_grid;
    read_apriltag_grid(r, board);
  } else {
    r.fail("kind", expected_kind, fmt::format("\"{}\"", kind));
  }
  r.string("description", std::string());  // checked for its type only
  return board;
}

CalibrationBoard load_board(const std::filesystem::path& path) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) throw BoardError(fmt::format("{}: cannot read board file: {}", path.string(), why));
  return parse_board(*text, path.string());
}

}  // namespace arpipe::calib
