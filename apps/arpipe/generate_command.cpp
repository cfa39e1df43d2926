// arpipe generate: a capture of a camera moving over an AprilTag, with exact ground truth.
#include <fmt/format.h>

#include <charconv>
#include <cstdio>
#include <exception>

#include "apps/arpipe/commands.h"
#include "capture/sim/tag_capture_generator.h"
#include "core/log.h"

namespace arpipe {

namespace {
constexpr const char* kUsage =
    "usage: arpipe generate --out DIR [--frames N] [--format GREY|RGB24|YUYV|NV12] [--seed S]\n";

template <typename T>
bool parse_number(const std::string& text, T& out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size();
}
}  // namespace

int run_generate(const Args& args) {
  TagCaptureOptions options;
  std::string out;
  for (size_t i = 0; i < args.size(); ++i) {
    if (i + 1 >= args.size()) {
      std::fputs(kUsage, stderr);
      return 2;
    }
    const std::string& key = args[i];
    const std::string& value = args[++i];
    bool ok = true;
    if (key == "--out") out = value;
    else if (key == "--frames") ok = parse_number(value, options.frames) && options.frames > 0;
    else if (key == "--seed") ok = parse_number(value, options.seed);
    else if (key == "--format") {
      const auto format = pixel_format_from_name(value);
      ok = format.has_value();
      if (ok) options.pixel_format = *format;
    } else {
      fmt::print(stderr, "arpipe generate: unknown option {}\n{}", key, kUsage);
      return 2;
    }
    if (!ok) {
      fmt::print(stderr, "arpipe generate: bad value '{}' for {}\n{}", value, key, kUsage);
      return 2;
    }
  }
  if (out.empty()) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  try {
    const int written = generate_tag_capture(out, options);
    log::info("wrote {} frames to {}", written, out);
    return 0;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 2;
  }
}

}  // namespace arpipe
