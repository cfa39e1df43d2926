#include "capture/libcamera/libcamera_stream.h"

#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <optional>

#include <fmt/format.h>
#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/framebuffer.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/property_ids.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>

#include "capture/libcamera/libcamera_cameras.h"
#include "capture/libcamera/libcamera_controls.h"
#include "capture/libcamera/libcamera_manager.h"
#include "capture/libcamera/libcamera_metadata.h"
#include "capture/libcamera/libcamera_pixel_format.h"
#include "core/log.h"

namespace arpipe {

namespace {

using Kind = CameraError::Kind;

libcamera::StreamRole stream_role(StreamRole role) {
  switch (role) {
    case StreamRole::Video: return libcamera::StreamRole::VideoRecording;
    case StreamRole::Viewfinder: return libcamera::StreamRole::Viewfinder;
    case StreamRole::Still: return libcamera::StreamRole::StillCapture;
    case StreamRole::Raw: return libcamera::StreamRole::Raw;
  }
  return libcamera::StreamRole::VideoRecording;
}

bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string join(const std::vector<std::string>& items, const char* sep) {
  std::string out;
  for (const auto& s : items) {
    if (!out.empty()) out += sep;
    out += s;
  }
  return out;
}

std::string present_ids(const std::vector<std::shared_ptr<libcamera::Camera>>& cameras) {
  if (cameras.empty()) return "no cameras present";
  std::vector<std::string> ids;
  for (size_t i = 0; i < cameras.size(); ++i) ids.push_back(fmt::format("{}: {}", i, cameras[i]->id()));
  return "cameras present: " + join(ids, ", ");
}

// "YUYV 640x480, YUYV 1280x720, NV12 sizes 32x32 to 1920x1080, ..." for refusal messages.
std::string offers(const libcamera::StreamFormats& formats) {
  std::vector<std::string> items;
  for (const auto& m : libcamera_modes(formats))
    items.push_back(m.note.empty() ? fmt::format("{} {}x{}", m.format, m.width, m.height)
                                   : fmt::format("{} {}", m.format, m.note));
  return items.empty() ? "nothing" : join(items, ", ");
}

std::shared_ptr<libcamera::Camera> find_camera(libcamera::CameraManager& manager, const std::string& wanted) {
  auto cameras = manager.cameras();
  if (wanted.empty()) {
    if (cameras.empty()) throw CameraError(Kind::Missing, "libcamera: no camera found (no cameras present)");
    return cameras.front();
  }
  if (all_digits(wanted)) {
    size_t index = std::stoul(wanted);
    if (index >= cameras.size())
      throw CameraError(Kind::Missing,
                        fmt::format("libcamera: no camera with index {} ({})", wanted, present_ids(cameras)));
    return cameras[index];
  }
  if (auto camera = manager.get(wanted)) return camera;
  throw CameraError(Kind::Missing, fmt::format("libcamera: no camera '{}' ({})", wanted, present_ids(cameras)));
}

class LibcameraStream final : public CameraStream {
 public:
  explicit LibcameraStream(const SourceConfig& config) {
    try {
      open(config);
    } catch (...) {
      close();
      throw;
    }
  }
  ~LibcameraStream() override { close(); }

  std::string describe() const override { return description_; }
  const StreamFormat& format() const override { return format_; }
  StreamStatus next(Frame& frame, int64_t timeout_ns, std::string& why) override;
  void interrupt() override {
    std::lock_guard lock(mutex_);
    interrupted_ = true;
    cv_.notify_all();
  }
  StreamCounters counters() const override {
    std::lock_guard lock(mutex_);
    return counters_;
  }

 private:
  struct Mapping {
    void* address = nullptr;
    size_t length = 0;
  };

  void open(const SourceConfig& config);
  void configure(const SourceConfig& config);
  void allocate_and_map(int buffer_count);
  void close();
  // Called from libcamera's thread.
  void on_request_completed(libcamera::Request* request);
  void on_disconnected();
  void copy_image(const libcamera::FrameBuffer& buffer, Frame& frame) const;
  bool requeue(libcamera::Request* request, std::string& why);

  std::string camera_id_;
  std::string description_;
  std::shared_ptr<libcamera::Camera> camera_;
  bool acquired_ = false;
  bool started_ = false;
  bool connected_ = false;
  std::unique_ptr<libcamera::CameraConfiguration> camera_config_;
  libcamera::Stream* stream_ = nullptr;
  unsigned stride_ = 0;
  std::unique_ptr<libcamera::FrameBufferAllocator> allocator_;
  std::vector<std::unique_ptr<libcamera::Request>> requests_;
  std::vector<Mapping> mappings_;
  std::map<const libcamera::FrameBuffer*, std::vector<const uint8_t*>> plane_data_;
  StreamFormat format_;
  LibcameraTiming timing_;

  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<libcamera::Request*> completed_;
  bool gone_ = false;
  bool interrupted_ = false;
  bool stopping_ = false;
  StreamCounters counters_;
  std::optional<uint64_t> last_sequence_;
  unsigned missing_logged_ = kMissingNone;
};

void LibcameraStream::open(const SourceConfig& config) {
  auto& manager = libcamera_manager();
  camera_ = find_camera(manager, config.camera);
  camera_id_ = camera_->id();
  int ret = camera_->acquire();
  if (ret < 0)
    throw CameraError(Kind::Failed, fmt::format("libcamera camera '{}': cannot acquire it: {}", camera_id_,
                                                ret == -EBUSY ? "in use by another process" : std::strerror(-ret)));
  acquired_ = true;
  camera_->disconnected.connect(this, &LibcameraStream::on_disconnected);
  camera_->requestCompleted.connect(this, &LibcameraStream::on_request_completed);
  connected_ = true;

  configure(config);
  allocate_and_map(std::max(config.buffers, 4));

  auto start = build_start_controls(config, camera_->controls());
  if (!start.refused.empty())
    throw CameraError(Kind::Refused, fmt::format("libcamera camera '{}': {}", camera_id_, join(start.refused, "; ")));
  for (const auto& note : start.notes) log::warn("libcamera camera '{}': {}", camera_id_, note);
  timing_ = libcamera_timing(config.timestamp_offset_ns, config.readout_ns, config.exposure_us, config.gain, config.fps);
  timing_.sensor_timestamp = config.timestamp_meaning;

  ret = camera_->start(&start.controls);
  if (ret < 0)
    throw CameraError(Kind::Failed, fmt::format("libcamera camera '{}': start failed: {}", camera_id_, std::strerror(-ret)));
  started_ = true;
  for (auto& request : requests_) {
    ret = camera_->queueRequest(request.get());
    if (ret < 0)
      throw CameraError(Kind::Failed,
                        fmt::format("libcamera camera '{}': queueing a request failed: {}", camera_id_, std::strerror(-ret)));
  }
  std::string model;
  if (auto m = camera_->properties().get(libcamera::properties::Model)) model = " (" + *m + ")";
  description_ = fmt::format("libcamera camera '{}'{} {}x{} {} ({})", camera_id_, model, format_.width, format_.height,
                             format_.camera_format, libcamera_compiled_version());
}

void LibcameraStream::configure(const SourceConfig& config) {
  const std::string_view role_name = choice_name(kStreamRoleNames, config.role);
  // A braced list: libcamera 0.0.x takes a StreamRoles vector, 0.1 and later a Span or an
  // initializer_list; this spelling compiles against both.
  camera_config_ = camera_->generateConfiguration({stream_role(config.role)});
  if (!camera_config_ || camera_config_->size() != 1)
    throw CameraError(Kind::Refused,
                      fmt::format("libcamera camera '{}': no configuration for the {} role", camera_id_, role_name));
  libcamera::StreamConfiguration& sc = camera_config_->at(0);
  const std::string offered = offers(sc.formats());

  std::optional<PixelFormat> wanted_format;
  if (config.pixel_format != CaptureFormat::Auto) {
    wanted_format = frame_format(config.pixel_format);
    if (wanted_format && !libcamera_pixel_format(*wanted_format).isValid()) wanted_format.reset();  // MJPG and the V4L2 reorderings
    if (!wanted_format)
      throw CameraError(Kind::Refused, fmt::format("libcamera camera '{}': pixel format {} is not one arpipe takes "
                                                   "from libcamera (RGB24, YUYV, NV12, GREY, raw Bayer); the camera offers {}",
                                                   camera_id_, choice_name(kCaptureFormatNames, config.pixel_format),
                                                   offered));
    sc.pixelFormat = libcamera_pixel_format(*wanted_format);
  } else if (!pixel_format_from_libcamera(sc.pixelFormat)) {
    auto preferred = preferred_libcamera_format(sc.formats().pixelformats());
    if (!preferred)
      throw CameraError(Kind::Refused, fmt::format("libcamera camera '{}': offers no format arpipe takes (RGB24, "
                                                   "YUYV, NV12, GREY, raw Bayer); it offers {}",
                                                   camera_id_, offered));
    sc.pixelFormat = libcamera_pixel_format(*preferred);
  }
  if (config.width > 0 && config.height > 0)
    sc.size = libcamera::Size(static_cast<unsigned>(config.width), static_cast<unsigned>(config.height));
  sc.bufferCount = static_cast<unsigned>(std::max(config.buffers, 4));
  const libcamera::PixelFormat asked_format = sc.pixelFormat;
  const libcamera::Size asked_size = sc.size;

  auto status = camera_config_->validate();
  if (status == libcamera::CameraConfiguration::Invalid)
    throw CameraError(Kind::Refused, fmt::format("libcamera camera '{}': {} {} is invalid for it; it offers {}",
                                                 camera_id_, asked_format.toString(), asked_size.toString(), offered));
  // validate() may also adjust the buffer count, stride or colour space: only the size and the
  // format are the config's business.
  const bool format_changed = sc.pixelFormat != asked_format && (wanted_format || !pixel_format_from_libcamera(sc.pixelFormat));
  const bool size_changed = config.width > 0 && config.height > 0 && sc.size != asked_size;
  if (format_changed || size_changed)
    throw CameraError(Kind::Refused,
                      fmt::format("libcamera camera '{}': asked for {} {}, it would give {} {}; it offers {}", camera_id_,
                                  asked_format.toString(), asked_size.toString(), sc.pixelFormat.toString(),
                                  sc.size.toString(), offered));
  if (status == libcamera::CameraConfiguration::Adjusted)
    log::info("libcamera camera '{}': configuration adjusted to {}", camera_id_, sc.toString());

  int ret = camera_->configure(camera_config_.get());
  if (ret < 0)
    throw CameraError(Kind::Failed, fmt::format("libcamera camera '{}': configure {} failed: {}", camera_id_,
                                                sc.toString(), std::strerror(-ret)));
  stream_ = sc.stream();
  stride_ = sc.stride;
  auto ours = pixel_format_from_libcamera(sc.pixelFormat);
  if (!ours)  // cannot happen after the checks above, but a wrong frame must never go out
    throw CameraError(Kind::Refused, fmt::format("libcamera camera '{}': configured {} which arpipe does not take",
                                                 camera_id_, sc.pixelFormat.toString()));
  format_.format = *ours;
  format_.camera_format = sc.pixelFormat.toString();
  timing_.raw_bit_depth = is_bayer(*ours) ? bayer_bit_depth(*ours) : 0;
  format_.width = static_cast<int>(sc.size.width);
  format_.height = static_cast<int>(sc.size.height);
  format_.frame_interval_ns = config.fps > 0 ? static_cast<int64_t>(1e9 / config.fps + 0.5) : 0;
  if (auto bad = check_image_size(format_.format, format_.width, format_.height))
    throw CameraError(Kind::Refused, fmt::format("libcamera camera '{}': {}", camera_id_, *bad));
  if (stride_ < min_bytes_per_line(format_.format, format_.width))
    throw CameraError(Kind::Failed, fmt::format("libcamera camera '{}': stride {} is below the {} bytes of a {} row",
                                                camera_id_, stride_, min_bytes_per_line(format_.format, format_.width),
                                                format_.camera_format));
}

void LibcameraStream::allocate_and_map(int buffer_count) {
  allocator_ = std::make_unique<libcamera::FrameBufferAllocator>(camera_);
  int ret = allocator_->allocate(stream_);
  if (ret < 0)
    throw CameraError(Kind::Failed,
                      fmt::format("libcamera camera '{}': allocating buffers failed: {}", camera_id_, std::strerror(-ret)));
  const auto& buffers = allocator_->buffers(stream_);
  if (static_cast<int>(buffers.size()) < buffer_count)
    log::info("libcamera camera '{}': {} buffers allocated ({} asked for)", camera_id_, buffers.size(), buffer_count);

  const size_t image_size = image_bytes(format_.format, format_.width, format_.height, stride_);
  for (const auto& buffer : buffers) {
    // Planes may share one dmabuf at different offsets: map each fd once, over all its planes.
    std::map<int, size_t> extent;
    for (const auto& plane : buffer->planes()) {
      size_t offset = plane.offset == libcamera::FrameBuffer::Plane::kInvalidOffset ? 0 : plane.offset;
      extent[plane.fd.get()] = std::max(extent[plane.fd.get()], offset + plane.length);
    }
    std::map<int, const uint8_t*> base;
    for (const auto& [fd, length] : extent) {
      void* address = mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, 0);
      if (address == MAP_FAILED)
        throw CameraError(Kind::Failed,
                          fmt::format("libcamera camera '{}': mmap of a buffer failed: {}", camera_id_, std::strerror(errno)));
      mappings_.push_back({address, length});
      base[fd] = static_cast<const uint8_t*>(address);
    }
    std::vector<const uint8_t*> planes;
    size_t total = 0;
    for (const auto& plane : buffer->planes()) {
      size_t offset = plane.offset == libcamera::FrameBuffer::Plane::kInvalidOffset ? 0 : plane.offset;
      planes.push_back(base[plane.fd.get()] + offset);
      total += plane.length;
    }
    if (total < image_size)
      throw CameraError(Kind::Failed, fmt::format("libcamera camera '{}': buffer of {} bytes for a {}-byte image",
                                                  camera_id_, total, image_size));
    plane_data_[buffer.get()] = std::move(planes);

    auto request = camera_->createRequest();
    if (!request) throw CameraError(Kind::Failed, fmt::format("libcamera camera '{}': cannot create a request", camera_id_));
    ret = request->addBuffer(stream_, buffer.get());
    if (ret < 0)
      throw CameraError(Kind::Failed, fmt::format("libcamera camera '{}': cannot add a buffer to a request: {}",
                                                  camera_id_, std::strerror(-ret)));
    requests_.push_back(std::move(request));
  }
}

void LibcameraStream::close() {
  if (camera_ && started_) {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    camera_->stop();  // completes every pending request as cancelled before it returns
    started_ = false;
  }
  if (camera_ && connected_) {
    camera_->requestCompleted.disconnect(this);
    camera_->disconnected.disconnect(this);
    connected_ = false;
  }
  {
    std::lock_guard lock(mutex_);
    completed_.clear();
  }
  requests_.clear();
  for (const auto& m : mappings_) munmap(m.address, m.length);
  mappings_.clear();
  plane_data_.clear();
  if (allocator_ && stream_) allocator_->free(stream_);
  allocator_.reset();
  camera_config_.reset();
  if (camera_ && acquired_) camera_->release();
  acquired_ = false;
  camera_.reset();
}

void LibcameraStream::on_request_completed(libcamera::Request* request) {
  std::lock_guard lock(mutex_);
  if (stopping_ || request->status() == libcamera::Request::RequestCancelled) return;
  completed_.push_back(request);
  cv_.notify_all();
}

void LibcameraStream::on_disconnected() {
  std::lock_guard lock(mutex_);
  gone_ = true;
  cv_.notify_all();
}

bool LibcameraStream::requeue(libcamera::Request* request, std::string& why) {
  request->reuse(libcamera::Request::ReuseBuffers);
  int ret = camera_->queueRequest(request);
  if (ret < 0) {
    why = fmt::format("libcamera camera '{}': requeueing a request failed: {}", camera_id_, std::strerror(-ret));
    return false;
  }
  return true;
}

void LibcameraStream::copy_image(const libcamera::FrameBuffer& buffer, Frame& frame) const {
  frame.reshape(format_.format, format_.width, format_.height);  // a recycled frame's memory is reused
  const size_t row = frame.bytes_per_line;
  const auto& planes = plane_data_.at(&buffer);
  const uint8_t* src = planes[0];
  uint8_t* dst = frame.data.data();
  for (int y = 0; y < format_.height; ++y) std::memcpy(dst + y * row, src + y * size_t{stride_}, row);
  if (format_.format == PixelFormat::NV12) {
    // The UV plane is the buffer's second plane, or follows the Y plane in a single-plane buffer.
    const uint8_t* uv = planes.size() > 1 ? planes[1] : src + size_t{stride_} * format_.height;
    uint8_t* dst_uv = dst + row * format_.height;
    for (int y = 0; y < format_.height / 2; ++y) std::memcpy(dst_uv + y * row, uv + y * size_t{stride_}, row);
  }
}

StreamStatus LibcameraStream::next(Frame& frame, int64_t timeout_ns, std::string& why) {
  libcamera::Request* request = nullptr;
  {
    std::unique_lock lock(mutex_);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::nanoseconds(std::max<int64_t>(timeout_ns, 0));
    cv_.wait_until(lock, deadline, [&] { return gone_ || interrupted_ || !completed_.empty(); });
    if (gone_) {
      why = fmt::format("libcamera camera '{}' disconnected", camera_id_);
      return StreamStatus::Gone;
    }
    if (interrupted_) {
      interrupted_ = false;
      why = "interrupted";
      return StreamStatus::Interrupted;
    }
    if (completed_.empty()) {
      ++counters_.timeouts;
      why = fmt::format("libcamera camera '{}': no frame within {} ms", camera_id_, timeout_ns / 1'000'000);
      return StreamStatus::Timeout;
    }
    request = completed_.front();
    completed_.pop_front();
  }

  const libcamera::FrameBuffer* buffer = request->findBuffer(stream_);
  if (!buffer) {
    why = fmt::format("libcamera camera '{}': a completed request without the stream's buffer", camera_id_);
    return requeue(request, why) ? StreamStatus::Again : StreamStatus::Gone;
  }
  const libcamera::FrameMetadata& fm = buffer->metadata();
  if (fm.status != libcamera::FrameMetadata::FrameSuccess) {
    {
      std::lock_guard lock(mutex_);
      ++counters_.error_buffers;
    }
    why = fmt::format("libcamera camera '{}': buffer {} came back with status {}", camera_id_, fm.sequence,
                      fm.status == libcamera::FrameMetadata::FrameError ? "error" : "cancelled");
    std::string requeue_why;
    if (!requeue(request, requeue_why)) {
      why = requeue_why;
      return StreamStatus::Gone;
    }
    return StreamStatus::Again;
  }

  auto mapped = map_libcamera_metadata(read_request_values(request->metadata()), fm.sequence,
                                       static_cast<int64_t>(fm.timestamp), timing_);
  copy_image(*buffer, frame);
  frame.meta = mapped.meta;
  if (unsigned fresh = mapped.missing & ~missing_logged_) {
    missing_logged_ |= fresh;
    log::info("libcamera camera '{}' does not report {}; using the documented defaults", camera_id_,
              libcamera_missing_names(fresh));
  }
  {
    std::lock_guard lock(mutex_);
    ++counters_.frames;
    if (last_sequence_ && fm.sequence > *last_sequence_ + 1) counters_.sequence_gaps += fm.sequence - *last_sequence_ - 1;
    last_sequence_ = fm.sequence;
  }
  if (!requeue(request, why)) return StreamStatus::Gone;  // the frame is lost, and the camera with it
  return StreamStatus::Frame;
}

}  // namespace

std::unique_ptr<CameraStream> open_libcamera_stream(const SourceConfig& config) {
  return std::make_unique<LibcameraStream>(config);
}

}  // namespace arpipe
