// CameraModel over mrcal's C API: mrcal reads the .cameramodel files and does every projection.
// Before mrcal sees a file, a small scanner checks it, so a bad file gets a message with its line.
#include "core/geometry/camera_model.h"
#include "core/geometry/math_constants.h"

extern "C" {
#include <mrcal/mrcal.h>
}

#include <fmt/format.h>

#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

#include "core/config/regular_file.h"

namespace arpipe {

struct CameraModel::Mrcal {
  mrcal_lensmodel_t lensmodel;
  mrcal_lensmodel_metadata_t metadata;
};

namespace {


std::string supported_lensmodels() {
  std::string names;
  for (const char* const* name = mrcal_supported_lensmodel_names(); *name != nullptr; ++name) {
    if (!names.empty()) names += ", ";
    names += *name;
  }
  return names;
}

// mrcal asserts (aborts the process) on spline configurations it cannot use, and counts parameters
// in int: check them first. Order 2 needs at least 3 knots each way, order 3 at least 4; 100000
// knots is far beyond any calibrated lens (60 x 40 is already fine-grained).
void check_spline_config(const std::string& name, const mrcal_lensmodel_t& lensmodel) {
  const auto& c = lensmodel.LENSMODEL_SPLINED_STEREOGRAPHIC__config;
  constexpr int kMaxKnots = 100000;
  if (c.order != 2 && c.order != 3)
    throw CameraModelError(fmt::format("lens model '{}': spline order {}, expected 2 or 3", name, c.order));
  if (c.Nx < c.order + 1 || c.Ny < c.order + 1)
    throw CameraModelError(fmt::format("lens model '{}': order-{} splines need Nx and Ny of at least {}, got Nx={} Ny={}",
                                       name, c.order, c.order + 1, c.Nx, c.Ny));
  if (int{c.Nx} * int{c.Ny} > kMaxKnots)
    throw CameraModelError(fmt::format("lens model '{}': {} x {} knots exceeds the limit of {}", name, c.Nx, c.Ny,
                                       kMaxKnots));
  if (c.fov_x_deg == 0) throw CameraModelError(fmt::format("lens model '{}': fov_x_deg 0, expected > 0", name));
}

// Turns a lens-model name into mrcal's struct, or says what is wrong with the name.
mrcal_lensmodel_t lensmodel_from_name(const std::string& name) {
  mrcal_lensmodel_t lensmodel{};
  if (mrcal_lensmodel_from_name(&lensmodel, name.c_str()) && mrcal_lensmodel_type_is_valid(lensmodel.type)) {
    if (lensmodel.type == MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC) check_spline_config(name, lensmodel);
    return lensmodel;
  }
  if (lensmodel.type == MRCAL_LENSMODEL_INVALID_BADCONFIG)
    throw CameraModelError(fmt::format(
        "lens model '{}' has a missing or malformed configuration; expected one of: {}", name,
        supported_lensmodels()));
  throw CameraModelError(fmt::format("unknown lens model '{}'; expected one of: {}", name, supported_lensmodels()));
}

// ---- Diagnosis of .cameramodel text (a Python dict literal) -----------------------------------
// mrcal's reader only says "no" (on stderr); this finds the line, the column and what was expected.

struct Place {
  int line = 1;
  int column = 1;
};

struct Token {
  enum class Kind { Punct, String, Number, Name, End } kind = Kind::End;
  std::string text;
  Place at;
};

class DictLiteralScanner {
 public:
  DictLiteralScanner(const std::string& text, const std::string& source) : text_(text), source_(source) {}

  Token next() {
    skip_space_and_comments();
    Token token;
    token.at = here();
    if (pos_ >= text_.size()) return token;
    const char c = text_[pos_];
    if (std::strchr("{}[](),:", c) != nullptr) {
      ++pos_;
      token.kind = Token::Kind::Punct;
      token.text = std::string(1, c);
      return token;
    }
    if (string_starts_here()) {
      token.kind = Token::Kind::String;
      token.text = scan_string(token.at);
      return token;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.') {
      token.kind = Token::Kind::Number;
      const size_t start = pos_;
      while (pos_ < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[pos_])) ||
                                     std::strchr("+-._", text_[pos_]) != nullptr))
        advance();
      token.text = text_.substr(start, pos_ - start);
      return token;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      token.kind = Token::Kind::Name;
      const size_t start = pos_;
      while (pos_ < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_'))
        advance();
      token.text = text_.substr(start, pos_ - start);
      return token;
    }
    throw error(token.at, fmt::format("expected a Python literal, got {}", describe_char(c)));
  }

  // Skips blanks and comments; throws unless the next character opens the top-level dict.
  void expect_dict_start() {
    skip_space_and_comments();
    if (pos_ < text_.size() && text_[pos_] == '{') return;
    throw error(here(), fmt::format("expected '{{' (a .cameramodel is a Python dict literal), got {}",
                                    pos_ < text_.size() ? describe_char(text_[pos_]) : "the end of the file"));
  }

  CameraModelError error(Place at, const std::string& what) const {
    return CameraModelError(fmt::format("{}:{}:{}: {}", source_, at.line, at.column, what));
  }

 private:
  Place here() const { return {line_, static_cast<int>(pos_ - line_start_) + 1}; }
  static std::string describe_char(char c) {
    const auto byte = static_cast<unsigned char>(c);
    if (std::isprint(byte)) return fmt::format("'{}'", c);
    return fmt::format("the byte 0x{:02x}", byte);
  }
  void advance() {
    if (text_[pos_] == '\n') {
      ++line_;
      line_start_ = pos_ + 1;
    }
    ++pos_;
  }
  void skip_space_and_comments() {
    while (pos_ < text_.size()) {
      if (std::isspace(static_cast<unsigned char>(text_[pos_]))) {
        advance();
      } else if (text_[pos_] == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') advance();
      } else {
        break;
      }
    }
  }
  // Python string prefixes (b'' for optimization_inputs, r'', u''), then a quote.
  bool string_starts_here() const {
    size_t p = pos_;
    while (p < text_.size() && p < pos_ + 2 && std::strchr("bBrRuU", text_[p]) != nullptr) ++p;
    return p < text_.size() && (text_[p] == '\'' || text_[p] == '"');
  }
  std::string scan_string(Place start) {
    while (text_[pos_] != '\'' && text_[pos_] != '"') advance();
    const char quote = text_[pos_];
    advance();
    std::string value;
    while (pos_ < text_.size() && text_[pos_] != quote) {
      if (text_[pos_] == '\\' && pos_ + 1 < text_.size()) advance();
      if (text_[pos_] == '\n') throw error(start, "string not closed before the end of the line");
      value += text_[pos_];
      advance();
    }
    if (pos_ >= text_.size()) throw error(start, "string not closed before the end of the file");
    advance();
    return value;
  }

  const std::string& text_;
  const std::string& source_;
  size_t pos_ = 0;
  int line_ = 1;
  size_t line_start_ = 0;
};

struct LiteralValue {
  enum class Kind { String, Number, Name, List, Dict } kind = Kind::Name;
  Place at;
  std::string text;                         // String, Number, Name
  std::vector<std::optional<double>> items;  // List: numbers, or nullopt for anything else
};

std::string describe(const Token& token) {
  switch (token.kind) {
    case Token::Kind::End: return "the end of the file";
    case Token::Kind::String: return fmt::format("the string '{}'", token.text);
    default: return fmt::format("'{}'", token.text);
  }
}

std::optional<double> parse_finite_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value)) return std::nullopt;
  return value;
}

// Nesting of lists and dicts inside the top-level dict: mrcal's files nest 2 deep (a list in a
// value; optional metadata dicts a little more).
constexpr int kMaxLiteralDepth = 32;
// A splined model of 60 x 40 knots is ~150 KB of text; 4 MiB bounds what a hostile file can make
// the parser and mrcal's reader hold.
constexpr uint64_t kMaxCameraModelBytes = uint64_t{4} << 20;

class DictLiteralParser {
 public:
  DictLiteralParser(const std::string& text, const std::string& source) : scanner_(text, source) {}

  // The top-level keys in file order with their values.
  std::vector<std::pair<std::string, LiteralValue>> parse_top_level() {
    std::vector<std::pair<std::string, LiteralValue>> entries;
    scanner_.expect_dict_start();
    Token token = scanner_.next();
    while (true) {
      token = scanner_.next();
      if (token.kind == Token::Kind::Punct && token.text == "}") break;
      if (token.kind != Token::Kind::String)
        throw scanner_.error(token.at, fmt::format("expected a quoted key or '}}', got {}", describe(token)));
      const std::string key = token.text;
      expect(":", "after the key '" + key + "'");
      entries.emplace_back(key, parse_value(scanner_.next()));
      token = scanner_.next();
      if (token.kind == Token::Kind::Punct && token.text == "}") break;
      if (token.kind != Token::Kind::Punct || token.text != ",")
        throw scanner_.error(token.at,
                             fmt::format("expected ',' or '}}' after the value of '{}', got {}", key, describe(token)));
    }
    token = scanner_.next();
    if (token.kind != Token::Kind::End)
      throw scanner_.error(token.at, fmt::format("expected the end of the file after '}}', got {}", describe(token)));
    return entries;
  }

  const DictLiteralScanner& scanner() const { return scanner_; }

 private:
  void expect(const std::string& punct, const std::string& where) {
    const Token token = scanner_.next();
    if (token.kind != Token::Kind::Punct || token.text != punct)
      throw scanner_.error(token.at, fmt::format("expected '{}' {}, got {}", punct, where, describe(token)));
  }

  // depth: lists and dicts around this value; bounded so a file of '[' cannot exhaust the stack.
  LiteralValue parse_value(const Token& first, int depth = 1) {
    LiteralValue value;
    value.at = first.at;
    if (depth > kMaxLiteralDepth)
      throw scanner_.error(first.at, fmt::format("values nested more than {} levels deep (a .cameramodel needs 2)",
                                                 kMaxLiteralDepth));
    switch (first.kind) {
      case Token::Kind::String: value.kind = LiteralValue::Kind::String; value.text = first.text; return value;
      case Token::Kind::Number: value.kind = LiteralValue::Kind::Number; value.text = first.text; return value;
      case Token::Kind::Name: value.kind = LiteralValue::Kind::Name; value.text = first.text; return value;
      case Token::Kind::End: throw scanner_.error(first.at, "expected a value, got the end of the file");
      case Token::Kind::Punct: break;
    }
    if (first.text == "[" || first.text == "(") {
      const std::string close = first.text == "[" ? "]" : ")";
      value.kind = LiteralValue::Kind::List;
      Token token = scanner_.next();
      while (!(token.kind == Token::Kind::Punct && token.text == close)) {
        const LiteralValue item = parse_value(token, depth + 1);
        value.items.push_back(item.kind == LiteralValue::Kind::Number ? parse_finite_number(item.text) : std::nullopt);
        token = scanner_.next();
        if (token.kind == Token::Kind::Punct && token.text == ",") {
          token = scanner_.next();
        } else if (!(token.kind == Token::Kind::Punct && token.text == close)) {
          throw scanner_.error(token.at, fmt::format("expected ',' or '{}' in the list, got {}", close, describe(token)));
        }
      }
      return value;
    }
    if (first.text == "{") {
      value.kind = LiteralValue::Kind::Dict;
      Token token = scanner_.next();
      while (!(token.kind == Token::Kind::Punct && token.text == "}")) {
        parse_value(token, depth + 1);
        expect(":", "after a key");
        parse_value(scanner_.next(), depth + 1);
        token = scanner_.next();
        if (token.kind == Token::Kind::Punct && token.text == ",") {
          token = scanner_.next();
        } else if (!(token.kind == Token::Kind::Punct && token.text == "}")) {
          throw scanner_.error(token.at, fmt::format("expected ',' or '}}' in the dict, got {}", describe(token)));
        }
      }
      return value;
    }
    throw scanner_.error(first.at, fmt::format("expected a value, got {}", describe(first)));
  }

  DictLiteralScanner scanner_;
};

// Throws a CameraModelError with the place of the first problem that would make mrcal's reader
// (or our constructor) reject the text. Returns quietly when it finds none.
void diagnose_cameramodel_text(const std::string& text, const std::string& source) {
  DictLiteralParser parser(text, source);
  const auto entries = parser.parse_top_level();
  const auto find = [&](const std::string& key) -> const std::pair<std::string, LiteralValue>* {
    for (const auto& entry : entries)
      if (entry.first == key) return &entry;
    return nullptr;
  };
  const auto require = [&](const std::string& key, const std::string& expected) -> const LiteralValue& {
    const auto* entry = find(key);
    if (entry == nullptr) throw CameraModelError(fmt::format("{}: missing key '{}' ({})", source, key, expected));
    return entry->second;
  };
  const auto error_at = [&](const LiteralValue& value, const std::string& what) {
    return parser.scanner().error(value.at, what);
  };
  const auto numbers = [&](const std::string& key, const LiteralValue& value, const std::string& expected) {
    if (value.kind != LiteralValue::Kind::List)
      throw error_at(value, fmt::format("'{}' expected a list of {}", key, expected));
    for (size_t i = 0; i < value.items.size(); ++i)
      if (!value.items[i])
        throw error_at(value, fmt::format("'{}' expected a list of {}; item {} is not a finite number", key, expected, i));
  };

  const LiteralValue& name = require("lensmodel", "expected a lens model name such as 'LENSMODEL_OPENCV8'");
  if (name.kind != LiteralValue::Kind::String)
    throw error_at(name, "'lensmodel' expected a quoted lens model name such as 'LENSMODEL_OPENCV8'");
  mrcal_lensmodel_t lensmodel{};
  try {
    lensmodel = lensmodel_from_name(name.text);
  } catch (const CameraModelError& e) {
    throw error_at(name, e.what());
  }
  const size_t needed = static_cast<size_t>(mrcal_lensmodel_num_params(&lensmodel));

  const LiteralValue& intrinsics = require("intrinsics", "expected fx, fy, cx, cy, distortion...");
  numbers("intrinsics", intrinsics, "numbers");
  if (intrinsics.items.size() != needed)
    throw error_at(intrinsics, fmt::format("'intrinsics' has {} values, but {} needs {}", intrinsics.items.size(),
                                           name.text, needed));
  if (find("intrinsics") < find("lensmodel"))
    throw error_at(intrinsics, "'intrinsics' comes before 'lensmodel'; mrcal's reader needs 'lensmodel' first");

  const LiteralValue& extrinsics = require("extrinsics", "expected rx, ry, rz, tx, ty, tz");
  numbers("extrinsics", extrinsics, "6 numbers (rx, ry, rz, tx, ty, tz)");
  if (extrinsics.items.size() != 6)
    throw error_at(extrinsics, fmt::format("'extrinsics' expected 6 numbers (rt_fromref), got {}", extrinsics.items.size()));

  const LiteralValue& imagersize = require("imagersize", "expected [width, height]");
  numbers("imagersize", imagersize, "2 positive integers (width, height)");
  bool size_ok = imagersize.items.size() == 2;
  for (const auto& item : imagersize.items)
    size_ok = size_ok && *item >= 1 && *item <= INT_MAX && std::floor(*item) == *item;
  if (!size_ok) throw error_at(imagersize, "'imagersize' expected 2 positive integers [width, height]");
}

std::string format_numbers(const double* values, size_t count) {
  std::string out;
  for (size_t i = 0; i < count; ++i) out += fmt::format(" {:.17g},", values[i]);
  return out;
}

}  // namespace

CameraModel::CameraModel(const std::string& lensmodel, std::vector<double> intrinsics, int width, int height)
    : intrinsics_(std::move(intrinsics)), width_(width), height_(height) {
  auto m = std::make_shared<Mrcal>();
  m->lensmodel = lensmodel_from_name(lensmodel);
  m->metadata = mrcal_lensmodel_metadata(&m->lensmodel);
  const size_t needed = static_cast<size_t>(mrcal_lensmodel_num_params(&m->lensmodel));
  if (intrinsics_.size() != needed)
    throw CameraModelError(fmt::format("lens model '{}' needs {} intrinsics, got {}", lensmodel, needed, intrinsics_.size()));
  for (size_t i = 0; i < intrinsics_.size(); ++i)
    if (!std::isfinite(intrinsics_[i]))
      throw CameraModelError(fmt::format("intrinsics[{}] of '{}' is not a finite number", i, lensmodel));
  if (m->metadata.has_core && !(intrinsics_[0] > 0 && intrinsics_[1] > 0))
    throw CameraModelError(fmt::format("focal lengths of '{}' must be positive, got fx={} fy={}", lensmodel,
                                       intrinsics_[0], intrinsics_[1]));
  if (width <= 0 || height <= 0)
    throw CameraModelError(fmt::format("imager size must be positive, got {}x{}", width, height));
  // A core far outside any real lens sends mrcal's unprojection solve into a loop that does not end
  // (a fuzzed splined model with cy = 2.4e12 ran for minutes): refused here, with the limits.
  if (m->metadata.has_core) {
    constexpr double kMaxFocalPx = 1e7;     // a 16k-pixel sensor behind a 0.1-degree field of view is ~1e7
    constexpr double kMaxCentreOffset = 10;  // the principal point within 10 imager sizes of the image
    if (intrinsics_[0] > kMaxFocalPx || intrinsics_[1] > kMaxFocalPx)
      throw CameraModelError(fmt::format("focal lengths of '{}' must be at most {} px, got fx={} fy={}", lensmodel,
                                         kMaxFocalPx, intrinsics_[0], intrinsics_[1]));
    const double cx = intrinsics_[2], cy = intrinsics_[3];
    if (cx < -kMaxCentreOffset * width || cx > (kMaxCentreOffset + 1) * width || cy < -kMaxCentreOffset * height ||
        cy > (kMaxCentreOffset + 1) * height)
      throw CameraModelError(fmt::format(
          "principal point of '{}' ({}, {}) is more than {} imager sizes outside the {}x{} image", lensmodel, cx, cy,
          kMaxCentreOffset, width, height));
  }
  char name[256];
  lensmodel_ = mrcal_lensmodel_name(name, sizeof name, &m->lensmodel) ? std::string(name) : lensmodel;
  mrcal_ = std::move(m);
}

CameraModel CameraModel::pinhole(double fx, double fy, double cx, double cy, int width, int height) {
  return CameraModel("LENSMODEL_PINHOLE", {fx, fy, cx, cy}, width, height);
}

CameraModel CameraModel::load(const std::filesystem::path& path) {
  std::string text;
  try {
    text = read_regular_file(path, "camera model", kMaxCameraModelBytes);
  } catch (const FileAccessError& e) {
    throw CameraModelError(e.what());
  }
  return parse(text, path.string());
}

CameraModel CameraModel::parse(const std::string& text, const std::string& source_name) {
  if (text.size() >= static_cast<size_t>(INT_MAX))
    throw CameraModelError(fmt::format("{}: camera model text too large ({} bytes)", source_name, text.size()));
  diagnose_cameramodel_text(text, source_name);

  mrcal_cameramodel_t* model = mrcal_read_cameramodel_string(text.c_str(), static_cast<int>(text.size()));
  if (model == nullptr)
    throw CameraModelError(fmt::format(
        "{}: mrcal's reader rejected this .cameramodel (its reason is on stderr); expected a Python dict with "
        "'lensmodel', 'intrinsics', 'extrinsics' and 'imagersize'",
        source_name));
  std::unique_ptr<mrcal_cameramodel_t, void (*)(mrcal_cameramodel_t*)> owner(
      model, [](mrcal_cameramodel_t* m) { mrcal_free_cameramodel(&m); });
  char name[256];
  if (!mrcal_lensmodel_name(name, sizeof name, &model->lensmodel))
    throw CameraModelError(fmt::format("{}: mrcal could not name the lens model it read", source_name));
  const int n = mrcal_lensmodel_num_params(&model->lensmodel);
  try {
    return CameraModel(name, std::vector<double>(model->intrinsics, model->intrinsics + n),
                       static_cast<int>(model->imagersize[0]), static_cast<int>(model->imagersize[1]));
  } catch (const CameraModelError& e) {
    throw CameraModelError(fmt::format("{}: {}", source_name, e.what()));
  }
}

std::string CameraModel::to_string() const {
  // The layout of mrcal's Python writer (cameramodel.py _write), with %.17g so that every double
  // reads back bit for bit. Extrinsics are identity: this class holds intrinsics only.
  const double extrinsics[6] = {0, 0, 0, 0, 0, 0};
  std::string out = "# mrcal camera model written by arpipe (numbers at full precision, %.17g)\n{\n";
  out += fmt::format("    'lensmodel':  '{}',\n\n", lensmodel_);
  if (has_core()) out += "    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....\n";
  out += fmt::format("    'intrinsics': [{}],\n\n", format_numbers(intrinsics_.data(), intrinsics_.size()));
  out += "    # extrinsics are rt_fromref\n";
  out += fmt::format("    'extrinsics': [{}],\n\n", format_numbers(extrinsics, 6));
  out += fmt::format("    'imagersize': [ {}, {},],\n}}\n", width_, height_);
  return out;
}

void CameraModel::save(const std::filesystem::path& path) const { save_text(path, to_string()); }

void CameraModel::save_text(const std::filesystem::path& path, const std::string& text) {
  // Write a temporary file and rename it, so a crash never leaves a half-written model behind.
  const std::filesystem::path temporary = path.string() + ".tmp";
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr)
    throw CameraModelError(fmt::format("{}: cannot write camera model: {}", path.string(), std::strerror(errno)));
  const bool written = std::fwrite(text.data(), 1, text.size(), file) == text.size();
  const int write_errno = errno;
  if (std::fclose(file) != 0 || !written) {
    std::filesystem::remove(temporary);
    throw CameraModelError(fmt::format("{}: cannot write camera model: {}", path.string(),
                                       std::strerror(written ? errno : write_errno)));
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary);
    throw CameraModelError(fmt::format("{}: cannot write camera model: {}", path.string(), ec.message()));
  }
}

bool CameraModel::is_pinhole() const { return mrcal_->lensmodel.type == MRCAL_LENSMODEL_PINHOLE; }

bool CameraModel::has_core() const { return mrcal_->metadata.has_core; }

std::optional<Vec2> CameraModel::project(const Vec3& p_cam) const {
  if (!mrcal_->metadata.can_project_behind_camera && !(p_cam[2] > 0)) return std::nullopt;
  mrcal_point3_t p{};
  p.x = p_cam[0], p.y = p_cam[1], p.z = p_cam[2];
  mrcal_point2_t q{};
  if (!mrcal_project(&q, nullptr, nullptr, &p, 1, &mrcal_->lensmodel, intrinsics_.data())) return std::nullopt;
  if (!std::isfinite(q.x) || !std::isfinite(q.y)) return std::nullopt;
  return Vec2{q.x, q.y};
}

void CameraModel::project(const std::vector<Vec3>& p_cam, std::vector<Vec2>& out) const {
  out.resize(p_cam.size());
  if (p_cam.empty()) return;
  // Vec3 and mrcal_point3_t are both three packed doubles; copying keeps us free of aliasing rules.
  std::vector<mrcal_point3_t> points(p_cam.size());
  for (size_t i = 0; i < p_cam.size(); ++i) points[i].x = p_cam[i][0], points[i].y = p_cam[i][1], points[i].z = p_cam[i][2];
  std::vector<mrcal_point2_t> pixels(p_cam.size());
  const bool ok = mrcal_project(pixels.data(), nullptr, nullptr, points.data(), static_cast<int>(points.size()),
                                &mrcal_->lensmodel, intrinsics_.data());
  const bool behind_is_invalid = !mrcal_->metadata.can_project_behind_camera;
  for (size_t i = 0; i < p_cam.size(); ++i) {
    const bool valid = ok && !(behind_is_invalid && !(p_cam[i][2] > 0)) && std::isfinite(pixels[i].x) &&
                       std::isfinite(pixels[i].y);
    out[i] = valid ? Vec2{pixels[i].x, pixels[i].y} : Vec2{kNaN, kNaN};
  }
}

std::optional<Vec3> CameraModel::unproject(const Vec2& pixel) const {
  // CAHVORE is the one model without gradients, and mrcal cannot unproject it.
  if (!mrcal_->metadata.has_gradients) return std::nullopt;
  if (!std::isfinite(pixel[0]) || !std::isfinite(pixel[1])) return std::nullopt;
  mrcal_point2_t q{};
  q.x = pixel[0], q.y = pixel[1];
  mrcal_point3_t v{};
  if (!mrcal_unproject(&v, &q, 1, &mrcal_->lensmodel, intrinsics_.data())) return std::nullopt;
  const Vec3 direction{v.x, v.y, v.z};
  const double length = norm(direction);
  if (!std::isfinite(length) || length == 0) return std::nullopt;
  return (1.0 / length) * direction;
}

void CameraModel::unproject(const std::vector<Vec2>& pixels, std::vector<Vec3>& out) const {
  out.assign(pixels.size(), Vec3{kNaN, kNaN, kNaN});
  if (pixels.empty() || !mrcal_->metadata.has_gradients) return;
  std::vector<mrcal_point2_t> q(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) q[i].x = pixels[i][0], q[i].y = pixels[i][1];
  std::vector<mrcal_point3_t> v(pixels.size());
  // mrcal marks a pixel it cannot unproject with NaN and carries on with the others.
  if (!mrcal_unproject(v.data(), q.data(), static_cast<int>(q.size()), &mrcal_->lensmodel, intrinsics_.data())) return;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Vec3 direction{v[i].x, v[i].y, v[i].z};
    const double length = norm(direction);
    if (std::isfinite(length) && length > 0) out[i] = (1.0 / length) * direction;
  }
}

std::optional<Vec2> CameraModel::normalize(const Vec2& pixel) const {
  const auto direction = unproject(pixel);
  if (!direction || !((*direction)[2] > 0)) return std::nullopt;
  return Vec2{(*direction)[0] / (*direction)[2], (*direction)[1] / (*direction)[2]};
}

std::optional<Vec2> CameraModel::normalize_near(const Vec2& pixel, const Vec2& near) const {
  constexpr int kMaxSteps = 8;
  constexpr double kConvergedPx = 1e-9;
  if (!mrcal_->metadata.has_gradients || !std::isfinite(near[0]) || !std::isfinite(near[1])) return normalize(pixel);
  double x = near[0], y = near[1];
  for (int step = 0; step < kMaxSteps; ++step) {
    const mrcal_point3_t p{.x = x, .y = y, .z = 1.0};
    mrcal_point2_t q{};
    mrcal_point3_t dq_dp[2]{};  // rows: d(qx)/dp, d(qy)/dp
    if (!mrcal_project(&q, dq_dp, nullptr, &p, 1, &mrcal_->lensmodel, intrinsics_.data())) break;
    const double ex = pixel[0] - q.x, ey = pixel[1] - q.y;
    if (!std::isfinite(ex) || !std::isfinite(ey)) break;
    if (std::abs(ex) < kConvergedPx && std::abs(ey) < kConvergedPx) return Vec2{x, y};
    // With z fixed at 1, the 2x2 Jacobian of the pixel in (x, y).
    const double a = dq_dp[0].x, b = dq_dp[0].y, c = dq_dp[1].x, d = dq_dp[1].y;
    const double det = a * d - b * c;
    if (!(std::abs(det) > 1e-12)) break;
    x += (d * ex - b * ey) / det;
    y += (a * ey - c * ex) / det;
  }
  return normalize(pixel);
}

}  // namespace arpipe
