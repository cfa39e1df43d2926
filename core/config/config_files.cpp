// Input files of a config, checked through the regular-file-only opener, each naming its key.
#include "core/config/config_files.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "core/config/regular_file.h"
#include "core/scene/builtin_meshes.h"

namespace arpipe {

namespace {

namespace fs = std::filesystem;

std::string config_name(const Config& config) {
  return config.file.empty() ? std::string("config") : config.file.string();
}

void check_regular_file(const Config& config, const std::string& key, const fs::path& path, std::string_view what) {
  if (path.empty())
    throw ConfigError(fmt::format("{}: {}: is empty, expected the path of {}", config_name(config), key, what));
  try {
    ::close(open_regular_file(path, what));
  } catch (const FileAccessError& e) {
    throw ConfigError(fmt::format("{}: {}: {}: {}", config_name(config), key, path.string(), e.reason()));
  }
}

void check_recording_dir(const Config& config, const fs::path& dir) {
  const std::string key = "source.path";
  // Empty is the default (config --defaults): nothing named, so nothing to check here; starting a
  // replay without it fails naming source.path (capture/replay_source.cpp).
  if (dir.empty()) return;
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)
    throw ConfigError(fmt::format("{}: {}: {}: {}", config_name(config), key, dir.string(), ec.message()));
  if (!fs::is_directory(status))
    throw ConfigError(fmt::format("{}: {}: {}: {}, expected a recording directory", config_name(config), key,
                                  dir.string(), fs::exists(status) ? "not a directory" : "no such directory"));
  // recording.json: kRecordingInfoFile of capture/recording/recording_format.h (core cannot include capture).
  check_regular_file(config, key, dir / "recording.json", "recording description");
}

}  // namespace

void check_config_files(const Config& config) {
  if (config.source.type == SourceType::Replay) check_recording_dir(config, config.source.path);
  if (!config.source.camera_model.empty())
    check_regular_file(config, "source.camera_model", config.source.camera_model, "camera model");
  if (config.source.type == SourceType::Panorama) {
    check_regular_file(config, "source.panorama.file", config.source.panorama.file, "panorama");
    for (size_t i = 0; i < config.source.panorama.viewpoints.size(); ++i)
      check_regular_file(config, fmt::format("source.panorama.viewpoints[{}].file", i), config.source.panorama.viewpoints[i].file,
                         "panorama");
    if (!config.source.panorama.view.track.empty())
      check_regular_file(config, "source.panorama.view.track", config.source.panorama.view.track, "head-pose track");
  }
  if (config.render.enabled)
    for (size_t i = 0; i < config.render.objects.size(); ++i) {
      const std::string& mesh = config.render.objects[i].mesh;
      if (!is_builtin_mesh_source(mesh))
        check_regular_file(config, fmt::format("render.objects[{}].mesh", i), mesh, "glTF mesh");
    }
  if (config.render.enabled)
    for (size_t i = 0; i < config.render.proxies.size(); ++i) {
      const SceneProxy& proxy = config.render.proxies[i];
      if (!is_builtin_mesh_source(proxy.mesh))
        check_regular_file(config, fmt::format("render.proxies[{}].mesh", i), proxy.mesh, "glTF mesh");
      if (!proxy.collision_mesh.empty())
        check_regular_file(config, fmt::format("render.proxies[{}].collision_mesh", i), proxy.collision_mesh, "glTF mesh");
    }
  if (config.light.source == LightSource::Panorama && !config.light.panorama.lights_file.empty())
    check_regular_file(config, "light.panorama.lights_file", config.light.panorama.lights_file, "glTF lights");
  if (config.light.source == LightSource::Environment || !config.light.environment.file.empty())
    check_regular_file(config, "light.environment.file", config.light.environment.file, "HDR environment");
}

}  // namespace arpipe
