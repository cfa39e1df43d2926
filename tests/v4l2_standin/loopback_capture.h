// A loopback's capture node (VIDEO_CAPTURE, MMAP streaming): serves the frames its output node
// wrote to the spool, from the oldest, in order, each once per stream, waiting for those not yet
// written. Its format is the writer's; there is none until a writer has set one.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loopback_spool.h"
#include "loopback_node.h"
#include "standin_config.h"

namespace arpipe::standin {

class LoopbackCapture final : public LoopbackNode {
 public:
  explicit LoopbackCapture(const LoopbackConfig& config);

  const std::string& path() const override { return config_.capture; }
  void advance(int64_t now) override;
  int64_t next_wake(int64_t now) const override;
  int ioctl(OpenFile& file, unsigned long request, void* arg, const Waiter& wait) override;

 private:
  // The stream's format once buffers are allocated, else the writer's latest (nullopt: none yet).
  std::optional<SpoolFormat> current_format();
  void fill_format(const SpoolFormat& s, v4l2_format& f) const;
  int reqbufs(OpenFile& file, v4l2_requestbuffers& r);
  int qbuf(OpenFile& file, v4l2_buffer& b);
  void queue_released() override;

  LoopbackConfig config_;
  SpoolReader reader_;
  std::optional<SpoolFormat> negotiated_;  // fixed by REQBUFS
  uint64_t next_frame_ = 0;  // the spool index served next
  uint32_t sequence_ = 0;    // frames since STREAMON
  std::string format_error_; // the last complaint about the format file (said once)
};

}  // namespace arpipe::standin
