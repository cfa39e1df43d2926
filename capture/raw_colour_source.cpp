#include "capture/raw_colour_source.h"

#include <fmt/format.h>

#include <vector>

#include "core/image/bayer.h"
#include "core/log.h"

namespace arpipe {

namespace {

// [source.raw]'s overrides of the camera's values (the white balance mode aside).
RawColour with_config(RawColour raw, const RawColourConfig& config) {
  if (config.black_level.size() == 1) raw.black_level = std::array<double, 4>{};
  if (config.black_level.size() == 1) raw.black_level->fill(config.black_level[0]);
  if (config.black_level.size() == 4)
    raw.black_level = std::array<double, 4>{config.black_level[0], config.black_level[1], config.black_level[2],
                                            config.black_level[3]};
  if (config.white_level > 0) raw.white_level = config.white_level;
  if (config.colour_matrix.size() == 9) {
    std::array<double, 9> m{};
    std::copy(config.colour_matrix.begin(), config.colour_matrix.end(), m.begin());
    raw.colour_matrix = m;
  }
  if (config.white_balance == WhiteBalanceMode::GreyWorld) raw.gains.reset();
  if (config.white_balance == WhiteBalanceMode::Fixed) raw.gains = config.gains;
  return raw;
}

std::string levels_text(const RawColour& raw) {
  const std::array<double, 4> black = raw.black_level.value_or(std::array<double, 4>{});
  return fmt::format("black {}/{}/{}/{}, white {}", black[0], black[1], black[2], black[3],
                     raw.white_level > 0 ? fmt::format("{}", raw.white_level) : std::string("the top code"));
}

}  // namespace

void RawColourResolver::resolve(Frame& frame) {
  if (!is_bayer(frame.format)) return;
  RawColour camera = frame.meta.raw;
  if (std::string why = raw_colour_problem(camera, frame.format); !why.empty()) {
    if (!reported_camera_problem_)
      log::warn("raw frames: the camera's {} for {}: left out, the frames develop without it", why,
                pixel_format_name(frame.format));
    reported_camera_problem_ = true;
    camera = RawColour{};
  }
  const bool camera_gains = camera.gains.has_value();
  RawColour raw = with_config(camera, config_);
  if (std::string why = raw_colour_problem(raw, frame.format); !why.empty()) {
    if (!reported_config_problem_)
      log::error("raw frames: source.raw: {} for {}: not applied, the frames develop with the camera's values", why,
                 pixel_format_name(frame.format));
    reported_config_problem_ = true;
    raw = camera;
  }
  const bool measured = !raw.gains.has_value();
  if (measured) {
    // Grey world needs the frame normalised exactly as develop_bayer will normalise it.
    thread_local BayerMosaic mosaic;
    thread_local std::vector<float> normalised;
    try {
      unpack_bayer(frame, mosaic);
      normalise_bayer(mosaic, bayer_development(raw), normalised);
      raw.gains = grey_world_gains(normalised, mosaic.width, mosaic.height, mosaic.order);
    } catch (const std::exception&) {
      raw.gains = std::array<double, 3>{1, 1, 1};  // a frame its format cannot hold: every stage refuses it anyway
    }
  }
  if (!described_)
    log::info("raw frames ({}): {}, gains {} ({}), {}", pixel_format_name(frame.format), levels_text(raw),
              fmt::format("{:.3f}/{:.3f}/{:.3f}", (*raw.gains)[0], (*raw.gains)[1], (*raw.gains)[2]),
              measured ? "grey world, per frame"
                       : (config_.white_balance == WhiteBalanceMode::Fixed ? "source.raw.gains"
                                                                            : (camera_gains ? "the camera's" : "")),
              raw.colour_matrix ? "a colour matrix" : "no colour matrix");
  described_ = true;
  frame.meta.raw = raw;
}

SourceStatus RawColourSource::next(Frame& frame) {
  const SourceStatus status = inner_->next(frame);
  if (status == SourceStatus::Frame) resolver_.resolve(frame);
  return status;
}

}  // namespace arpipe
