// How far world points move in the image while their own row is exposed: the blur length that
// decides whether a frame needs motion blur at all (below half a pixel it does not).
#pragma once

#include <vector>

#include "core/geometry/camera_model.h"
#include "core/motion/shutter_motion.h"

namespace arpipe {

// The longest image path, in pixels, of any of the world points over its row's exposure window
// (the row it lies on at the frame's pose; with a global shutter every row's window is the whole
// exposure). The path is followed in `steps` pieces, so a motion that turns back is measured by
// its length, not by its end points. Points the camera cannot see at the frame's pose are skipped;
// 0 when none is seen or the motion is None.
double max_image_motion_px(const ShutterMotion& motion, const CameraModel& camera, const std::vector<Vec3>& world_points,
                           int steps = 8);

}  // namespace arpipe
