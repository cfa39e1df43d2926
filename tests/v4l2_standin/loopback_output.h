// A loopback's output node (VIDEO_OUTPUT, MMAP streaming): what the host writes is handed to the
// spool as soon as a buffer is queued while streaming, so its capture node, here or in another
// process, serves it. Optional stalls hold the buffers back, as a device whose reader stopped.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <vector>

#include "loopback_spool.h"
#include "loopback_node.h"
#include "standin_config.h"

namespace arpipe::standin {

class LoopbackOutput final : public LoopbackNode {
 public:
  explicit LoopbackOutput(const LoopbackConfig& config);

  const std::string& path() const override { return config_.output; }
  void advance(int64_t now) override;
  int64_t next_wake(int64_t now) const override;
  int ioctl(OpenFile& file, unsigned long request, void* arg, const Waiter& wait) override;

 private:
  PixelFormat offered(size_t index) const;
  SpoolFormat adjust(const v4l2_format& f) const;
  void fill_format(const SpoolFormat& s, v4l2_format& f) const;
  int enum_framesizes(v4l2_frmsizeenum& e) const;
  int parm(v4l2_streamparm& p, bool set);
  int reqbufs(OpenFile& file, v4l2_requestbuffers& r);
  int qbuf(OpenFile& file, v4l2_buffer& b);
  int streamon(OpenFile& file);
  void take(uint32_t index, int64_t now);
  void save_format();

  LoopbackConfig config_;
  SpoolWriter writer_;
  SpoolFormat format_;
  uint32_t sequence_ = 0;         // frames taken since STREAMON
  uint64_t taken_ = 0;            // frames taken since the configuration was loaded (stall faults count these)
  std::vector<bool> stall_fired_;
  int64_t hold_until_ = 0;        // a stall: no buffer is taken before then
  bool failing_ = false;          // the last frame could not be spooled (said once per outage)
  std::string format_failure_;    // the last failure to write the format file (said once)
};

}  // namespace arpipe::standin
