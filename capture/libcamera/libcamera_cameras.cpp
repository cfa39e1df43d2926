#include "capture/libcamera/libcamera_cameras.h"

#include <algorithm>

#include <fmt/format.h>
#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/property_ids.h>
#include <libcamera/stream.h>

#include "capture/libcamera/libcamera_manager.h"
#include "capture/libcamera/libcamera_pixel_format.h"
#include "capture/live/camera_stream.h"

namespace arpipe {

namespace {

std::string location_name(int32_t location) {
  switch (location) {
    case libcamera::properties::CameraLocationFront: return "front";
    case libcamera::properties::CameraLocationBack: return "back";
    case libcamera::properties::CameraLocationExternal: return "external";
    default: return fmt::format("location {}", location);
  }
}

CameraDescription describe(libcamera::Camera& camera) {
  CameraDescription d;
  d.backend = SourceType::Libcamera;
  d.id = camera.id();
  const auto& props = camera.properties();
  if (auto model = props.get(libcamera::properties::Model)) d.name = *model;
  if (auto location = props.get(libcamera::properties::Location)) d.location = location_name(*location);

  for (const auto& [id, info] : camera.controls()) d.controls.push_back({id->name(), info.toString()});
  std::sort(d.controls.begin(), d.controls.end(), [](const auto& a, const auto& b) { return a.name < b.name; });

  // Generating a configuration does not need the camera acquired, so a camera busy in another
  // process still lists its formats.
  auto config = camera.generateConfiguration({libcamera::StreamRole::VideoRecording});
  if (!config || config->empty())
    d.error = "the camera generated no video configuration";
  else
    d.modes = libcamera_modes(config->at(0).formats());
  return d;
}

}  // namespace

std::vector<CameraMode> libcamera_modes(const libcamera::StreamFormats& formats) {
  std::vector<CameraMode> modes;
  for (const auto& pf : formats.pixelformats()) {
    auto ours = pixel_format_from_libcamera(pf);
    std::string name = ours ? std::string(pixel_format_name(*ours)) : pf.toString();
    auto sizes = formats.sizes(pf);
    if (sizes.empty()) {
      auto range = formats.range(pf);
      CameraMode m;
      m.format = name;
      m.width = static_cast<int>(range.max.width);
      m.height = static_cast<int>(range.max.height);
      m.note = fmt::format("sizes {} to {}", range.min.toString(), range.max.toString());
      modes.push_back(m);
      continue;
    }
    for (const auto& s : sizes) {
      CameraMode m;
      m.format = name;
      m.width = static_cast<int>(s.width);
      m.height = static_cast<int>(s.height);
      modes.push_back(m);
    }
  }
  return modes;
}

std::vector<CameraDescription> list_libcamera_cameras() {
  std::vector<CameraDescription> out;
  libcamera::CameraManager* manager = nullptr;
  try {
    manager = &libcamera_manager();
  } catch (const CameraError& e) {
    CameraDescription d;
    d.backend = SourceType::Libcamera;
    d.error = e.what();
    out.push_back(d);
    return out;
  }
  for (const auto& camera : manager->cameras()) out.push_back(describe(*camera));
  return out;
}

}  // namespace arpipe
