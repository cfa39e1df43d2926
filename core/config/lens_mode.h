// The three ways the virtual layer can match the real lens (config key render.lens), with their
// one name table; render/lens/lens_mode.h says which lens models each of them can reproduce.
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class LensMode {
  Map,        // pinhole canvas, warped per pixel through a map built with mrcal (render/lens/lens_warp_map.h)
  Vertex,     // distortion applied per vertex in the vertex shader (render/lens/lens_projection.h)
  Undistort,  // the camera frame undistorted to the pinhole core; drawn pinhole (render/lens/lens_undistortion.h)
};

inline constexpr ChoiceName<LensMode> kLensModeNames[] = {
    {"map", LensMode::Map}, {"vertex", LensMode::Vertex}, {"undistort", LensMode::Undistort}};

}  // namespace arpipe
