#include "capture/panorama/head_pose_track.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <string_view>

#include "capture/panorama/panorama_view.h"
#include "core/config/regular_file.h"
#include "core/geometry/se3.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

constexpr double kRadiansPerDegree = std::numbers::pi / 180;

std::vector<std::string_view> fields_of(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ',' || line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i == line.size()) break;
    const size_t start = i;
    while (i < line.size() && line[i] != ',' && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    out.push_back(line.substr(start, i - start));
  }
  return out;
}

// The view camera's axes from a head orientation in OpenXR's convention (x right, y up, -z forward).
Mat3 camera_from_head_quaternion(double w, double x, double y, double z) {
  const Mat3 R{{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
  // Camera right = head x, down = -head y, forward = -head z.
  return {{{R[0][0], -R[0][1], -R[0][2]}, {R[1][0], -R[1][1], -R[1][2]}, {R[2][0], -R[2][1], -R[2][2]}}};
}

}  // namespace

HeadPoseTrack HeadPoseTrack::load(const std::filesystem::path& file) {
  std::string text;
  try {
    text = read_regular_file(file, "head-pose track", kMaxBytes);
  } catch (const FileAccessError& e) {
    throw AssetError(fmt::format("head-pose track \"{}\": {}", file.string(), e.action_and_reason()));
  }
  return parse(text, file.string());
}

HeadPoseTrack HeadPoseTrack::parse(const std::string& text, const std::string& name) {
  HeadPoseTrack track;
  // Column indices, once the header is read.
  std::optional<size_t> t_col, yaw_col, pitch_col, roll_col, qw_col, qx_col, qy_col, qz_col;
  bool have_header = false, quaternions = false;
  size_t columns_needed = 0;
  size_t line_number = 0;
  for (size_t start = 0; start < text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + start, end - start);
    start = end + 1;
    ++line_number;
    const auto fail = [&](const std::string& what) {
      throw AssetError(fmt::format("head-pose track \"{}\" line {}: {}", name, line_number, what));
    };
    const std::vector<std::string_view> fields = fields_of(line);
    if (fields.empty() || fields[0].starts_with('#')) continue;
    if (!have_header) {
      for (size_t i = 0; i < fields.size(); ++i) {
        const std::string_view f = fields[i];
        for (auto& [column_name, column] : {std::pair{"t_s", &t_col}, {"yaw_deg", &yaw_col}, {"pitch_deg", &pitch_col},
                                            {"roll_deg", &roll_col}, {"qw", &qw_col}, {"qx", &qx_col},
                                            {"qy", &qy_col}, {"qz", &qz_col}})
          if (f == column_name) {
            if (*column) fail(fmt::format("the column {} is named twice", f));
            *column = i;
          }
      }
      const bool angles = yaw_col && pitch_col;
      quaternions = qw_col && qx_col && qy_col && qz_col;
      if (!t_col || angles == quaternions)
        fail(fmt::format("expected a header naming t_s and either yaw_deg, pitch_deg (and roll_deg) or qw, qx, qy, qz; found \"{}\"",
                         std::string(line.substr(0, 200))));
      for (const auto& c : {t_col, yaw_col, pitch_col, roll_col, qw_col, qx_col, qy_col, qz_col})
        if (c) columns_needed = std::max(columns_needed, *c + 1);
      have_header = true;
      continue;
    }
    if (fields.size() < columns_needed)
      fail(fmt::format("{} fields, where the header needs {}", fields.size(), columns_needed));
    if (track.samples_.size() == kMaxSamples) fail(fmt::format("more than the limit of {} samples", kMaxSamples));
    const auto number = [&](size_t column, const char* column_name) {
      const std::string_view f = fields[column];
      double value = 0;
      const auto [end_ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), value);
      if (ec != std::errc() || end_ptr != f.data() + f.size() || !std::isfinite(value))
        fail(fmt::format("{} \"{}\" is not a finite number", column_name, std::string(f.substr(0, 40))));
      return value;
    };
    Sample sample;
    sample.t_s = number(*t_col, "t_s");
    if (!track.samples_.empty() && !(sample.t_s > track.samples_.back().t_s))
      fail(fmt::format("t_s {} is not after the line before's {}: a track's times must increase", sample.t_s,
                       track.samples_.back().t_s));
    if (quaternions) {
      double w = number(*qw_col, "qw"), x = number(*qx_col, "qx"), y = number(*qy_col, "qy"), z = number(*qz_col, "qz");
      const double length = std::sqrt(w * w + x * x + y * y + z * z);
      if (!(std::abs(length - 1) <= 0.01)) fail(fmt::format("the quaternion's length is {}, not 1 (within 1 %)", length));
      w /= length, x /= length, y /= length, z /= length;
      sample.R_pano_cam = camera_from_head_quaternion(w, x, y, z);
    } else {
      const double pitch = number(*pitch_col, "pitch_deg");
      if (pitch < -90 || pitch > 90) fail(fmt::format("pitch_deg {} is outside [-90, 90]", pitch));
      sample.R_pano_cam = panorama_view_rotation(number(*yaw_col, "yaw_deg") * kRadiansPerDegree, pitch * kRadiansPerDegree,
                                                 roll_col ? number(*roll_col, "roll_deg") * kRadiansPerDegree : 0.0);
    }
    track.samples_.push_back(sample);
  }
  if (!have_header) throw AssetError(fmt::format("head-pose track \"{}\": no header line (t_s and the orientation's columns)", name));
  if (track.samples_.empty()) throw AssetError(fmt::format("head-pose track \"{}\": no sample after the header", name));
  return track;
}

Mat3 HeadPoseTrack::rotation_at(double t_s) const {
  const auto after = std::upper_bound(samples_.begin(), samples_.end(), t_s,
                                      [](double t, const Sample& s) { return t < s.t_s; });
  if (after == samples_.begin()) return samples_.front().R_pano_cam;
  if (after == samples_.end()) return samples_.back().R_pano_cam;
  const Sample& a = *(after - 1);
  const Sample& b = *after;
  const double s = (t_s - a.t_s) / (b.t_s - a.t_s);
  return SE3(a.R_pano_cam, {0, 0, 0}).interpolate(SE3(b.R_pano_cam, {0, 0, 0}), s).rotation();
}

}  // namespace arpipe
