#include "capture/v4l2/v4l2_cameras.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <filesystem>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "capture/live/camera_stream.h"
#include "capture/v4l2/v4l2_device.h"
#include "capture/v4l2/v4l2_negotiation.h"
#include "core/pixel_format.h"

namespace arpipe {

namespace {

std::string mode_format_name(uint32_t fourcc) {
  if (is_mjpeg_fourcc(fourcc)) return "MJPG";
  if (const auto format = pixel_format_from_fourcc(fourcc)) return std::string(pixel_format_name(*format));
  return fourcc_text(fourcc);
}

// /dev/video0, /dev/video1, ..., /dev/video10 in numeric order.
std::vector<std::string> video_nodes() {
  std::vector<std::pair<int, std::string>> nodes;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("video", 0) != 0 || name.size() == 5) continue;
    const std::string digits = name.substr(5);
    if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) continue;
    nodes.emplace_back(std::stoi(digits), entry.path().string());
  }
  std::sort(nodes.begin(), nodes.end());
  std::vector<std::string> paths;
  for (auto& [number, path] : nodes) paths.push_back(std::move(path));
  return paths;
}

// The stable links (/dev/v4l/by-id, by-path) that point at a node: what a config should use.
std::vector<std::string> stable_links(const std::string& node) {
  std::vector<std::string> links;
  std::error_code ec;
  const auto target = std::filesystem::canonical(node, ec);
  if (ec) return links;
  for (const char* dir : {"/dev/v4l/by-id", "/dev/v4l/by-path"})
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
      if (std::filesystem::canonical(entry.path(), ec) == target) links.push_back(entry.path().string());
  return links;
}

CameraDescription describe(const std::string& path, bool capture_only, bool& keep) {
  CameraDescription d;
  d.backend = SourceType::V4l2;
  d.id = path;
  keep = true;
  try {
    const V4L2Device device(path);
    d.name = device.card();
    d.location = device.bus_info();
    const auto links = stable_links(path);
    if (!links.empty()) d.location += fmt::format(" ({})", fmt::join(links, ", "));
    if (!device.can_capture()) {
      keep = !capture_only;
      d.error = fmt::format("not a video capture device with streaming I/O (device caps {:#x})", device.device_caps());
      return d;
    }
    for (const auto& offer : device.enumerate_formats()) {
      if (!offer.note.empty()) d.modes.push_back({mode_format_name(offer.fourcc), 0, 0, {}, offer.note});
      for (const auto& size : offer.sizes) {
        CameraMode mode{mode_format_name(offer.fourcc), int(size.width), int(size.height), {}, size.note};
        for (const auto& interval : size.intervals) mode.fps.push_back(interval.fps());
        if (!is_usable_fourcc(offer.fourcc)) mode.note += mode.note.empty() ? "not usable by arpipe" : "; not usable by arpipe";
        d.modes.push_back(std::move(mode));
      }
    }
    d.controls = list_v4l2_controls(device);
  } catch (const std::exception& e) {
    d.error = e.what();
  }
  return d;
}

std::string control_range(const v4l2_query_ext_ctrl& q) {
  switch (q.type) {
    case V4L2_CTRL_TYPE_BOOLEAN:
      return fmt::format("bool, default {}", q.default_value);
    case V4L2_CTRL_TYPE_MENU:
    case V4L2_CTRL_TYPE_INTEGER_MENU:
      return fmt::format("menu {}..{}, default {}", q.minimum, q.maximum, q.default_value);
    case V4L2_CTRL_TYPE_BUTTON:
      return "button";
    default:
      return fmt::format("{}..{} step {}, default {}", q.minimum, q.maximum, q.step, q.default_value);
  }
}

}  // namespace

std::vector<CameraControl> list_v4l2_controls(const V4L2Device& device) {
  std::vector<CameraControl> controls;
  v4l2_query_ext_ctrl q{};
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
  while (device.ioctl(VIDIOC_QUERY_EXT_CTRL, &q) == 0) {
    if (q.type != V4L2_CTRL_TYPE_CTRL_CLASS && !(q.flags & V4L2_CTRL_FLAG_DISABLED)) {
      std::string range = control_range(q);
      if (q.id == V4L2_CID_EXPOSURE_ABSOLUTE) range += " (100 µs units)";
      if (q.flags & V4L2_CTRL_FLAG_INACTIVE) range += ", inactive";
      if (q.flags & V4L2_CTRL_FLAG_READ_ONLY) range += ", read-only";
      controls.push_back({reinterpret_cast<const char*>(q.name), range});
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
  }
  return controls;
}

std::vector<CameraDescription> list_v4l2_cameras(const std::vector<std::string>& extra_paths) {
  std::vector<CameraDescription> cameras;
  for (const auto& path : video_nodes()) {
    bool keep = true;
    auto d = describe(path, true, keep);
    if (keep) cameras.push_back(std::move(d));
  }
  for (const auto& path : extra_paths) {
    bool keep = true;
    cameras.push_back(describe(path, false, keep));
  }
  return cameras;
}

}  // namespace arpipe
