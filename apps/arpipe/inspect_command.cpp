// arpipe inspect: what a recording holds, and whether its timing is sound.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "capture/recording/recording_reader.h"
#include "core/log.h"

namespace arpipe {

namespace {

int inspect(const std::string& dir) {
  RecordingReader reader(dir);
  for (const auto& w : reader.warnings()) log::warn("{}", w);
  const auto& info = reader.info();
  const auto& model = reader.camera_model();
  fmt::print("recording    {}\n", dir);
  fmt::print("format       v{}, {} {}x{}, {} bytes per line\n", info.version, pixel_format_name(info.pixel_format),
             info.width, info.height, info.bytes_per_line);
  fmt::print("source       {}\n", info.source);
  fmt::print("created      {}\n", info.created_utc);
  fmt::print("camera       {} fx {:.3f} fy {:.3f} cx {:.3f} cy {:.3f}\n", model.lensmodel(), model.fx(), model.fy(),
             model.cx(), model.cy());
  const size_t n = reader.frame_count();
  fmt::print("frames       {}\n", n);
  fmt::print("ground truth {}\n", reader.ground_truth().empty() ? "no" : "yes");
  if (n == 0) return 0;

  uint64_t gaps = 0;
  int64_t min_dt = INT64_MAX, max_dt = 0, backwards = 0;
  for (size_t i = 1; i < n; ++i) {
    const auto& a = reader.metadata(i - 1);
    const auto& b = reader.metadata(i);
    if (b.sequence > a.sequence + 1) gaps += b.sequence - a.sequence - 1;
    const int64_t dt = b.exposure_start_ns - a.exposure_start_ns;
    if (dt <= 0) ++backwards;
    min_dt = std::min(min_dt, dt);
    max_dt = std::max(max_dt, dt);
  }
  const auto& first = reader.metadata(0);
  const auto& last = reader.metadata(n - 1);
  const double duration_s = double(last.exposure_start_ns - first.exposure_start_ns) * 1e-9;
  fmt::print("sequence     {} .. {}, {} dropped (sequence gaps)\n", first.sequence, last.sequence, gaps);
  fmt::print("duration     {:.3f} s", duration_s);
  if (n > 1) fmt::print(", {:.2f} frames/s, interval {:.3f} .. {:.3f} ms", double(n - 1) / duration_s, min_dt * 1e-6,
                        max_dt * 1e-6);
  fmt::print("\n");
  fmt::print("exposure     {:.3f} ms (first frame), readout {:.3f} ms, gain {:.2f} x {:.2f}\n",
             first.exposure_ns * 1e-6, first.readout_ns * 1e-6, first.analogue_gain, first.digital_gain);
  fmt::print("timestamps   {} (offset {} ns)\n", timestamp_meaning_name(first.raw_timestamp_meaning),
             first.timestamp_offset_ns);
  if (backwards) {
    log::warn("{}: {} frame(s) do not advance in time", dir, backwards);
    return 1;
  }
  return 0;
}

}  // namespace

void add_inspect_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand("inspect", "summary of a recording: frames, format, timing, drops");
  auto dir = std::make_shared<std::string>();
  command->add_option("DIR", *dir, "the recording")->required();
  cli::on_run(command, [dir] { return inspect(*dir); }, cli::Failure{.status = 2});
}

}  // namespace arpipe
