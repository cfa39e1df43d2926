// A 360° video written through libavformat and libavcodec (libx264), with spherical metadata.
#include "capture/panorama/panorama_video_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <libavutil/spherical.h>
#include <libavutil/stereo3d.h>
#include <libswscale/swscale.h>
}

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "capture/panorama/ffmpeg_error.h"
#include "core/log.h"

namespace arpipe {

struct PanoramaVideoWriter::Impl {
  std::filesystem::path file;
  int width = 0, height = 0;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  SwsContext* scaler = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  int64_t next_pts = 0;
  bool finished = false;

  ~Impl() {
    sws_freeContext(scaler);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    if (format) {
      if (format->pb) avio_closep(&format->pb);
      avformat_free_context(format);
    }
  }

  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error(fmt::format("video \"{}\": {}", file.string(), why));
  }

  // Sends `input` (nullptr: the end) and writes every packet the encoder gives back.
  void encode(const AVFrame* input) {
    int error = avcodec_send_frame(codec, input);
    if (error < 0) fail(fmt::format("encoding: {}", ffmpeg_error(error)));
    while ((error = avcodec_receive_packet(codec, packet)) == 0) {
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      if ((error = av_interleaved_write_frame(format, packet)) < 0) fail(fmt::format("writing: {}", ffmpeg_error(error)));
    }
    if (error != AVERROR(EAGAIN) && error != AVERROR_EOF) fail(fmt::format("encoding: {}", ffmpeg_error(error)));
  }
};

PanoramaVideoWriter::PanoramaVideoWriter(const std::filesystem::path& file, int width, int height, double fps,
                                         PanoramaLayout layout, int crf)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.file = file;
  s.width = width;
  s.height = height;
  if (width <= 0 || height <= 0 || width % 2 != 0 || height % 2 != 0)
    s.fail(fmt::format("{} x {}: H.264 in 4:2:0 needs an even width and height", width, height));
  if (!(fps > 0 && fps <= 1000)) s.fail(fmt::format("{} frames/s is not in (0, 1000]", fps));
  const AVCodec* encoder = avcodec_find_encoder_by_name("libx264");
  if (!encoder) s.fail("FFmpeg's libraries have no libx264 encoder");
  int error = avformat_alloc_output_context2(&s.format, nullptr, "mp4", file.c_str());
  if (error < 0 || !s.format) s.fail(fmt::format("cannot make an MP4: {}", ffmpeg_error(error)));
  s.stream = avformat_new_stream(s.format, nullptr);
  s.codec = avcodec_alloc_context3(encoder);
  s.frame = av_frame_alloc();
  s.packet = av_packet_alloc();
  if (!s.stream || !s.codec || !s.frame || !s.packet) s.fail("out of memory");
  // The frame rate as a fraction to the microsecond (29.97 = 30000/1001 exactly).
  const AVRational rate = av_d2q(fps, 1'000'000);
  s.codec->width = width;
  s.codec->height = height;
  s.codec->pix_fmt = AV_PIX_FMT_YUV420P;
  s.codec->time_base = av_inv_q(rate);
  s.codec->framerate = rate;
  s.codec->gop_size = std::max(1, int(std::lround(fps)));  // a key frame a second: seeking stays quick
  if (s.format->oformat->flags & AVFMT_GLOBALHEADER) s.codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(s.codec->priv_data, "preset", "medium", 0);
  av_opt_set_int(s.codec->priv_data, "crf", crf, 0);
  if ((error = avcodec_open2(s.codec, encoder, nullptr)) < 0) s.fail(fmt::format("cannot open libx264: {}", ffmpeg_error(error)));
  if ((error = avcodec_parameters_from_context(s.stream->codecpar, s.codec)) < 0) s.fail("cannot describe the stream");
  s.stream->time_base = s.codec->time_base;
  s.stream->avg_frame_rate = rate;

  // Spherical Video V2: the whole sphere, equirectangular; the eyes' packing.
  size_t size = 0;
  AVSphericalMapping* mapping = av_spherical_alloc(&size);
  if (!mapping) s.fail("out of memory");
  mapping->projection = AV_SPHERICAL_EQUIRECTANGULAR;
  if (av_stream_add_side_data(s.stream, AV_PKT_DATA_SPHERICAL, reinterpret_cast<uint8_t*>(mapping), size) < 0) {
    av_free(mapping);
    s.fail("cannot attach its spherical metadata");
  }
  AVStereo3D* stereo = av_stereo3d_alloc();
  if (!stereo) s.fail("out of memory");
  stereo->type = layout == PanoramaLayout::EquirectTopBottom   ? AV_STEREO3D_TOPBOTTOM
                 : layout == PanoramaLayout::EquirectLeftRight ? AV_STEREO3D_SIDEBYSIDE
                                                               : AV_STEREO3D_2D;
  if (av_stream_add_side_data(s.stream, AV_PKT_DATA_STEREO3D, reinterpret_cast<uint8_t*>(stereo), sizeof(AVStereo3D)) < 0) {
    av_free(stereo);
    s.fail("cannot attach its stereo metadata");
  }
  s.format->strict_std_compliance = FF_COMPLIANCE_UNOFFICIAL;  // the MP4 muxer writes sv3d and st3d only so
  if ((error = avio_open(&s.format->pb, file.c_str(), AVIO_FLAG_WRITE)) < 0) s.fail(fmt::format("cannot open it: {}", ffmpeg_error(error)));
  if ((error = avformat_write_header(s.format, nullptr)) < 0) s.fail(fmt::format("cannot write its header: {}", ffmpeg_error(error)));

  s.frame->format = AV_PIX_FMT_YUV420P;
  s.frame->width = width;
  s.frame->height = height;
  if (av_frame_get_buffer(s.frame, 0) < 0) s.fail("out of memory");
  s.scaler = sws_getContext(width, height, AV_PIX_FMT_RGB24, width, height, AV_PIX_FMT_YUV420P, SWS_BICUBIC, nullptr,
                            nullptr, nullptr);
  if (!s.scaler) s.fail("no conversion from RGB to 4:2:0");
}

PanoramaVideoWriter::~PanoramaVideoWriter() {
  if (impl_ && !impl_->finished) {
    try {
      finish();
    } catch (const std::exception& e) {
      log::error("{}", e.what());
    }
  }
}

void PanoramaVideoWriter::write(const uint8_t* rgb, size_t bytes_per_line) {
  Impl& s = *impl_;
  if (s.finished) s.fail("a frame after the end");
  if (av_frame_make_writable(s.frame) < 0) s.fail("out of memory");
  const uint8_t* planes[1] = {rgb};
  const int strides[1] = {int(bytes_per_line)};
  sws_scale(s.scaler, planes, strides, 0, s.height, s.frame->data, s.frame->linesize);
  s.frame->pts = s.next_pts++;
  s.encode(s.frame);
}

void PanoramaVideoWriter::finish() {
  Impl& s = *impl_;
  if (s.finished) return;
  s.finished = true;
  s.encode(nullptr);
  const int error = av_write_trailer(s.format);
  if (error < 0) s.fail(fmt::format("cannot write its index: {}", ffmpeg_error(error)));
}

}  // namespace arpipe
