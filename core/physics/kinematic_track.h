// Where a kinematic body is at an instant: its pose track interpolated (body origin on a straight
// line at constant speed, orientation by slerp), held before the first key and after the last.
#pragma once

#include <cstdint>
#include <vector>

#include "core/physics/rigid_body_spec.h"

namespace arpipe {

// `fallback` when the track is empty. The keys are time-ordered (spec_checks.h checks it).
SE3 pose_on_track(const std::vector<BodyPoseKey>& track, int64_t t_ns, const SE3& fallback);

}  // namespace arpipe
