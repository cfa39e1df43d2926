// A camera frame: pixels in the source's own format plus the exposure metadata of docs/DESIGN.md.
// Timestamps are int64 nanoseconds on CLOCK_MONOTONIC.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "core/geometry/ods_projection.h"
#include "core/geometry/se3.h"
#include "core/pixel_format.h"
#include "core/raw_colour.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

// What a source's raw timestamp meant before it was normalised to exposure_start_ns.
enum class TimestampMeaning {
  StartOfExposure,  // first row started exposing (libcamera SensorTimestamp, V4L2 SOE)
  EndOfFrame,       // last row was read out (V4L2 EOF, most UVC drivers)
  EndOfExposure,    // first row stopped exposing, i.e. its readout began (Raspberry Pi's SensorTimestamp, reportedly)
  Sensor,           // sensor-defined; treated as start of exposure plus the configured offset
};
std::string_view timestamp_meaning_name(TimestampMeaning meaning);
bool timestamp_meaning_from_name(std::string_view name, TimestampMeaning& out);

struct FrameMetadata {
  uint64_t sequence = 0;            // source sequence number; gaps are dropped frames
  int64_t exposure_start_ns = 0;    // CLOCK_MONOTONIC time the first row started exposing
  int64_t exposure_ns = 0;          // exposure time of one row
  int64_t readout_ns = 0;           // first-row to last-row readout time; 0 for a global shutter
  int64_t frame_duration_ns = 0;    // nominal frame interval
  double analogue_gain = 1.0;
  double digital_gain = 1.0;
  int64_t raw_timestamp_ns = 0;     // the source's timestamp as it gave it
  TimestampMeaning raw_timestamp_meaning = TimestampMeaning::StartOfExposure;
  int64_t timestamp_offset_ns = 0;  // per-camera offset applied while normalising
  // What the camera's own processing measured, when it says (libcamera's Lux and
  // ColourTemperature); 0 when unknown.
  double lux = 0;
  double colour_temperature_k = 0;
  // Where the camera was, when the source knows it rather than a tracker (a panorama's view
  // camera, turned by its configured sweep): T_cam_world at exposure_mid_ns. The track stage then
  // takes it instead of detecting tags.
  std::optional<SE3> known_T_cam_world;
  // The index of the source's own frame this one shows, when that differs from the sequence: a
  // panorama video's frame (in presentation order), which repeats on each loop.
  std::optional<int64_t> source_frame_index;
  // Where that frame lies on the source's own timeline (a panorama video's frame: its index over
  // the video's nominal rate; a still: 0): the time the scene's animations are sampled at
  // (render.proxies[].node, light.panorama.lights_animation). None for cameras and recordings.
  std::optional<int64_t> source_frame_time_ns;
  // The place the source shows, when it has several (a panorama's viewpoint: 0 is source.panorama's
  // own); proxies of other viewpoints are not drawn.
  std::optional<int> viewpoint;
  // Which eye of a stereo panorama the frame shows (source.panorama.layout "equirect-tb" or "-lr":
  // each time step gives the left eye's frame, then the right's, with the same times); the renderer
  // then draws through that eye's omnidirectional-stereo geometry (core/geometry/ods_projection.h).
  Eye eye = Eye::Mono;
  OdsRig ods;  // a stereo eye's capture geometry (source.panorama's ipd and pole merge)
  // The whole light around the camera, when the source holds it (a panorama, which is its own
  // environment): radiance SH in the world frame, scene-linear (light.source = "panorama").
  std::optional<ShRgb9> environment_sh;
  // How a raw Bayer frame develops into light (core/raw_colour.h); unused for other formats.
  RawColour raw;

  // Middle of the exposure of the middle row: where a single pose for the frame belongs.
  int64_t exposure_mid_ns() const { return exposure_start_ns + (exposure_ns + readout_ns) / 2; }
  double total_gain() const { return analogue_gain * digital_gain; }
};

// Turns a raw source timestamp into exposure_start_ns per docs/DESIGN.md:
// end of frame minus exposure and readout; plus the configured per-camera offset.
int64_t exposure_start_from_raw(int64_t raw_ns, TimestampMeaning meaning, int64_t exposure_ns,
                                int64_t readout_ns, int64_t offset_ns);

struct Frame {
  FrameMetadata meta;
  PixelFormat format = PixelFormat::RGB24;
  int width = 0;
  int height = 0;
  size_t bytes_per_line = 0;  // stride of the first plane (NV12's UV plane has the same stride)
  std::vector<uint8_t> data;

  // Allocates an image of this format and size with the minimum stride.
  static Frame allocate(PixelFormat format, int width, int height);
  // Gives this frame that format, size and stride (0: the minimum), keeping its memory when it
  // holds enough (a recycled frame, core/pipeline/frame_pool.h); its pixels are then undefined.
  // True when the memory had to be allocated.
  bool reshape(PixelFormat format, int width, int height, size_t bytes_per_line = 0);
  bool empty() const { return data.empty(); }
};

}  // namespace arpipe
