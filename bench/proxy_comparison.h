// Phantom proxies against the simulator's visible coverage, shared by the proxy tests and `arpipe
// bench proxies`: every frame of a capture with ground_truth_coverage/ (configs/sim/proxies.toml)
// drawn by the render and composite stages with the ground-truth camera motion (so that only the
// renderer is measured), the virtual layer's alpha against the coverage.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "capture/sim/ground_truth_coverage.h"
#include "core/config/config.h"
#include "core/pipeline/frame_context.h"

namespace arpipe::bench {

// Issue 22's measure of an occlusion edge: the symmetric difference of the drawn and the true
// coverage masks (each thresholded at one half) over the length of the true visible outline (the
// total variation of the true coverage: for an antialiased edge, its length in pixels).
struct EdgeError {
  double displacement_px = 0;
  double edge_length_px = 0;
};
EdgeError occlusion_edge_error(const std::vector<float>& drawn, const sim::CoverageImage& truth);

// The virtual layer's alpha, read back (row-major, the layer's size), zero outside its rectangle.
// Needs the render stages' GL context current.
std::vector<float> layer_alpha(const VirtualLayerTexture& layer);

struct ProxyFrame {
  double motion_px = 0;  // the largest image motion of the first object's box corners over the exposure
  EdgeError edge;
  std::string blur_method;
  int blur_samples = 0;
  double hidden = -1;  // the frame's report for the first object (-1: none)
};

struct ProxyCaptureRun {
  std::vector<ProxyFrame> frames;
  double render_ms = 0;     // median over the frames and repeats: the render stage, report included
  double occlusion_ms = 0;  // median: the per-object hidden-share report alone
  double worst_still_px = 0, worst_blurred_px = 0;  // frames under / over 1 px of motion
  double mean_still_px = 0, mean_blurred_px = 0;
  int still_frames = 0, blurred_frames = 0;
};

// Draws the capture `repeats` times with `config` (its source is not used; set its shadows to
// "off" to measure coverage: the layer's alpha is then the objects' alone). Throws on a capture
// without coverage, or a frame the stages do not draw.
// The middle value (the upper of the two for an even count); 0 for none.
double median_of(std::vector<double> values);

ProxyCaptureRun run_proxy_capture(const std::filesystem::path& capture, const Config& config, int repeats = 1);

}  // namespace arpipe::bench
