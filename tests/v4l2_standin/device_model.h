// One served V4L2 capture device: its state machine (format, buffer queue, streaming, controls,
// events, faults) and the lazy frame schedule that advances whenever the host calls in.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "control_table.h"
#include "fault_plan.h"
#include "frame_source.h"
#include "served_node.h"
#include "standin_config.h"

namespace arpipe::standin {

class Device final : public Node {
 public:
  // Opens the recording; throws StandinConfigError.
  explicit Device(DeviceConfig config);
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  const std::string& path() const override { return config_.path; }
  // Everything below runs with the registry's lock held.
  // False while unplugged (until the replug time has passed).
  bool present(int64_t now) override;
  void attach(OpenFile& file) override;
  void detach(OpenFile& file) override;
  bool open() const override { return open_count_ > 0; }
  // Unload: every open file goes dead (ENODEV) and streaming stops.
  void disconnect_all() override;

  // Lets every frame that is due by `now` fall due (faults, controls, events, buffers).
  void advance(int64_t now) override;
  // When advance() may next have something to do; kNever: only when the host acts.
  int64_t next_wake(int64_t now) const override;

  // A V4L2 ioctl: 0 or an errno.
  int ioctl(OpenFile& file, unsigned long request, void* arg, const Waiter& wait) override;
  short poll_events(const OpenFile& file, short requested) const override;
  // mmap of a buffer: the mapping, or MAP_FAILED with errno set.
  void* mmap(void* addr, size_t length, int prot, int flags, int64_t offset) override;

 private:
  struct Buffer {
    bool queued = false, done = false, mapped = false, error = false;
    uint32_t bytes_used = 0, sequence = 0;
    int64_t timestamp_ns = 0;
  };

  int querycap(v4l2_capability& cap) const;
  int enum_fmt(v4l2_fmtdesc& desc) const;
  int enum_framesizes(v4l2_frmsizeenum& e) const;
  int enum_frameintervals(v4l2_frmivalenum& e) const;
  void fill_format(size_t index, v4l2_format& f) const;
  size_t adjust_format(const v4l2_format& f) const;
  int parm(v4l2_streamparm& p) const;
  int reqbufs(OpenFile& file, v4l2_requestbuffers& r);
  void fill_buffer(uint32_t index, v4l2_buffer& b) const;
  int qbuf(OpenFile& file, v4l2_buffer& b);
  int dqbuf(OpenFile& file, v4l2_buffer& b, const Waiter& wait);
  int streamon(OpenFile& file, int64_t now);
  void stop_streaming();
  int ext_ctrls(OpenFile& file, unsigned long request, v4l2_ext_controls& c);
  int subscribe(OpenFile& file, const v4l2_event_subscription& s);
  int dqevent(OpenFile& file, v4l2_event& e, const Waiter& wait);
  void queue_control_events(const std::vector<ControlChange>& changes, const OpenFile* setter, int64_t at);

  bool busy(const OpenFile& file) const { return owner_ != nullptr && owner_ != &file; }
  bool has_frame(uint64_t g) const { return config_.loop || g < source_.frame_count(); }
  int64_t recorded_offset(uint64_t g) const;  // exposure end of g minus that of frame 0, loops included
  int64_t due(uint64_t g) const { return anchor_ns_ + shift_ns_ + recorded_offset(g); }
  int64_t timestamp(uint64_t g) const;
  void deliver(uint64_t g, int64_t at);
  void unplug(int64_t at, int64_t replug_after_ns);
  void free_buffers();

  bool mplane() const { return config_.buffer_type == BufferType::Mplane; }
  uint32_t plane_bytes_used(const Buffer& b, uint32_t plane) const;

  DeviceConfig config_;
  uint32_t type_;  // V4L2_BUF_TYPE_VIDEO_CAPTURE or _MPLANE, from buffer_type
  FrameSource source_;
  ControlTable controls_;
  FaultPlan faults_;
  std::vector<OpenFile*> files_;  // live ones
  int open_count_ = 0;            // live and dead
  size_t format_ = 0;

  OpenFile* owner_ = nullptr;  // the file handle that allocated the buffers (vb2's queue owner)
  int memfd_ = -1;
  uint8_t* memory_ = nullptr;
  size_t buffer_stride_ = 0;  // page-aligned spacing of the buffers in the memfd (their mmap offsets)
  uint32_t buffer_length_ = 0;  // single-planar: the buffer's length
  // The planes of each buffer (one unless the format is split, multi-planar only): their lengths and
  // page-aligned offsets within the buffer, so each plane is mapped by its own offset.
  uint32_t num_planes_ = 1;
  uint32_t plane_length_[kMaxPlanes] = {};
  size_t plane_offset_[kMaxPlanes] = {};
  std::vector<uint8_t> scratch_;  // a split frame is rendered whole, then cut into its planes
  std::vector<Buffer> buffers_;
  std::deque<uint32_t> queued_, done_;
  bool streaming_ = false;

  // The schedule: frame g (counting loops) falls due at anchor + shift + recorded_offset(g).
  int64_t anchor_ns_ = 0;
  int64_t shift_ns_ = 0;         // stalls so far
  int64_t fast_hold_until_ = 0;  // fast pacing: a stall holds frames back until then
  uint64_t next_ = 0;
  uint32_t sequence_ = 0;
  bool resume_ = false;  // unplugged while streaming: the next STREAMON continues the schedule
  uint64_t error_frame_ = UINT64_MAX;  // error_buffer fault: this frame's buffer gets V4L2_BUF_FLAG_ERROR
  uint32_t spurious_ = 0;        // eagain fault: wake-ups left
  bool eio_ = false;             // eio fault: the next DQBUF fails
  bool unplugged_ = false;
  int64_t replug_at_ = kNever;
};

}  // namespace arpipe::standin
