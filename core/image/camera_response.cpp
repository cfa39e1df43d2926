#include "core/image/camera_response.h"

#include <charconv>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "core/image/srgb.h"

namespace arpipe {

CameraResponse::CameraResponse() { build_lut(); }

CameraResponse CameraResponse::linear() {
  CameraResponse r;
  r.kind_ = Kind::Linear;
  r.build_lut();
  return r;
}

CameraResponse CameraResponse::gamma(double g) {
  if (!(g > 0) || !std::isfinite(g)) throw std::invalid_argument(fmt::format("camera response gamma {} must be > 0", g));
  CameraResponse r;
  r.kind_ = Kind::Gamma;
  r.gamma_ = g;
  r.build_lut();
  return r;
}

std::optional<CameraResponse> CameraResponse::from_name(std::string_view text) {
  try {
    return parse(text, "");
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
}

CameraResponse CameraResponse::parse(std::string_view text, std::string_view where) {
  if (text == "srgb") return srgb();
  if (text == "linear") return linear();
  constexpr std::string_view kGamma = "gamma:";
  if (text.starts_with(kGamma)) {
    const std::string_view number = text.substr(kGamma.size());
    double g = 0;
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), g);
    if (error == std::errc() && end == number.data() + number.size() && g > 0 && std::isfinite(g)) return gamma(g);
    throw std::invalid_argument(fmt::format("{}: camera response \"{}\": expected gamma:<g> with g a positive number",
                                            where, text));
  }
  throw std::invalid_argument(
      fmt::format("{}: camera response \"{}\": expected \"srgb\", \"linear\" or \"gamma:<g>\"", where, text));
}

std::string CameraResponse::name() const {
  switch (kind_) {
    case Kind::Srgb: return "srgb";
    case Kind::Linear: return "linear";
    case Kind::Gamma: return fmt::format("gamma:{}", gamma_);
  }
  return "?";
}

double CameraResponse::decode(double encoded) const {
  const double e = std::clamp(encoded, 0.0, 1.0);
  switch (kind_) {
    case Kind::Srgb: return srgb_decode(e);
    case Kind::Gamma: return std::pow(e, gamma_);
    case Kind::Linear: break;
  }
  return e;
}

void CameraResponse::build_lut() {
  for (int v = 0; v < 256; ++v) lut_[size_t(v)] = float(decode(v / 255.0));
}

}  // namespace arpipe
