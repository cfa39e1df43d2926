// arpipe sh: inspect an HDR light probe through spherical harmonics: its radiance coefficients,
// the irradiance they give at chosen normals, and (optionally) the band-limited probe written back.
#include <fmt/format.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "core/image/hdr_file.h"
#include "core/image/openexr_file.h"
#include "core/image/radiance_hdr.h"
#include "core/image/reinhard_tone_map.h"
#include "core/image/srgb.h"
#include "core/environment/environment_sh.h"
#include "core/environment/hdr_environment.h"
#include "core/environment/environment_layout.h"
#include "core/sh/sh_irradiance.h"
#include "core/sh/sh_sampling.h"
#include "core/sh/sh_window.h"
#include "core/scene/asset_error.h"

#include <opencv2/imgcodecs.hpp>

namespace arpipe {
namespace {

// A number, the whole text (std::from_chars: no locale, no trailing characters).
std::optional<double> parse_number(std::string_view text) {
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<Vec3> parse_direction(const std::string& text) {
  Vec3 v{};
  size_t start = 0;
  for (size_t axis = 0; axis < 3; ++axis) {
    const size_t comma = text.find(',', start);
    if ((axis < 2) != (comma != std::string::npos)) return std::nullopt;
    const std::optional<double> value =
        parse_number(std::string_view(text).substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (!value) return std::nullopt;
    v[axis] = *value;
    start = comma + 1;
  }
  if (norm(v) <= 0) return std::nullopt;
  return normalized(v);
}

bool ends_with(const std::string& text, std::string_view suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The band-limited probe in its own layout: every valid texel gets sum_i c_i y_i(direction).
HdrImage reconstruct(const HdrEnvironment& environment, const ShRgb& sh, const Mat3& R_world_probe) {
  HdrImage out;
  out.width = environment.width();
  out.height = environment.height();
  out.rgb.assign(size_t(out.width) * size_t(out.height) * 3, 0.0f);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      const std::optional<Vec3> probe_dir = environment_pixel_direction(environment.layout(), out.width, out.height, x, y);
      if (!probe_dir) continue;
      const Vec3 radiance = sh_eval(sh, mat_mul(R_world_probe, *probe_dir));
      for (size_t c = 0; c < 3; ++c)
        out.rgb[(size_t(y) * size_t(out.width) + size_t(x)) * 3 + c] = static_cast<float>(std::max(0.0, radiance[c]));
    }
  return out;
}

void write_png(const std::string& path, HdrImage image) {
  reinhard_tone_map(image);
  cv::Mat bgr(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double linear = image.rgb[(size_t(y) * size_t(image.width) + size_t(x)) * 3 + size_t(c)];
        bgr.at<cv::Vec3b>(y, x)[2 - c] = static_cast<uint8_t>(std::lround(255 * srgb_encode(linear)));
      }
  if (!cv::imwrite(path, bgr)) throw std::runtime_error(fmt::format("{}: could not write the PNG", path));
}

struct ShOptions {
  std::string probe_file, layout_name, window_name = "none", method = "texels", reconstruct_path;
  int bands = 3, samples = 200;
  double yaw_deg = 0, scale = 1;
  std::vector<std::string> normals;
};

bool is_image_file(const std::string& path) {
  return ends_with(path, ".hdr") || ends_with(path, ".exr") || ends_with(path, ".png");
}

// The options are checked when read (add_sh_command): what is parsed here is known to parse.
int run_sh(const ShOptions& options) {
  const std::string& probe_file = options.probe_file;
  const std::string& window_name = options.window_name;
  const std::string& method = options.method;
  const std::string& reconstruct_path = options.reconstruct_path;
  const int bands = options.bands, samples = options.samples;
  const double yaw_deg = options.yaw_deg, scale = options.scale;
  const std::optional<EnvironmentLayout> layout = parse_environment_layout(options.layout_name);
  const std::optional<ShWindow> window = parse_sh_window(window_name);
  std::vector<Vec3> normals;
  for (const std::string& text : options.normals) normals.push_back(*parse_direction(text));

  const Mat3 R_world_probe = default_world_from_probe(yaw_deg * std::numbers::pi / 180);
  const HdrEnvironment environment = HdrEnvironment::load(probe_file, *layout, R_world_probe, scale);
  const auto start = std::chrono::steady_clock::now();
  ShRgb sh;
  if (method == "texels") {
    sh = project_environment(environment, bands);
  } else {
    const SphereSamples sphere = stratified_sphere_samples(samples, bands, 1);
    sh = project_samples(sphere, [&](const Vec3& d) { return environment.radiance(d); });
  }
  const double ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  apply_sh_window(sh, *window);
  fmt::print("probe {} ({} x {}, {}), scale {}, yaw {} deg\n", probe_file, environment.width(), environment.height(),
             environment_layout_name(*layout), scale, yaw_deg);
  fmt::print("radiance SH, {} bands, {} ({:.1f} ms), window {}\n", bands,
             method == "texels" ? std::string("per-texel solid angles") : fmt::format("{0} x {0} jittered samples", samples),
             ms, window_name);
  fmt::print("  {:>3} {:>3} {:>3}  {:>12} {:>12} {:>12}\n", "i", "l", "m", "R", "G", "B");
  for (int l = 0; l < bands; ++l)
    for (int m = -l; m <= l; ++m) {
      const Vec3& c = sh.c[size_t(sh_index(l, m))];
      fmt::print("  {:>3} {:>3} {:>3}  {:>12.6g} {:>12.6g} {:>12.6g}\n", sh_index(l, m), l, m, c[0], c[1], c[2]);
    }
  fmt::print("band energy (sum of c^2, luminance-weighted):");
  for (int l = 0; l < bands; ++l) {
    double energy = 0;
    for (int m = -l; m <= l; ++m) {
      const Vec3& c = sh.c[size_t(sh_index(l, m))];
      const double y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
      energy += y * y;
    }
    fmt::print(" {:.4g}", energy);
  }
  fmt::print("\n");
  for (const Vec3& n : normals) {
    const Vec3 e = sh_irradiance(sh, n);
    fmt::print("irradiance at normal [{:+.4f}, {:+.4f}, {:+.4f}]: [{:.6g}, {:.6g}, {:.6g}] (radiance of a white "
               "Lambertian surface: E / pi = [{:.6g}, {:.6g}, {:.6g}])\n",
               n[0], n[1], n[2], e[0], e[1], e[2], e[0] / std::numbers::pi, e[1] / std::numbers::pi,
               e[2] / std::numbers::pi);
  }
  if (!reconstruct_path.empty()) {
    const HdrImage image = reconstruct(environment, sh, R_world_probe);
    if (ends_with(reconstruct_path, ".hdr")) write_radiance_hdr(reconstruct_path, image);
    else if (ends_with(reconstruct_path, ".exr")) write_openexr(reconstruct_path, image);
    else write_png(reconstruct_path, image);
    fmt::print("wrote the {}-band reconstruction to {}\n", bands, reconstruct_path);
  }
  return 0;
}

}  // namespace

void add_sh_command(CLI::App& arpipe) {
  CLI::App* command =
      arpipe.add_subcommand("sh", "an HDR light probe's spherical-harmonic coefficients and irradiance");
  command->footer(
      "Projects a Radiance .hdr or OpenEXR light probe onto real spherical harmonics (Green's order, index\n"
      "l(l+1)+m, no Condon-Shortley phase) and prints the radiance coefficients per channel. Directions are in\n"
      "arpipe's world frame: the probe's up is +z, its forward +y, turned by --yaw degrees about +z. --normal\n"
      "prints the irradiance E(n) of the band-limited light (Ramamoorthi-Hanrahan: band l times A_l) at that\n"
      "world normal. --reconstruct writes the band-limited probe in the same layout and size: .hdr/.exr as\n"
      "linear radiance, .png tone-mapped with Reinhard's global operator (key 0.72) and sRGB-encoded.");
  auto options = std::make_shared<ShOptions>();
  command->add_option("--environment,--probe", options->probe_file, "the HDR environment file (.hdr, .exr); --probe is its old name")->type_name("FILE")->required();
  command->add_option("--layout", options->layout_name, "angular, mirror-ball, equirect or cube-cross")
      ->type_name("L")
      ->required()
      ->check(cli::accepted_by([](const std::string& t) { return parse_environment_layout(t).has_value(); },
                               "angular, mirror-ball, equirect or cube-cross"));
  command->add_option("--bands", options->bands, "SH bands")->check(CLI::Range(1, kMaxShBands));
  command->add_option("--normal", options->normals, "print the irradiance at this world normal; repeatable")
      ->type_name("X,Y,Z")
      ->allow_extra_args(false)
      ->check(cli::accepted_by([](const std::string& t) { return parse_direction(t).has_value(); },
                               "X,Y,Z (not all zero)"));
  command->add_option("--yaw", options->yaw_deg, "the probe's turn about +z")->type_name("DEG");
  command->add_option("--scale", options->scale, "radiance scale")->type_name("S")->check(CLI::PositiveNumber);
  command->add_option("--window", options->window_name, "ringing window: none, hanning or lanczos")
      ->check(cli::accepted_by([](const std::string& t) { return parse_sh_window(t).has_value(); },
                               "none, hanning or lanczos"));
  command->add_option("--method", options->method,
                      "texels (every texel times its exact solid angle) or stratified (seed 002's N x N jittered "
                      "sphere samples, --samples N per axis)")
      ->check(CLI::IsMember({"texels", "stratified"}));
  command->add_option("--samples", options->samples, "sphere samples per axis for --method stratified")
      ->check(CLI::Range(1, 400));
  command->add_option("--reconstruct", options->reconstruct_path, "write the band-limited probe")
      ->type_name("OUT.hdr|.exr|.png")
      ->check(cli::accepted_by(is_image_file, "a file ending in .hdr, .exr or .png"));
  cli::on_run(command, [options] { return run_sh(*options); },
              cli::Failure{.status = 1, .message = cli::Failure::Message::after_command_name});
}

}  // namespace arpipe
