// Board files through the project's TOML section reader: the kind decides which keys belong; every
// key is checked for type and range, unknown keys are errors, and every message names the file,
// the place and the key.
#include "calib/calibration_board.h"

#include <apriltag/apriltag.h>
#include <opencv2/aruco/dictionary.hpp>
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <tuple>

#include "core/config/text_file.h"
#include "core/config/toml_section.h"
#include "core/track/tag_family.h"

namespace arpipe::calib {

namespace {

namespace fs = std::filesystem;

// Larger grids are certainly a typo: mrcal's pool is rows x cols points per image.
constexpr int64_t kMaxGridPoints = 1000;

// The keys of each kind, in the order messages list them.
const std::vector<std::string_view> kChessboardKeys{"kind", "description", "inner_corners", "square_m"};
const std::vector<std::string_view> kAprilGridKeys{"kind",          "description", "tags",    "tag_size_m",
                                                   "tag_spacing_m", "family",      "first_id"};
const std::vector<std::string_view> kCharucoKeys{"kind", "description", "squares", "square_m", "marker_m", "dictionary"};

// Board keys have no defaults but for family and first_id: an absent one is "found nothing".
void require(const TomlSection& s, std::string_view key, const std::string& expected) {
  if (!s.has(key)) s.fail(key, expected, "nothing");
}

// A length in metres, > 0 (or >= 0 when zero_ok); required.
double metres(const TomlSection& s, std::string_view key, bool zero_ok = false) {
  const NumberRange range = (zero_ok ? NumberRange::at_least(0) : NumberRange::above(0)).in("m");
  require(s, key, range.phrase());
  return s.number(key, 0, range);
}

// [rows, cols], each >= 2 (a single row or column gives the solve no board pose); required.
std::pair<int, int> grid(const TomlSection& s, std::string_view key, std::string_view what) {
  const std::string expected = fmt::format("[rows, cols] of {}, two integers >= 2", what);
  require(s, key, expected);
  const toml::node& n = *s.node(key);
  if (!n.is_array()) s.fail(key, expected, std::string(toml_type_phrase(n)));
  const toml::array& array = *n.as_array();
  if (array.size() != 2) s.fail(key, expected, fmt::format("{} items", array.size()));
  const IntRange range{2, kMaxGridPoints};
  int64_t values[2]{};
  for (size_t i = 0; i < 2; ++i) {
    const std::string item = fmt::format("{}[{}]", s.key_path(key), i);
    if (!array[i].is_integer()) s.fail_at(array[i], item, range.phrase(), std::string(toml_type_phrase(array[i])));
    values[i] = array[i].as_integer()->get();
    if (values[i] < range.min || values[i] > range.max)
      s.fail_at(array[i], item, range.phrase(), fmt::format("{}", values[i]));
  }
  if (values[0] * values[1] > kMaxGridPoints)
    s.fail(key, fmt::format("at most {} points", kMaxGridPoints), fmt::format("{} x {}", values[0], values[1]));
  return {static_cast<int>(values[0]), static_cast<int>(values[1])};
}

void read_chessboard(const TomlSection& s, CalibrationBoard& board) {
  std::tie(board.rows, board.cols) = grid(s, "inner_corners", "inner corners (squares - 1 each way)");
  board.spacing_m = metres(s, "square_m");
}

void read_apriltag_grid(const TomlSection& s, CalibrationBoard& board) {
  std::tie(board.rows, board.cols) = grid(s, "tags", "tags");
  board.tag_size_m = metres(s, "tag_size_m");
  const double gap = metres(s, "tag_spacing_m", true);
  board.family = s.string("family", "tag36h11");
  const TagFamilyPtr family = create_tag_family(board.family);
  if (!family)
    s.fail("family", fmt::format("one of {}", joined_tag_family_names()), toml_quoted(board.family));
  // Neighbouring tags' printed patterns (quiet zone or outer code ring included) must not overlap,
  // or the detector cannot find the quads.
  const int outside_cells = family->total_width - family->width_at_border;
  const double min_gap = board.tag_size_m * outside_cells / family->width_at_border;
  if (gap < min_gap * (1 - 1e-9))
    s.fail("tag_spacing_m",
           fmt::format("a gap of at least {:g} m ({} cells of a {} tag of {:g} m, so that printed tags do not "
                       "overlap)",
                       min_gap, outside_cells, board.family, board.tag_size_m),
           fmt::format("{:g}", gap));
  board.spacing_m = board.tag_size_m + gap;
  const int64_t codes = static_cast<int64_t>(family->ncodes);
  const int64_t count = static_cast<int64_t>(board.rows) * board.cols;
  const int64_t last_first_id = std::max<int64_t>(codes - count, 0);
  if (count > codes)
    s.fail("tags", fmt::format("at most {} tags (family {} has {} ids)", codes, board.family, codes),
           fmt::format("{} x {}", board.rows, board.cols));
  // ids first_id .. first_id + rows*cols - 1 must exist
  board.first_id = s.integer_as<int>("first_id", 0, IntRange{0, last_first_id});
}

void read_charuco(const TomlSection& s, CalibrationBoard& board) {
  // Three squares each way at least, so that there are two rows and two columns of inner corners.
  const auto [square_rows, square_cols] = grid(s, "squares", "squares");
  if (square_rows < 3 || square_cols < 3)
    s.fail("squares", "at least 3 squares each way (2 x 2 inner corners)",
           fmt::format("{} x {}", square_rows, square_cols));
  board.rows = square_rows - 1;
  board.cols = square_cols - 1;
  board.spacing_m = metres(s, "square_m");
  board.marker_m = metres(s, "marker_m");
  if (!(board.marker_m < board.spacing_m))
    s.fail("marker_m", fmt::format("less than square_m ({:g} m): the marker sits inside a light square", board.spacing_m),
           fmt::format("{:g}", board.marker_m));
  std::string names;
  for (const auto& d : aruco_dictionary_names()) names += (names.empty() ? "" : ", ") + std::string(d.name);
  require(s, "dictionary", "one of " + names);
  board.dictionary = s.string("dictionary", "");
  const auto& known = aruco_dictionary_names();
  const auto it = std::find_if(known.begin(), known.end(), [&](const auto& d) { return board.dictionary == d.name; });
  if (it == known.end()) s.fail("dictionary", "one of " + names, toml_quoted(board.dictionary));
  board.dictionary_id = it->id;
  // One marker in every light square: half the squares, rounded down (the top-left one is dark).
  const int markers = square_rows * square_cols / 2;
  const int codes = cv::aruco::getPredefinedDictionary(board.dictionary_id)->bytesList.rows;
  if (markers > codes)
    s.fail("squares", fmt::format("at most {} markers ({} has {} codes; a board has one per light square)", codes,
                                  board.dictionary, codes),
           fmt::format("{} x {} squares, {} markers", square_rows, square_cols, markers));
}

CalibrationBoard read_board(const TomlSection& file) {
  CalibrationBoard board;
  board.name = fs::path(file.source_name()).stem().string();
  require(file, "kind", "one of " + choice_list<BoardKind>(kBoardKindNames));
  board.kind = file.choice("kind", BoardKind::chessboard, kBoardKindNames);
  // The kind decides which keys belong: a key of the other kind is named before any value is read.
  const auto& keys = board.kind == BoardKind::chessboard ? kChessboardKeys
                     : board.kind == BoardKind::charuco  ? kCharucoKeys
                                                         : kAprilGridKeys;
  for (const auto key : keys) file.allow(key);
  file.reject_stray_keys();
  file.string("description", "");  // checked for its type only
  if (board.kind == BoardKind::chessboard)
    read_chessboard(file, board);
  else if (board.kind == BoardKind::charuco)
    read_charuco(file, board);
  else
    read_apriltag_grid(file, board);
  return board;
}

}  // namespace

const std::vector<ArucoDictionaryName>& aruco_dictionary_names() {
  using namespace cv::aruco;
  static const std::vector<ArucoDictionaryName> names{
      {"DICT_4X4_50", DICT_4X4_50},     {"DICT_4X4_100", DICT_4X4_100},
      {"DICT_4X4_250", DICT_4X4_250},   {"DICT_4X4_1000", DICT_4X4_1000},
      {"DICT_5X5_50", DICT_5X5_50},     {"DICT_5X5_100", DICT_5X5_100},
      {"DICT_5X5_250", DICT_5X5_250},   {"DICT_5X5_1000", DICT_5X5_1000},
      {"DICT_6X6_50", DICT_6X6_50},     {"DICT_6X6_100", DICT_6X6_100},
      {"DICT_6X6_250", DICT_6X6_250},   {"DICT_6X6_1000", DICT_6X6_1000},
      {"DICT_7X7_50", DICT_7X7_50},     {"DICT_7X7_100", DICT_7X7_100},
      {"DICT_7X7_250", DICT_7X7_250},   {"DICT_7X7_1000", DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", DICT_ARUCO_ORIGINAL},
      {"DICT_APRILTAG_16h5", DICT_APRILTAG_16h5},
      {"DICT_APRILTAG_25h9", DICT_APRILTAG_25h9},
      {"DICT_APRILTAG_36h10", DICT_APRILTAG_36h10},
      {"DICT_APRILTAG_36h11", DICT_APRILTAG_36h11}};
  return names;
}

std::vector<Vec3> CalibrationBoard::points() const {
  std::vector<Vec3> out;
  out.reserve(static_cast<size_t>(point_count()));
  for (int row = 0; row < rows; ++row)
    for (int col = 0; col < cols; ++col) out.push_back(point(row, col));
  return out;
}

CalibrationBoard parse_board(const std::string& text, const std::string& source_name) {
  try {
    const toml::table root = parse_toml(text, source_name);
    return read_board(TomlSection(root, source_name));
  } catch (const TomlInputError& e) {
    throw BoardError(e.what());
  }
}

CalibrationBoard load_board(const std::filesystem::path& path) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) throw BoardError(fmt::format("{}: cannot read board file: {}", path.string(), why));
  return parse_board(*text, path.string());
}

}  // namespace arpipe::calib
