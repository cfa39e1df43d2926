// Replay of a recording as a frame source: real-time pacing against the steady clock, looping with
// timestamps kept increasing, damaged frames skipped rather than thrown.
#include "capture/replay_source.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <optional>
#include <vector>

#include "capture/pacing_clock.h"
#include "capture/recording/recording_reader.h"
#include "core/log.h"

namespace arpipe {

namespace {
constexpr int64_t kFallbackFrameIntervalNs = 33'333'333;  // 30 fps, when a recording says nothing

// The recording source.path names; its problems say which key led to it.
RecordingReader open_recording(const std::filesystem::path& path) {
  if (path.empty())
    throw ConfigError("source.path is empty: a replay needs the recording directory (set source.path, or "
                      "source.type for a live camera)");
  try {
    return RecordingReader(path);
  } catch (const RecordingError& e) {
    throw RecordingError(fmt::format("{} (source.path)", e.what()));
  }
}

// a + b, or nullopt when int64 nanoseconds cannot hold it.
std::optional<int64_t> checked_add(int64_t a, int64_t b) {
  int64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum)) return std::nullopt;
  return sum;
}
}

struct ReplaySource::Impl {
  SourceConfig config;
  bool paced = true;
  RecordingReader reader;
  std::shared_ptr<const CameraModel> model;
  int64_t loop_period_ns = 0;   // added to timestamps per completed pass
  std::optional<int64_t> frame_interval_ns;
  uint64_t loop_sequences = 0;  // added to sequence numbers per completed pass
  size_t next_index = 0;
  uint64_t passes = 0;
  std::atomic<uint64_t> skipped{0};
  PacingClock clock;
  // A looped recording's frames as the first pass read and checked them (unshifted), while they
  // fit source.loop_cache_mb: later passes copy them as a camera's driver buffer is copied,
  // instead of reading and checksumming the file again. A frame that failed its check has none.
  std::vector<std::optional<Frame>> loop_cache;
  size_t loop_cache_bytes = 0;
  bool loop_cache_full = false;  // over the budget: dropped, and every pass reads the file

  explicit Impl(const SourceConfig& c) : config(c), reader(open_recording(c.path)) {}
  SourceStatus next(Frame& frame);
  void keep_for_later_passes(size_t index, const Frame& frame);
};

void ReplaySource::Impl::keep_for_later_passes(size_t index, const Frame& frame) {
  const size_t budget = size_t(std::max(config.loop_cache_mb, 0)) << 20;
  if (loop_cache_bytes + frame.data.size() > budget) {
    if (config.loop_cache_mb > 0)
      log::info("replay {}: its frames exceed source.loop_cache_mb ({} MiB); every pass reads them from the file",
                config.path.string(), config.loop_cache_mb);
    loop_cache.clear();
    loop_cache.shrink_to_fit();
    loop_cache_full = true;
    return;
  }
  loop_cache.resize(reader.frame_count());
  loop_cache[index] = frame;
  loop_cache_bytes += frame.data.size();
}

ReplaySource::ReplaySource(const SourceConfig& config) : impl_(std::make_unique<Impl>(config)) {
  Impl& s = *impl_;
  s.paced = config.pacing == ReplayPacing::Timestamps;
  const RecordingInfo& info = s.reader.info();
  if (config.camera_model.empty()) {
    s.model = std::make_shared<const CameraModel>(s.reader.camera_model());
  } else {
    auto model = std::make_shared<const CameraModel>(CameraModel::load(config.camera_model));
    if (model->width() != info.width || model->height() != info.height)
      throw CameraModelError(fmt::format(
          "{}: imager size {}x{} differs from the {}x{} frames of the recording {}; it cannot describe this camera",
          config.camera_model.string(), model->width(), model->height(), info.width, info.height,
          config.path.string()));
    s.model = std::move(model);
  }
  const size_t count = s.reader.frame_count();
  // Pacing and looping take differences of recorded times: each must fit int64 ns.
  for (size_t i = 1; i < count; ++i) {
    int64_t difference = 0;
    if (__builtin_sub_overflow(s.reader.metadata(i).exposure_start_ns, s.reader.metadata(0).exposure_start_ns,
                               &difference))
      throw RecordingError(fmt::format("{}: frame {}'s exposure_start_ns {} lies too far from frame 0's {} for 64-bit "
                                       "nanoseconds (source.path)",
                                       config.path.string(), i, s.reader.metadata(i).exposure_start_ns,
                                       s.reader.metadata(0).exposure_start_ns));
  }
  if (count > 0) {
    const FrameMetadata& first = s.reader.metadata(0);
    const FrameMetadata& last = s.reader.metadata(count - 1);
    int64_t interval = last.frame_duration_ns;
    if (interval <= 0 && count > 1) interval = (last.exposure_start_ns - first.exposure_start_ns) / int64_t(count - 1);
    if (interval > 0) s.frame_interval_ns = interval;
    if (interval <= 0) interval = kFallbackFrameIntervalNs;
    // Too long to loop in int64 ns: the first pass past it ends the replay (next()).
    s.loop_period_ns = checked_add(std::max<int64_t>(last.exposure_start_ns - first.exposure_start_ns, 0), interval)
                           .value_or(std::numeric_limits<int64_t>::max());
    s.loop_sequences = last.sequence >= first.sequence ? last.sequence - first.sequence + 1 : count;
    for (const FrameMetadata* meta : {&first, &last})
      if (!checked_add(meta->exposure_start_ns, config.timestamp_offset_ns))
        throw ConfigError(fmt::format("source.timestamp_offset_ns {} added to the exposure start {} ns of {} overflows "
                                      "64-bit nanoseconds",
                                      config.timestamp_offset_ns, meta->exposure_start_ns, config.path.string()));
  }
}

ReplaySource::~ReplaySource() = default;

std::optional<int64_t> ReplaySource::frame_interval_ns() const { return impl_->frame_interval_ns; }

std::string ReplaySource::describe() const {
  const Impl& s = *impl_;
  const RecordingInfo& info = s.reader.info();
  return fmt::format("replay:{} ({} frames, {}x{} {}, pacing {}{})", s.config.path.string(), s.reader.frame_count(),
                     info.width, info.height, pixel_format_name(info.pixel_format),
                     choice_name(kReplayPacingNames, s.config.pacing),
                     s.config.loop ? ", loop" : "");
}

std::shared_ptr<const CameraModel> ReplaySource::camera_model() const { return impl_->model; }

uint64_t ReplaySource::frames_skipped() const { return impl_->skipped; }

void ReplaySource::interrupt() { impl_->clock.interrupt(); }

SourceStatus ReplaySource::Impl::next(Frame& frame) {
  Impl& s = *this;
  const size_t count = s.reader.frame_count();
  if (count == 0) return SourceStatus::EndOfStream;
  if (s.next_index == count) {
    if (!s.config.loop) return SourceStatus::EndOfStream;
    s.next_index = 0;
    ++s.passes;
  }
  const size_t index = s.next_index;
  // Looping adds a period per pass: after enough passes (or with a huge recorded timestamp) the
  // shifted time no longer fits int64 ns, and the replay ends rather than wrap around.
  int64_t pass_shift_ns = 0;
  std::optional<int64_t> shifted, due_ns;
  if (!__builtin_mul_overflow(int64_t(s.passes), s.loop_period_ns, &pass_shift_ns))
    if (const auto start = checked_add(s.reader.metadata(index).exposure_start_ns, pass_shift_ns)) {
      shifted = checked_add(*start, s.config.timestamp_offset_ns);
      int64_t since_first = 0;  // the constructor checked that this difference fits
      __builtin_sub_overflow(s.reader.metadata(index).exposure_start_ns, s.reader.metadata(0).exposure_start_ns,
                             &since_first);
      due_ns = checked_add(since_first, pass_shift_ns);
    }
  if (!shifted || !due_ns) {
    log::error("replay {}: pass {} of the loop would move frame {}'s timestamp past 64-bit nanoseconds; the replay ends",
               s.config.path.string(), s.passes + 1, index);
    return SourceStatus::EndOfStream;
  }

  if (s.paced && !s.clock.wait(*due_ns)) return SourceStatus::Retry;

  s.next_index = index + 1;
  if (s.passes > 0 && index < s.loop_cache.size() && s.loop_cache[index]) {
    frame = *s.loop_cache[index];  // copy assignment keeps frame's (recycled) memory when it holds enough
  } else {
    try {
      s.reader.read(index, frame);
    } catch (const std::exception& e) {
      ++s.skipped;
      log::warn("replay {}: frame {} skipped: {}", s.config.path.string(), index, e.what());
      return SourceStatus::Retry;
    }
    if (s.config.loop && s.passes == 0 && !s.loop_cache_full) keep_for_later_passes(index, frame);
  }
  frame.meta.exposure_start_ns = *shifted;
  frame.meta.timestamp_offset_ns += s.config.timestamp_offset_ns;
  frame.meta.sequence += s.passes * s.loop_sequences;
  return SourceStatus::Frame;
}

SourceStatus ReplaySource::next(Frame& frame) {
  try {
    return impl_->next(frame);
  } catch (const std::exception& e) {  // per-frame code never throws (docs/DESIGN.md "Errors")
    log::error("replay {}: {}", impl_->config.path.string(), e.what());
    return SourceStatus::Retry;
  }
}

}  // namespace arpipe
