// The three ways the virtual layer can match the real lens (config key render.lens), and which
// lens models each of them can reproduce, checked before streaming starts.
#pragma once

#include <string_view>

#include "core/geometry/camera_model.h"

namespace arpipe {

enum class LensMode {
  Map,        // pinhole canvas, warped per pixel through a map built with mrcal (lens_warp_map.h)
  Vertex,     // distortion applied per vertex in the vertex shader (lens_projection.h)
  Undistort,  // the camera frame undistorted to the pinhole core; drawn pinhole (lens_undistortion.h)
};

// "map", "vertex" or "undistort"; throws ConfigError otherwise (the config loader has checked it).
LensMode parse_lens_mode(std::string_view name);
std::string_view lens_mode_name(LensMode mode);

// Throws RenderError naming the model when this mode cannot render through it: Vertex needs
// PINHOLE or OPENCV4/5/8; Map needs a pinhole core, mrcal's unprojection of the whole image border
// and a field of view a pinhole canvas can hold; Undistort needs a pinhole core.
void check_lens_for_mode(const CameraModel& model, LensMode mode);

}  // namespace arpipe
