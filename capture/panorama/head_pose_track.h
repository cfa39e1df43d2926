// A head-pose track (source.panorama.view.track): the view's orientation over time, as a 360° player
// or a headset logs it, turned between samples at constant angular velocity (slerp).
//
// The file is text: blank lines and lines starting with '#' are skipped; the first other line names
// the columns (commas or white space between fields, in any order, other columns ignored):
//   t_s                                 seconds from the view's first frame (frame k is at k / fps)
//   yaw_deg, pitch_deg [, roll_deg]     as source.panorama.view's yaw and pitch; roll > 0 tilts the
//                                       head right (right ear down), so the picture turns anticlockwise
//   or qw, qx, qy, qz                   the head's orientation in the panorama's frame, OpenXR's
//                                       convention (x right, y up, -z forward): the identity looks at
//                                       the image's centre with its top up
// Times strictly increase. Before the first sample the first orientation holds, after the last the
// last one.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe {

class HeadPoseTrack {
 public:
  static constexpr uint64_t kMaxBytes = uint64_t{64} << 20;  // 10 minutes at 1 kHz is about 40 MB
  static constexpr size_t kMaxSamples = 2'000'000;

  struct Sample {
    double t_s = 0;
    Mat3 R_pano_cam;  // the view camera's axes (right, down, forward) in the panorama's frame
  };

  // Reads and checks the file. Throws AssetError naming the file and the line: a missing or unknown
  // column set, a field that is not a finite number, a pitch outside [-90, 90], a quaternion whose
  // length is not 1 within 1 %, a time not after the line before's, no sample, past the limits.
  static HeadPoseTrack load(const std::filesystem::path& file);
  // The same from the file's text (`name` in messages).
  static HeadPoseTrack parse(const std::string& text, const std::string& name);

  // The orientation at t_s: slerp between the samples around it (the shorter way round).
  Mat3 rotation_at(double t_s) const;

  const std::vector<Sample>& samples() const { return samples_; }

 private:
  std::vector<Sample> samples_;
};

}  // namespace arpipe
