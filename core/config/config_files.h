// The input files a config names (recording, camera model, meshes, HDR environment, panoramas,
// head tracks, scene lights): each must
// exist and be a regular, readable file, checked up front so `arpipe config --check` can say so.
#pragma once

#include "core/config/config.h"

namespace arpipe {

// Throws ConfigError "<config>: <key>: <path>: <reason>" for the first input that cannot be used:
// source.path (replay, when set: a directory holding recording.json), source.camera_model, every
// render.objects[i].mesh that is a file (render enabled), light.environment.file (when the light
// source is "environment" or a file is named); for a panorama source its file, every viewpoint's
// file and the head-pose track; light.panorama.lights_file (light source "panorama"). Paths are relative to the working directory, as
// arpiped reads them. Only existence and type are checked here; each loader checks the content.
void check_config_files(const Config& config);

}  // namespace arpipe
