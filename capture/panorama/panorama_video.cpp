#include "capture/panorama/panorama_video.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/spherical.h>
#include <libavutil/stereo3d.h>
#include <libswscale/swscale.h>
}

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <string>
#include <utility>

#include "capture/panorama/equirect_image.h"
#include "capture/panorama/ffmpeg_error.h"
#include "core/log.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

constexpr const char* kDemuxers = "mov,mp4,m4a,3gp,3g2,mj2,matroska,webm";
constexpr const char* kDecoders = "h264,hevc,vp8,vp9,av1,libdav1d,libaom-av1";

}  // namespace

struct PanoramaVideo::Impl {
  std::filesystem::path file;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  SwsContext* scaler = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  int stream = -1;
  int width = 0, height = 0;  // the stream's, checked at open: a frame of another size is skipped
  PanoramaLayout layout = PanoramaLayout::Equirect;
  AVRational time_base{0, 1};
  AVRational rate{0, 1};
  int64_t start_pts = 0;
  bool draining = false;   // the demuxer ended: the decoder is being flushed
  bool ended = false;
  int64_t skip_before = -1;  // after a seek: frames before this index are decoded but not given
  uint64_t decode_errors = 0;

  ~Impl() {
    sws_freeContext(scaler);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    avformat_close_input(&format);
  }

  [[noreturn]] void fail(const std::string& why) const {
    throw AssetError(fmt::format("panorama video \"{}\": {}", file.string(), why));
  }

  // The file's own word on what it holds, where it says (Google's Spherical Video V2 boxes in MP4,
  // sv3d and st3d; Matroska's Projection and StereoMode), before its shape is checked, so that a
  // cubemap, a cropped or a stereo 360 video is refused for what it is: only the whole mono
  // equirectangular layout is built.
  // Returns the layout the metadata says, when it says one.
  std::optional<PanoramaLayout> check_spherical_metadata(const AVStream* stream, PanoramaLayout layout) const {
    size_t size = 0;
    if (const uint8_t* data = av_stream_get_side_data(stream, AV_PKT_DATA_SPHERICAL, &size);
        data && size >= sizeof(AVSphericalMapping)) {
      const auto* mapping = reinterpret_cast<const AVSphericalMapping*>(data);
      const bool cropped = mapping->bound_left || mapping->bound_top || mapping->bound_right || mapping->bound_bottom;
      if (mapping->projection != AV_SPHERICAL_EQUIRECTANGULAR && !(mapping->projection == AV_SPHERICAL_EQUIRECTANGULAR_TILE && cropped))
        fail(fmt::format("its spherical metadata says the {} projection; only equirectangular panoramas are supported",
                         av_spherical_projection_name(mapping->projection)));
      if (cropped)  // the tiled form: an equirectangular image of part of the sphere
        fail(fmt::format("its spherical metadata crops the sphere (bounds left {}, top {}, right {}, bottom {} of 2^32); "
                         "only whole panoramas are supported",
                         mapping->bound_left, mapping->bound_top, mapping->bound_right, mapping->bound_bottom));
      if (mapping->yaw || mapping->pitch || mapping->roll)
        log::warn("panorama video \"{}\": its spherical metadata's pose (yaw {:.2f}, pitch {:.2f}, roll {:.2f} degrees) is "
                  "not applied: turn it with source.panorama.yaw_deg",
                  file.string(), mapping->yaw / 65536.0, mapping->pitch / 65536.0, mapping->roll / 65536.0);
    }
    if (const uint8_t* data = av_stream_get_side_data(stream, AV_PKT_DATA_STEREO3D, &size);
        data && size >= sizeof(AVStereo3D)) {
      const auto* stereo = reinterpret_cast<const AVStereo3D*>(data);
      const auto [said, name] = [&]() -> std::pair<std::optional<PanoramaLayout>, std::string_view> {
        switch (stereo->type) {
          case AV_STEREO3D_2D: return {PanoramaLayout::Equirect, "equirect"};
          case AV_STEREO3D_TOPBOTTOM: return {PanoramaLayout::EquirectTopBottom, "equirect-tb"};
          case AV_STEREO3D_SIDEBYSIDE: return {PanoramaLayout::EquirectLeftRight, "equirect-lr"};
          default: return {std::nullopt, ""};
        }
      }();
      if (!said)
        fail(fmt::format("its metadata says it is stereo as {}; only top/bottom and side-by-side pairs are supported",
                         av_stereo3d_type_name(stereo->type)));
      if ((stereo->flags & AV_STEREO3D_FLAG_INVERT) != 0)
        fail("its metadata says its right eye comes first; only the left eye first (on top, or on the left) is supported");
      if (layout != PanoramaLayout::Auto && *said != layout)
        fail(fmt::format("its metadata says the layout is \"{}\" but source.panorama.layout is \"{}\"", name,
                         choice_name(kPanoramaLayoutNames, layout)));
      return said;
    }
    return std::nullopt;
  }

  // The board's V4L2 memory-to-memory decoder for the codec (h264_v4l2m2m, hevc_v4l2m2m,
  // vp8_v4l2m2m, vp9_v4l2m2m: the Raspberry Pi's, Rockchip's, i.MX's), when FFmpeg has one and it
  // opens (a device that decodes the codec exists); codec stays null otherwise.
  void open_hardware_decoder(const AVCodecParameters* parameters) {
    const std::string name = fmt::format("{}_v4l2m2m", avcodec_get_name(parameters->codec_id));
    const AVCodec* hardware = avcodec_find_decoder_by_name(name.c_str());
    if (!hardware) {
      log::debug("panorama video \"{}\": no {} decoder in FFmpeg: software decoding", file.string(), name);
      return;
    }
    AVCodecContext* context = avcodec_alloc_context3(hardware);
    int error = context ? avcodec_parameters_to_context(context, parameters) : AVERROR(ENOMEM);
    if (error >= 0) error = avcodec_open2(context, hardware, nullptr);
    if (error < 0) {
      avcodec_free_context(&context);
      log::info("panorama video \"{}\": no hardware decoder ({}: {}): software decoding", file.string(), name,
                ffmpeg_error(error));
      return;
    }
    log::info("panorama video \"{}\": decoded by {}", file.string(), name);
    codec = context;
  }

  int64_t index_of(int64_t pts) const {
    // (pts - start) x time_base x rate, rounded to the nearest frame.
    return av_rescale_q_rnd(pts - start_pts, time_base, av_inv_q(rate),
                            static_cast<AVRounding>(AV_ROUND_NEAR_INF | AV_ROUND_PASS_MINMAX));
  }

  // Fills `out` from the decoded `frame`.
  void convert(PanoramaVideoFrame& out, int64_t pts) {
    const int w = frame->width, h = frame->height;
    scaler = sws_getCachedContext(scaler, w, h, static_cast<AVPixelFormat>(frame->format), w, h, AV_PIX_FMT_RGB24,
                                  SWS_POINT, nullptr, nullptr, nullptr);
    if (!scaler) fail("no conversion from its pixel format to RGB");
    out.width = w;
    out.height = h;
    out.rgb.resize(size_t(w) * size_t(h) * 3);
    uint8_t* planes[1] = {out.rgb.data()};
    const int strides[1] = {w * 3};
    sws_scale(scaler, frame->data, frame->linesize, 0, h, planes, strides);
    out.index = index_of(pts);
    out.time_ns = av_rescale_q(pts - start_pts, time_base, AVRational{1, 1'000'000'000});
  }
};

PanoramaVideo::PanoramaVideo(const std::filesystem::path& file, PanoramaLayout layout, bool hardware)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.file = file;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) s.fail("no such file (or not a regular file)");
  AVDictionary* options = nullptr;
  av_dict_set(&options, "protocol_whitelist", "file", 0);
  s.format = avformat_alloc_context();
  if (!s.format) s.fail("out of memory");
  s.format->format_whitelist = av_strdup(kDemuxers);
  s.format->codec_whitelist = av_strdup(kDecoders);
  int error = avformat_open_input(&s.format, file.c_str(), nullptr, &options);
  av_dict_free(&options);
  if (error < 0) {
    s.format = nullptr;  // freed by avformat_open_input
    s.fail(fmt::format("cannot open it as MP4, MOV, MKV or WebM: {}", ffmpeg_error(error)));
  }
  if ((error = avformat_find_stream_info(s.format, nullptr)) < 0) s.fail(fmt::format("no stream information: {}", ffmpeg_error(error)));
  const AVCodec* decoder = nullptr;
  s.stream = av_find_best_stream(s.format, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (s.stream < 0 || !decoder) s.fail("no video stream that H.264, HEVC, VP8, VP9 or AV1 decoding reads");
  AVStream* stream = s.format->streams[s.stream];
  const std::optional<PanoramaLayout> said = s.check_spherical_metadata(stream, layout);
  const AVCodecParameters* parameters = stream->codecpar;
  const int width = parameters->width, height = parameters->height;
  if (layout == PanoramaLayout::Auto) layout = said ? *said : layout_of_shape(width, height);
  s.layout = layout;
  if (const std::string why = EquirectImage::shape_problem(layout, width, height); !why.empty())
    s.fail(fmt::format("not a panorama: {}", why));
  s.width = width;
  s.height = height;
  if (hardware) s.open_hardware_decoder(parameters);
  if (!s.codec) {  // software
    s.codec = avcodec_alloc_context3(decoder);
    if (!s.codec || avcodec_parameters_to_context(s.codec, parameters) < 0) s.fail("cannot set up its decoder");
    s.codec->thread_count = 0;  // FFmpeg's choice: one per core
    if ((error = avcodec_open2(s.codec, decoder, nullptr)) < 0)
      s.fail(fmt::format("cannot open its {} decoder: {}", decoder->name, ffmpeg_error(error)));
  }
  s.time_base = stream->time_base;
  s.rate = stream->avg_frame_rate.num > 0 && stream->avg_frame_rate.den > 0 ? stream->avg_frame_rate : stream->r_frame_rate;
  if (s.rate.num <= 0 || s.rate.den <= 0 || s.time_base.num <= 0 || s.time_base.den <= 0) s.fail("no frame rate or time base");
  s.start_pts = stream->start_time != AV_NOPTS_VALUE ? stream->start_time : 0;
  s.packet = av_packet_alloc();
  s.frame = av_frame_alloc();
  if (!s.packet || !s.frame) s.fail("out of memory");
}

PanoramaVideo::~PanoramaVideo() = default;

PanoramaLayout PanoramaVideo::layout() const { return impl_->layout; }
int PanoramaVideo::width() const { return impl_->width; }
int PanoramaVideo::height() const { return impl_->height; }
int64_t PanoramaVideo::rate_num() const { return impl_->rate.num; }
int64_t PanoramaVideo::rate_den() const { return impl_->rate.den; }
uint64_t PanoramaVideo::decode_errors() const { return impl_->decode_errors; }

std::string PanoramaVideo::describe() const {
  return fmt::format("{} {} x {} at {}/{} frames/s", impl_->codec->codec->name, width(), height(), impl_->rate.num, impl_->rate.den);
}

bool PanoramaVideo::next(PanoramaVideoFrame& out) {
  Impl& s = *impl_;
  while (!s.ended) {
    const int received = avcodec_receive_frame(s.codec, s.frame);
    if (received == 0) {
      const int64_t pts = s.frame->best_effort_timestamp;
      if (pts == AV_NOPTS_VALUE) {  // a frame with no time cannot have an index
        ++s.decode_errors;
        continue;
      }
      if (s.frame->width != s.width || s.frame->height != s.height) {  // the stream changed size: not the panorama checked
        ++s.decode_errors;
        av_frame_unref(s.frame);
        continue;
      }
      if (s.skip_before >= 0 && s.index_of(pts) < s.skip_before) continue;
      s.skip_before = -1;
      s.convert(out, pts);
      av_frame_unref(s.frame);
      return true;
    }
    if (received == AVERROR_EOF) {
      s.ended = true;
      break;
    }
    if (received != AVERROR(EAGAIN)) {
      ++s.decode_errors;
      log::debug("panorama video {}: {}", s.file.string(), ffmpeg_error(received));
    }
    if (s.draining) {
      if (received == AVERROR(EAGAIN)) s.ended = true;
      continue;
    }
    // Feed the decoder the next packet of the stream, or the flush at the end.
    const int read = av_read_frame(s.format, s.packet);
    if (read < 0) {
      s.draining = true;
      avcodec_send_packet(s.codec, nullptr);
      continue;
    }
    if (s.packet->stream_index == s.stream && avcodec_send_packet(s.codec, s.packet) < 0) ++s.decode_errors;
    av_packet_unref(s.packet);
  }
  return false;
}

void PanoramaVideo::seek(int64_t index) {
  Impl& s = *impl_;
  const int64_t target = s.start_pts + av_rescale_q(std::max<int64_t>(index, 0), av_inv_q(s.rate), s.time_base);
  const int error = av_seek_frame(s.format, s.stream, target, AVSEEK_FLAG_BACKWARD);
  if (error < 0) s.fail(fmt::format("cannot seek to frame {}: {}", index, ffmpeg_error(error)));
  avcodec_flush_buffers(s.codec);
  s.draining = s.ended = false;
  s.skip_before = std::max<int64_t>(index, 0);
}

}  // namespace arpipe
