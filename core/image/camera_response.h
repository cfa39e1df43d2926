// The camera's response curve (encoded 8-bit value -> linear light in [0, 1]), as docs/DESIGN.md's colour
// rule needs: "srgb" (default), "linear" or "gamma:<g>", decoded through a 256-entry table.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace arpipe {

class CameraResponse {
 public:
  enum class Kind { Srgb, Linear, Gamma };

  // An 8-bit value at or above this counts as clipped. A sensor clipped at full scale reaches 255
  // only where all three channels and their chroma neighbours saturate: YUYV/NV12 carry luma at
  // 16..235 and chroma subsampled, so a saturated pixel comes back from BT.601 at 250..255 after
  // rounding and chroma mixing at a highlight's edge. 250 decodes to 0.956 of full scale (sRGB),
  // so treating it as clipped loses little and never mistakes a clipped value for a measurement.
  static constexpr int kClippedFrom = 250;

  CameraResponse();  // sRGB
  static CameraResponse srgb() { return CameraResponse(); }
  static CameraResponse linear();
  static CameraResponse gamma(double g);  // encoded = linear^(1/g); g > 0
  // "srgb", "linear" or "gamma:<g>" (the simulator's camera.sensor.response words). Throws
  // std::invalid_argument naming `where` and the text when it is none of these.
  static CameraResponse parse(std::string_view text, std::string_view where);
  // The same rule without the message: nullopt when the text is none of these (the config's reader).
  static std::optional<CameraResponse> from_name(std::string_view text);

  Kind kind() const { return kind_; }
  double gamma_value() const { return gamma_; }
  std::string name() const;  // as parse() reads it

  // Encoded value in [0, 1] to linear light in [0, 1].
  double decode(double encoded) const;
  // 8-bit value to linear light, from the table.
  float decode8(uint8_t value) const { return lut_[value]; }
  const std::array<float, 256>& lut() const { return lut_; }
  static bool clipped(uint8_t value) { return value >= kClippedFrom; }

  bool operator==(const CameraResponse&) const = default;

 private:
  void build_lut();
  Kind kind_ = Kind::Srgb;
  double gamma_ = 1;
  std::array<float, 256> lut_{};
};

}  // namespace arpipe
