// The three ways the virtual layer can match the real lens (config key render.lens), and which
// lens models each of them can reproduce, checked before streaming starts.
#pragma once

#include <string_view>

#include "core/config/lens_mode.h"
#include "core/geometry/camera_model.h"

namespace arpipe {

// Its name in the config (kLensModeNames), for messages.
inline std::string_view lens_mode_name(LensMode mode) { return choice_name(kLensModeNames, mode); }

// Throws RenderError naming the model when this mode cannot render through it: Vertex needs
// PINHOLE or OPENCV4/5/8; Map needs a pinhole core, mrcal's unprojection of the whole image border
// and a field of view a pinhole canvas can hold; Undistort needs a pinhole core.
void check_lens_for_mode(const CameraModel& model, LensMode mode);

}  // namespace arpipe
